//! `[array]`: the sensor as R × C pixels, all alike, on the scene plane. The section gives
//! the shape, the pitch, how pixels map onto the plane (mm per pixel at the target, or a
//! horizontal field of view and a distance) and per-pixel maps of the signal rate ρ_s
//! (reflectivity) and the background ρ_b. [`SensorArray`] is its resolution: the mapping
//! and both maps as R × C values, so a worker that receives a resolved design needs no map
//! file. Pixel (r, c) sits at ((c + ½)·s, (r + ½)·s) mm, s the mm per pixel; its photon
//! stream depends only on (seed, r, c) ([`pixel_seed`]). A document without `[array]` is
//! the single pixel, unchanged.
//!
//! With `superpixel = G` (docs/pixel-contract.md "Superpixel") the written rows × cols are
//! SPADs and G × G of them share one pixel: the resolved array is R/G × C/G pixels (its
//! `rows`, `cols`, `pitch_um` and `mm_per_pixel` are the pixels'), while the rate maps, the
//! SPAD centres and the streams' seeds stay on the SPAD grid, so SPAD (r, c) draws the same
//! photons whatever G.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::DesignError;

/// Largest rows or columns.
pub const MAX_SIDE: u32 = 4096;
/// Bounds of a pixel's size on the scene plane (mm), written or from the field of view:
/// a micrometre to ten metres.
pub const MIN_MM_PER_PIXEL: f64 = 1e-3;
pub const MAX_MM_PER_PIXEL: f64 = 1e4;
/// Smallest pixel pitch on the die (µm): a nanometre-scale pitch is no pixel.
pub const MIN_PITCH_UM: f64 = 1e-3;
/// Most pixel-pulses an array frame may cost (R·C·N): 2^40 ≈ 1.1·10^12, a 256 × 256 array
/// over a 1 s frame at 10 MHz and about three hours at the model's 10^8 pixel-pulses/s.
pub const MAX_PIXEL_PULSES: u64 = 1 << 40;
/// Largest memory an array command (`simulate`, `merge`, a shard) may hold, in bytes: 4 GiB,
/// a sixth of the 24 GiB machines the project runs on. It counts everything the command
/// holds ([`SensorArray::bytes_needed`]): the per-pixel data and [`FIXED_BYTES`].
pub const MAX_ARRAY_BYTES: u64 = 4 << 30;
/// What an array command holds whatever the array's size: the program and its libraries,
/// the probe ROM (≤ 16 MB at its largest periodic depth) and the driver's folded tables,
/// the streaming buffers of the threads (512 kB each), the allocator's arenas. Measured:
/// `simulate --out` of a 4 × 4 array peaks at 7–10 MB resident
/// (crates/cli/tests/it/array_memory.rs); 256 MiB leaves room for a periodic ROM at its
/// largest depth, whose construction peaks near 340 MB before any per-pixel memory is
/// taken (every array command builds the ROM before it allocates the frame).
pub const FIXED_BYTES: u64 = 256 << 20;

/// The `[array]` section as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrayConfig {
    /// Rows of pixels (y on the scene plane).
    pub rows: u32,
    /// Columns of pixels (x on the scene plane).
    pub cols: u32,
    /// Pixel pitch on the die (µm): the sensor's size, for the maps' axes and the layout.
    pub pitch_um: f64,
    /// Scene-plane size of one pixel at the target (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mm_per_pixel: Option<f64>,
    /// Horizontal field of view across the columns (degrees), with `distance_mm`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field_of_view_deg: Option<f64>,
    /// Distance to the scene plane (mm), with `field_of_view_deg`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance_mm: Option<f64>,
    /// Per-pixel ρ_s (default: `sensor.signal_rate` everywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signal_map: Option<RateMap>,
    /// Per-pixel ρ_b (default: `sensor.background_rate` everywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background_map: Option<RateMap>,
    /// b: bits per beat of the readout port (default W); see [`crate::readout`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readout_bits: Option<u32>,
    /// The output link's rate in bits/s (default: one beat per pixel-clock cycle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readout_bits_per_s: Option<f64>,
    /// A frame rate the readout must allow (Hz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_rate_hz: Option<f64>,
    /// Double-buffered pixel registers (the next frame accumulates during the readout).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub double_buffer: bool,
    /// G: G × G SPADs share one pixel, their detections averaged each pulse (1: none).
    #[serde(default = "one_u32", skip_serializing_if = "is_one")]
    pub superpixel: u32,
    /// The fidelity level every pixel runs at (docs/tradeoff.md "Array levels").
    #[serde(default, skip_serializing_if = "ArrayLevel::is_bit_true")]
    pub level: ArrayLevel,
    /// K of `level = "auto"`: a pixel runs bit-true where its motion moves a register by
    /// more than K × that register's noise sd (default [`AUTO_THRESHOLD`]; only with
    /// `level = "auto"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auto_threshold: Option<f64>,
}

/// K of `[array] level = "auto"` when `auto_threshold` is not written: 0.5, so a pixel left
/// at the statistical level has a spread at most √(1 + K²) = 1.12 × the bit-true one
/// (crates/array/src/statistical/auto.rs says why).
pub const AUTO_THRESHOLD: f64 = 0.5;

/// Largest `auto_threshold`: at K = 10 a motion ten noise sds strong still runs
/// statistical, past any use of the auto level (the statistical level alone is the
/// choice then).
pub const MAX_AUTO_THRESHOLD: f64 = 10.0;

/// How faithfully the array's pixels are computed (`[array] level`); every level writes
/// the same output set and maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ArrayLevel {
    /// Every pulse of every pixel through the Monte Carlo and the one pixel datapath.
    #[default]
    BitTrue,
    /// Each pixel's registers drawn from their predicted distribution: the noise-free
    /// registers plus correlated Gaussian noise from the closed forms (per-pixel seeds).
    Statistical,
    /// Each pixel's noise-free (expected) registers.
    ClosedForm,
    /// Per pixel: statistical where its scene is static or its motion's response is far
    /// below its noise floor, bit-true where it moves (the rule: `tofprobe_array::auto`).
    Auto,
}

impl ArrayLevel {
    /// Every level, as written in `[array] level`.
    pub const ALL: [ArrayLevel; 4] = [
        ArrayLevel::BitTrue,
        ArrayLevel::Statistical,
        ArrayLevel::ClosedForm,
        ArrayLevel::Auto,
    ];

    /// Its name as written.
    pub fn name(self) -> &'static str {
        match self {
            ArrayLevel::BitTrue => "bit-true",
            ArrayLevel::Statistical => "statistical",
            ArrayLevel::ClosedForm => "closed-form",
            ArrayLevel::Auto => "auto",
        }
    }

    /// The default, bit-true.
    pub fn is_bit_true(&self) -> bool {
        *self == ArrayLevel::BitTrue
    }
}

impl std::fmt::Display for ArrayLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Refuses a level other than bit-true outside the range its closed forms were validated
/// on: a Fourier pixel whose scene is a static depth plus sines and plate modes, and
/// no background with a superpixel (G above 1), which the superpixel's closed form
/// (`dsp::superpixel`) assumes. Names the key and the level that works. `"auto"` runs
/// pixels at the statistical level, so it is refused exactly where the statistical is.
pub fn check_level(
    level: ArrayLevel,
    pixel: &tofprobe_pixel::PixelParams,
    scene: &tofprobe_scene::SceneConfig,
    superpixel: u32,
    background_rate: &[f64],
) -> Result<(), String> {
    if level.is_bit_true() {
        return Ok(());
    }
    let refuse = |why: String| {
        Err(format!(
            "array.level = \"{level}\" is outside its validated range: {why}; \
             array.level = \"bit-true\" runs it"
        ))
    };
    if pixel.mode != tofprobe_pixel::Mode::Fourier {
        return refuse(format!(
            "the pixel is in {} mode (Fourier only)",
            pixel.mode
        ));
    }
    use tofprobe_scene::MotionConfig as M;
    if let Some((i, m)) = scene
        .motions
        .iter()
        .enumerate()
        .find(|(_, m)| !matches!(m, M::Sine { .. } | M::PlateMode { .. }))
    {
        return refuse(format!(
            "scene.motion[{i}] is a {} (sines and plate modes only)",
            m.kind()
        ));
    }
    if superpixel > 1 && background_rate.iter().any(|&b| b > 0.0) {
        return refuse(format!(
            "array.superpixel = {superpixel} with background (the superpixel's closed form \
             has none)"
        ));
    }
    Ok(())
}

fn one_u32() -> u32 {
    1
}

fn one_usize() -> usize {
    1
}

fn is_one(v: &u32) -> bool {
    *v == 1
}

impl ArrayConfig {
    /// The section with only its required keys and `mm_per_pixel` written, every other key
    /// at its default (what a program building a configuration starts from, so a new
    /// optional key does not have to be spelled out there).
    pub fn new(rows: u32, cols: u32, pitch_um: f64, mm_per_pixel: f64) -> ArrayConfig {
        ArrayConfig {
            rows,
            cols,
            pitch_um,
            mm_per_pixel: Some(mm_per_pixel),
            field_of_view_deg: None,
            distance_mm: None,
            signal_map: None,
            background_map: None,
            readout_bits: None,
            readout_bits_per_s: None,
            frame_rate_hz: None,
            double_buffer: false,
            superpixel: 1,
            level: ArrayLevel::default(),
            auto_threshold: None,
        }
    }

    /// The readout keys of the section.
    pub fn readout_keys(&self) -> crate::readout::ReadoutKeys {
        crate::readout::ReadoutKeys {
            readout_bits: self.readout_bits,
            readout_bits_per_s: self.readout_bits_per_s,
            frame_rate_hz: self.frame_rate_hz,
            double_buffer: self.double_buffer,
        }
    }
}

/// Which way a gradient runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Along a row: column 0 has `from`, the last column `to`.
    #[default]
    X,
    /// Down a column: row 0 has `from`, the last row `to`.
    Y,
}

/// A per-pixel map of a photon rate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum RateMap {
    /// The same value everywhere.
    Constant { value: f64 },
    /// Linear from `from` to `to` across the array.
    Gradient {
        from: f64,
        to: f64,
        #[serde(default)]
        axis: Axis,
    },
    /// An image of R × C: a binary PGM (8- or 16-bit; value / maxval) or a `.npy` of
    /// R × C numbers, times `scale`. A relative path is relative to the configuration.
    Image {
        path: String,
        #[serde(default = "one")]
        scale: f64,
    },
}

fn one() -> f64 {
    1.0
}

/// The resolved array.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorArray {
    /// Rows of pixels (of superpixels when G > 1: the written rows / G).
    pub rows: usize,
    /// Columns of pixels (the written cols / G).
    pub cols: usize,
    /// A pixel's pitch on the die (µm): G × the written SPAD pitch.
    pub pitch_um: f64,
    /// Scene-plane size of one pixel (mm): G × a SPAD's.
    pub mm_per_pixel: f64,
    /// G: SPADs per pixel side (1: a pixel is one SPAD).
    #[serde(default = "one_usize")]
    pub superpixel: usize,
    /// ρ_s of each SPAD, row-major over the (rows·G) × (cols·G) SPADs.
    pub signal_rate: Vec<f64>,
    /// ρ_b of each SPAD, row-major.
    pub background_rate: Vec<f64>,
    /// The readout keys as written; [`crate::ResolvedDesign::readout`] resolves them for
    /// the pixel (its W, C and N), checked once by the resolution.
    #[serde(default)]
    pub readout: crate::readout::ReadoutKeys,
    /// The fidelity level the pixels run at.
    #[serde(default)]
    pub level: ArrayLevel,
    /// K of the auto level ([`ArrayConfig::auto_threshold`], resolved; omitted from the
    /// serialised design at the default, so sets written before the key keep their hash).
    #[serde(
        default = "auto_threshold_default",
        skip_serializing_if = "is_auto_threshold_default"
    )]
    pub auto_threshold: f64,
}

fn auto_threshold_default() -> f64 {
    AUTO_THRESHOLD
}

fn is_auto_threshold_default(k: &f64) -> bool {
    *k == AUTO_THRESHOLD
}

/// `array.auto_threshold` checked: finite, 0 ≤ K ≤ [`MAX_AUTO_THRESHOLD`], and written only
/// with `level = "auto"` (never accepted and ignored); the default where not written.
fn auto_threshold(a: &ArrayConfig) -> Result<f64, String> {
    let Some(k) = a.auto_threshold else {
        return Ok(AUTO_THRESHOLD);
    };
    let num = tofprobe_io::text::number;
    if a.level != ArrayLevel::Auto {
        return Err(format!(
            "array.auto_threshold = {} applies only with array.level = \"auto\" (the level is \"{}\"): \
             remove it, or set array.level = \"auto\"",
            num(k),
            a.level
        ));
    }
    if !(k.is_finite() && (0.0..=MAX_AUTO_THRESHOLD).contains(&k)) {
        return Err(format!(
            "array.auto_threshold = {} is out of range: allowed 0 <= auto_threshold <= {} \
             (default {})",
            num(k),
            num(MAX_AUTO_THRESHOLD),
            num(AUTO_THRESHOLD)
        ));
    }
    Ok(k)
}

impl SensorArray {
    /// Pixels in the array.
    pub fn pixels(&self) -> usize {
        self.rows * self.cols
    }

    /// Centre of pixel (r, c) on the scene plane, (x, y) mm.
    pub fn centre_mm(&self, r: usize, c: usize) -> (f64, f64) {
        (
            (c as f64 + 0.5) * self.mm_per_pixel,
            (r as f64 + 0.5) * self.mm_per_pixel,
        )
    }

    /// Rows of SPADs (rows · G).
    pub fn spad_rows(&self) -> usize {
        self.rows * self.superpixel
    }

    /// Columns of SPADs (cols · G).
    pub fn spad_cols(&self) -> usize {
        self.cols * self.superpixel
    }

    /// SPADs per pixel, G².
    pub fn spads_per_pixel(&self) -> usize {
        self.superpixel * self.superpixel
    }

    /// A SPAD's pitch on the die (µm), as written.
    pub fn spad_pitch_um(&self) -> f64 {
        self.pitch_um / self.superpixel as f64
    }

    /// Centre of SPAD (r, c) on the scene plane, (x, y) mm.
    pub fn spad_centre_mm(&self, r: usize, c: usize) -> (f64, f64) {
        let s = self.mm_per_pixel / self.superpixel as f64;
        ((c as f64 + 0.5) * s, (r as f64 + 0.5) * s)
    }

    /// The SPADs of pixel (r, c), row-major within it: (rows·G + i, cols·G + j).
    pub fn spads_of(&self, r: usize, c: usize) -> impl Iterator<Item = (usize, usize)> {
        let g = self.superpixel;
        (0..g * g).map(move |k| (r * g + k / g, c * g + k % g))
    }

    /// The superpixel front end of a pixel with `tdc_bits` TDC bits (`None` when G = 1).
    pub fn front_end(
        &self,
        tdc_bits: u32,
    ) -> Result<Option<tofprobe_pixel::Superpixel>, tofprobe_pixel::PixelError> {
        if self.superpixel == 1 {
            return Ok(None);
        }
        tofprobe_pixel::Superpixel::new(self.superpixel as u32, tdc_bits).map(Some)
    }

    /// The bytes one pixel costs an array command at its peak (the frame and the maps are
    /// held together while the set is written; every file is streamed, so no file adds
    /// to it): its `registers` words (i64) and detections (8); the ρ_s and ρ_b maps of its
    /// `spads` SPADs (16 each, kept in the design); and what is read from the frame —
    /// Fourier (`bins` > 0): amplitude and phase per bin (16 each) and the strongest bin (8);
    /// Haar (`bins` = 0): the transition time (8) and its point of the plane fit (24).
    /// `merge`'s coverage table (4 per pixel) is freed before the maps are made.
    pub fn bytes_per_pixel(registers: u64, bins: u64, spads: u64) -> u64 {
        let analysis = if bins > 0 { 16 * bins + 8 } else { 32 };
        8 * registers + 8 + 16 * spads + analysis
    }

    /// The bytes an array command holds for `rows` × `cols` pixels
    /// ([`Self::bytes_per_pixel`] each, and [`FIXED_BYTES`]), saturating.
    pub fn bytes_needed(rows: u64, cols: u64, registers: u64, bins: u64, spads: u64) -> u64 {
        rows.saturating_mul(cols)
            .saturating_mul(Self::bytes_per_pixel(registers, bins, spads))
            .saturating_add(FIXED_BYTES)
    }

    /// Checks a resolved array received whole (a tile set's manifest, a worker's design):
    /// [`Self::check_shape`], then maps of one value per SPAD, finite and in range. What a
    /// resolution produced always passes; a tampered one is refused before anything is
    /// sized from it.
    pub fn check_received(&self, registers: usize, bins: usize) -> Result<(), String> {
        self.check_shape(registers, bins)?;
        let spads = self.spad_rows() * self.spad_cols();
        for (name, map, max) in [
            ("signal", &self.signal_rate, 1.0),
            ("background", &self.background_rate, 20.0),
        ] {
            if map.len() != spads {
                return Err(format!(
                    "the {name} map has {} values for {} × {} SPADs",
                    map.len(),
                    self.spad_rows(),
                    self.spad_cols()
                ));
            }
            if let Some(v) = map
                .iter()
                .find(|v| !(v.is_finite() && (0.0..=max).contains(*v)))
            {
                return Err(format!(
                    "the {name} map holds the rate {v}: allowed 0..={max}"
                ));
            }
        }
        Ok(())
    }

    /// The shape of a received array, its maps aside: G within 1..=4, rows and columns of
    /// SPADs within 1..=[`MAX_SIDE`], pitch and mapping finite and positive, and the memory
    /// within [`MAX_ARRAY_BYTES`] for `registers` words and `bins` bins per pixel (so
    /// nothing sized from it can overflow or exceed the cap).
    pub fn check_shape(&self, registers: usize, bins: usize) -> Result<(), String> {
        let g = self.superpixel;
        let max_g = tofprobe_pixel::superpixel::MAX_SUPERPIXEL as usize;
        if !(1..=max_g).contains(&g) {
            return Err(format!("array.superpixel = {g}: allowed 1..={max_g}"));
        }
        for (name, v) in [("rows", self.rows), ("cols", self.cols)] {
            if v == 0 || v.saturating_mul(g) > MAX_SIDE as usize {
                return Err(format!(
                    "array.{name} = {v} pixels of {g} × {g} SPADs: allowed 1..={MAX_SIDE} SPADs"
                ));
            }
        }
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.mm_per_pixel) || !positive(self.pitch_um) {
            return Err(format!(
                "pitch {} µm, {} mm per pixel: both must be finite and positive",
                self.pitch_um, self.mm_per_pixel
            ));
        }
        let need = Self::bytes_needed(
            self.rows as u64,
            self.cols as u64,
            registers as u64,
            bins as u64,
            (g * g) as u64,
        );
        if need > MAX_ARRAY_BYTES {
            return Err(format!(
                "{} × {} pixels need {need} bytes: allowed at most {MAX_ARRAY_BYTES}",
                self.rows, self.cols
            ));
        }
        Ok(())
    }
}

/// The stream seed of pixel (r, c): a bijective mix of (seed, r, c), so every pixel's
/// photons depend on nothing else (not on the tiling, the threads or the process).
pub fn pixel_seed(seed: u64, r: usize, c: usize) -> u64 {
    use tofprobe_scene::splitmix::mix;
    mix(mix(seed ^ 0xA22A_7E5E_ED00_0000) ^ ((r as u64) << 32 | c as u64))
}

/// Resolves `[array]`: checks the shape (and the memory it needs for the pixel's registers
/// and bins), the mapping, the maps, with `sensor`'s rates as defaults, and the readout
/// ([`crate::readout`]). `origin` is the configuration's path (relative map paths are read
/// beside it).
pub fn resolve_array(
    a: &ArrayConfig,
    sensor: &tofprobe_scene::SensorConfig,
    scene: &tofprobe_scene::SceneConfig,
    pixel: &tofprobe_pixel::PixelParams,
    origin: &str,
) -> Result<SensorArray, DesignError> {
    let (registers, bins, frame_pulses) = (pixel.registers(), pixel.bins, pixel.frame_pulses);
    let err = |m: String| DesignError::array(origin, m);
    for (name, v) in [("rows", a.rows), ("cols", a.cols)] {
        if !(1..=MAX_SIDE).contains(&v) {
            return Err(err(format!(
                "array.{name} = {v} is out of range: allowed 1..={MAX_SIDE} (1 × 1 is one pixel)"
            )));
        }
    }
    let g = a.superpixel;
    let max_g = tofprobe_pixel::superpixel::MAX_SUPERPIXEL;
    if !(1..=max_g).contains(&g) {
        return Err(err(format!(
            "array.superpixel = {g} is out of range: allowed 1..={max_g} (G × G SPADs share one \
             pixel; 1: no superpixel)"
        )));
    }
    for (name, v) in [("rows", a.rows), ("cols", a.cols)] {
        if v % g != 0 {
            let down = v / g * g;
            let nearest = if down == 0 || v - down > down + g - v {
                down + g
            } else {
                down
            };
            return Err(err(format!(
                "array.{name} = {v} is not a multiple of array.superpixel = {g}: the SPADs form \
                 {g} × {g} superpixels; array.{name} = {nearest} is the nearest that does"
            )));
        }
    }
    // The pixels: G × G SPADs each.
    let (prows, pcols) = (a.rows / g, a.cols / g);
    let analysis_bins = match pixel.mode {
        tofprobe_pixel::Mode::Fourier => bins as u64,
        tofprobe_pixel::Mode::Haar => 0,
    };
    let spads = u64::from(g) * u64::from(g);
    let need = SensorArray::bytes_needed(
        prows.into(),
        pcols.into(),
        registers as u64,
        analysis_bins,
        spads,
    );
    if need > MAX_ARRAY_BYTES {
        let per_pixel = SensorArray::bytes_per_pixel(registers as u64, analysis_bins, spads);
        // The largest square of SPADs (a multiple of G) whose pixels fit.
        let pixels = (MAX_ARRAY_BYTES - FIXED_BYTES) / per_pixel;
        let side = ((pixels as f64).sqrt().floor() as u64) * u64::from(g);
        return Err(err(format!(
            "array.rows × array.cols = {} × {} needs {:.2} GiB at its peak ({per_pixel} bytes \
             per pixel: {registers} registers, the detections, the rate maps and the {} maps, \
             with {} MiB for the ROM and the program): allowed at most {} GiB; \
             array.rows = array.cols = {side} fits",
            a.rows,
            a.cols,
            need as f64 / (1u64 << 30) as f64,
            if analysis_bins > 0 {
                "amplitude and phase"
            } else {
                "transition-time"
            },
            FIXED_BYTES >> 20,
            MAX_ARRAY_BYTES >> 30
        )));
    }
    let work = u64::from(a.rows) * u64::from(a.cols) * frame_pulses;
    if work > MAX_PIXEL_PULSES {
        let n = MAX_PIXEL_PULSES / (u64::from(a.rows) * u64::from(a.cols));
        return Err(err(format!(
            "array.rows × array.cols × frame pulses = {} × {} × {frame_pulses} = {work:.3e} \
             pixel-pulses: allowed at most 2^40 = {MAX_PIXEL_PULSES:.3e} per frame; \
             acquisition.pulses (or pixel.frame_pulses) <= {n} fits this array",
            a.rows, a.cols,
        )));
    }
    let num = tofprobe_io::text::number;
    if !(a.pitch_um.is_finite() && (MIN_PITCH_UM..=1e4).contains(&a.pitch_um)) {
        return Err(err(format!(
            "array.pitch_um = {} is out of range: allowed {} <= pitch_um <= 10000 (e.g. 30)",
            num(a.pitch_um),
            num(MIN_PITCH_UM)
        )));
    }
    let mm_per_pixel = match (a.mm_per_pixel, a.field_of_view_deg, a.distance_mm) {
        (Some(s), None, None) => {
            if !(s.is_finite() && (MIN_MM_PER_PIXEL..=MAX_MM_PER_PIXEL).contains(&s)) {
                return Err(err(format!(
                    "array.mm_per_pixel = {} is out of range: allowed {} <= mm_per_pixel <= 10000",
                    num(s),
                    num(MIN_MM_PER_PIXEL)
                )));
            }
            s
        }
        (None, Some(fov), Some(d)) => {
            if !(fov.is_finite() && fov > 0.0 && fov < 180.0) {
                return Err(err(format!(
                    "array.field_of_view_deg = {} is out of range: allowed 0 < fov < 180",
                    num(fov)
                )));
            }
            if !(d.is_finite() && d > 0.0 && d <= 1e7) {
                return Err(err(format!(
                    "array.distance_mm = {} is out of range: allowed 0 < distance_mm <= 1e7",
                    num(d)
                )));
            }
            let s = 2.0 * d * (fov.to_radians() / 2.0).tan() / f64::from(a.cols);
            // The mapping's result within the bounds `mm_per_pixel` has when written.
            if !(s.is_finite() && (MIN_MM_PER_PIXEL..=MAX_MM_PER_PIXEL).contains(&s)) {
                let want = if s.is_finite() && s > MAX_MM_PER_PIXEL {
                    "a narrower field of view or a nearer plane"
                } else {
                    "a wider field of view or a farther plane"
                };
                return Err(err(format!(
                    "array.field_of_view_deg = {} and array.distance_mm = {} over {} columns give \
                     {} mm per pixel: allowed {} ..= 10000 (what array.mm_per_pixel allows); {want}",
                    num(fov),
                    num(d),
                    a.cols,
                    num(s),
                    num(MIN_MM_PER_PIXEL)
                )));
            }
            s
        }
        _ => {
            // Name the keys written (their dotted paths), not only the section.
            let given: Vec<&str> = [
                ("array.mm_per_pixel", a.mm_per_pixel.is_some()),
                ("array.field_of_view_deg", a.field_of_view_deg.is_some()),
                ("array.distance_mm", a.distance_mm.is_some()),
            ]
            .iter()
            .filter(|(_, set)| *set)
            .map(|(k, _)| *k)
            .collect();
            return Err(err(format!(
                "[array] maps pixels onto the scene plane with either array.mm_per_pixel or both \
                 array.field_of_view_deg and array.distance_mm (exactly one of the two ways); given: {}",
                if given.is_empty() {
                    "none".to_string()
                } else {
                    given.join(", ")
                }
            )));
        }
    };
    let (rows, cols) = (a.rows as usize, a.cols as usize);
    let base = config_dir(origin);
    let signal_rate = rate_map(
        a.signal_map.as_ref(),
        "array.signal_map",
        sensor.signal_rate,
        rows,
        cols,
        &base,
    )
    .map_err(err)?;
    let background_rate = rate_map(
        a.background_map.as_ref(),
        "array.background_map",
        sensor.background_rate,
        rows,
        cols,
        &base,
    )
    .map_err(err)?;
    let readout = a.readout_keys();
    let (g, prows, pcols) = (g as usize, prows as usize, pcols as usize);
    crate::readout::Readout::new(&readout, prows, pcols, pixel, sensor.laser_rate_hz)
        .map_err(err)?;
    check_level(a.level, pixel, scene, g as u32, &background_rate).map_err(err)?;
    let auto_threshold = auto_threshold(a).map_err(err)?;
    Ok(SensorArray {
        rows: prows,
        cols: pcols,
        pitch_um: a.pitch_um * g as f64,
        // The mapping above is per SPAD (cols SPADs across the field of view).
        mm_per_pixel: mm_per_pixel * g as f64,
        superpixel: g,
        signal_rate,
        background_rate,
        readout,
        level: a.level,
        auto_threshold,
    })
}

/// The directory map paths are relative to.
fn config_dir(origin: &str) -> PathBuf {
    if origin == crate::DEFAULT_ORIGIN {
        return PathBuf::from(".");
    }
    Path::new(origin)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// One map's R × C values, each a valid rate (ρ_s in [0, 1], ρ_b in [0, 20]).
fn rate_map(
    map: Option<&RateMap>,
    field: &str,
    default: f64,
    rows: usize,
    cols: usize,
    base: &Path,
) -> Result<Vec<f64>, String> {
    let max = if field.contains("signal") { 1.0 } else { 20.0 };
    let values = match map {
        None => vec![default; rows * cols],
        Some(RateMap::Constant { value }) => vec![*value; rows * cols],
        Some(RateMap::Gradient { from, to, axis }) => (0..rows * cols)
            .map(|i| {
                let (r, c) = (i / cols, i % cols);
                let (k, n) = match axis {
                    Axis::X => (c, cols),
                    Axis::Y => (r, rows),
                };
                let t = if n > 1 {
                    k as f64 / (n - 1) as f64
                } else {
                    0.0
                };
                from + (to - from) * t
            })
            .collect(),
        Some(RateMap::Image { path, scale }) => {
            if !(scale.is_finite() && *scale >= 0.0) {
                return Err(format!(
                    "{field}.scale = {} is out of range: allowed >= 0 (1: the image as it is)",
                    tofprobe_io::text::number(*scale)
                ));
            }
            let p = base.join(path);
            // A path is echoed at most 200 characters (a 4 kB path made a 4 kB message).
            let shown = tofprobe_io::text::clip(path, 200);
            let img = crate::rate_image::read(&p, rows, cols)
                .map_err(|m| format!("{field}.path = \"{shown}\": {m}"))?;
            img.into_iter().map(|v| v * scale).collect()
        }
    };
    if let Some((i, v)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && (0.0..=max).contains(*v)))
    {
        // No map: every pixel has the sensor's rate, and the sensor's key is the one to name.
        let field = match map {
            None if max == 1.0 => format!("sensor.signal_rate (every pixel's without {field})"),
            None => format!("sensor.background_rate (every pixel's without {field})"),
            Some(_) => field.to_string(),
        };
        return Err(format!(
            "{field} gives pixel ({}, {}) the rate {}: allowed 0..={max} (a {} rate per pulse)",
            i / cols,
            i % cols,
            tofprobe_io::text::number(*v),
            if max == 1.0 {
                "signal-photon probability; scale the map down"
            } else {
                "mean background"
            }
        ));
    }
    Ok(values)
}
