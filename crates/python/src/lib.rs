//! The Python package `tofprobe` (module `tofprobe._native`): a resolved design as
//! `tofprobe.Design`, numpy arrays in and out. Conversion only: every computation is a
//! library entry — the one resolution (`tofprobe_design`), the photon source
//! (`tofprobe_scene::PhotonSource`), the pixel's `FrameDriver`, the one readout → phasor
//! function (`tofprobe_pixel::spectrum::phasors`) and the array model
//! (`tofprobe_array::output::simulate`) — run with the GIL released, off the calling
//! thread so that Ctrl-C stops a long call (`long_call`). Errors are the package's
//! exceptions (`errors`: `tofprobe.Error` and its subclasses, each also the builtin a user
//! would catch) carrying the library's message (it names the field, the value and what
//! would work), or `TypeError`s naming the argument of a wrong type.

mod analysis;
mod convert;
mod design_io;
mod errors;
mod frames;
mod long_call;
mod tiles;

use std::path::PathBuf;
use std::sync::OnceLock;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use tofprobe_design::{DEFAULT_ORIGIN, DEFAULT_TOML, ResolvedDesign};
use tofprobe_dsp::sd::ProbeRom;
use tofprobe_pixel::{FrameDriver, PixelError};

use convert::value_error;
use long_call::Progress;

/// What a pickled Design carries: its resolved JSON and, once generated, its ROM's JSON.
type PickleState = (String, Option<String>);

/// A tile's rectangle for Python: `((row_start, row_end), (col_start, col_end))`.
type PyRect = ((usize, usize), (usize, usize));

/// A tofprobe design resolved once (``tofprobe config``'s resolution): sensor, scene,
/// acquisition, the pixel's parameters and widths, the Fourier bins and the ΣΔ probe.
///
/// Build one with ``Design.default()`` (the embedded paper Fig. 8 case),
/// ``Design.from_toml(path)``, ``Design.from_toml_text(text)``, ``Design.from_dict(d)`` or
/// ``Design.from_json(text)``, and change keys with ``design.with_overrides({"pixel.bins":
/// 4})``; then ``simulate_scene`` → ``run_pixel`` → ``spectrum`` is ``tofprobe
/// simulate``'s bit-true frame with numpy arrays at each step, and ``simulate_array`` runs
/// an ``[array]`` design.
///
/// The letters of the shapes and the summary: B is the number of Fourier bins (frequencies
/// the pixel measures; 2B registers, an I and a Q per bin); W the width in bits of each
/// register; N the pulses of one frame (``frame_pulses``: one TDC code or none per laser
/// pulse); L the depth of the probe ROM (its period in pulses; bin k sits at k·f_s/L,
/// f_s the laser rate); G the register's fractional bits (the registers count 2^−G TDC
/// codes; ``register_frac_bits``) — and, for an ``[array]``, R × C the pixels and
/// ``superpixel`` the SPADs per pixel side.
///
/// The first call that needs the probe ROM (``run_pixel``, ``spectrum``, ``probe_rom``,
/// ``simulate_array``, ...) generates it — about 1.4 s for the default L = 20 000 on two
/// cores — and keeps it: later calls and pickled copies do not pay again.
///
/// Computations release the GIL and run off the calling thread: Ctrl-C stops a long call
/// within a fraction of a second (``KeyboardInterrupt``). Do not mutate an input array from
/// another thread during a call. Errors are ``tofprobe.Error`` subclasses
/// (``tofprobe.errors``). A Design is immutable and picklable.
#[pyclass(module = "tofprobe._native", name = "Design", frozen)]
#[derive(Debug)]
struct Design {
    pub(crate) inner: ResolvedDesign,
    /// The probe ROM (Fourier), generated on first use.
    rom: OnceLock<Option<ProbeRom>>,
}

impl Design {
    fn new(inner: ResolvedDesign) -> Self {
        Design {
            inner,
            rom: OnceLock::new(),
        }
    }

    /// A resolved design, with what it ignores (`ignored_warning`: a `[probe]` in Haar
    /// mode) shown as a Python `UserWarning`, as the CLI shows it on stderr.
    fn loaded(py: Python<'_>, inner: ResolvedDesign) -> PyResult<Self> {
        if let Some(w) = inner.ignored_warning() {
            let message = std::ffi::CString::new(w.replace('\0', " ")).map_err(value_error)?;
            let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
            PyErr::warn(py, &category, &message, 1)?;
        }
        Ok(Design::new(inner))
    }

    /// The probe ROM (`None` in Haar mode), generated once off the calling thread (about
    /// 1.4 s for L = 20 000: Ctrl-C returns at once, the generation finishing unseen).
    pub(crate) fn rom(&self, py: Python<'_>) -> PyResult<Option<&ProbeRom>> {
        if let Some(r) = self.rom.get() {
            return Ok(r.as_ref());
        }
        let inner = self.inner.clone();
        let r = long_call::detached(py, move || inner.probe_rom())?.map_err(value_error)?;
        Ok(self.rom.get_or_init(|| r).as_ref())
    }

    /// The probe ROM, refused in Haar mode (`what` names the call).
    pub(crate) fn fourier_rom(&self, py: Python<'_>, what: &str) -> PyResult<&ProbeRom> {
        self.rom(py)?.ok_or_else(|| {
            errors::input(format!(
                "{what} needs a Fourier pixel, and pixel.mode of `{}` resolved to \"{}\" \
                 (set pixel.mode = \"fourier\")",
                self.inner.origin, self.inner.pixel.mode
            ))
        })
    }

    /// The largest TDC code the pixel takes: 2^T − 1.
    pub(crate) fn max_code(&self) -> u32 {
        ((1u64 << self.inner.pixel.tdc_bits.min(32)) - 1) as u32
    }
}

#[pymethods]
impl Design {
    /// The embedded default design (the paper's Fig. 8: a 0.1 mm, 4.5 kHz sine; 10^7
    /// pulses; 16 bins), as ``tofprobe`` commands use without a configuration.
    #[staticmethod]
    fn default(py: Python<'_>) -> PyResult<Self> {
        let inner = design_io::from_text(py, DEFAULT_TOML.to_string(), DEFAULT_ORIGIN)?;
        Design::loaded(py, inner)
    }

    /// The design in the TOML file at ``path`` (a ``str`` or an ``os.PathLike``), resolved
    /// (validated and completed). A string is always a path, never TOML text: text goes
    /// to ``from_toml_text``.
    ///
    /// Raises ``tofprobe.FileNotFoundError`` (also the builtin ``FileNotFoundError``) for a
    /// path that does not exist, ``tofprobe.FileError`` (an ``OSError``) for a directory,
    /// a file that is not a regular file or cannot be read — each naming the path — and
    /// ``tofprobe.ConfigError`` (a ``ValueError``) naming the key, the value and the allowed
    /// values for a document that does not resolve; ``TypeError`` for a path of another
    /// type.
    #[staticmethod]
    fn from_toml(path: &Bound<'_, PyAny>) -> PyResult<Self> {
        let py = path.py();
        let inner = design_io::load(py, design_io::path_of(path)?)?;
        Design::loaded(py, inner)
    }

    /// The design a TOML document given as text holds, resolved like ``from_toml``'s file
    /// (``origin`` is ``<TOML text>``). ``tofprobe.ConfigError`` names the key (and the
    /// line and column of ``text``) when it does not resolve.
    #[staticmethod]
    fn from_toml_text(py: Python<'_>, text: String) -> PyResult<Self> {
        let inner = design_io::from_text(py, text, design_io::TEXT_ORIGIN)?;
        Design::loaded(py, inner)
    }

    /// A design from a dict shaped like the TOML document (``{"sensor": {...}, "scene":
    /// {...}, "pixel": {...}, ...}``, e.g. ``tomllib.load`` of a configuration), resolved
    /// by the same one resolution as ``from_toml``. ``tofprobe.ConfigError`` naming the
    /// key's dotted path (``pixel.binz``, with the keys its section takes) for an unknown
    /// key or a bad value, or a ``None``; ``TypeError`` for a value TOML cannot hold.
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyAny>) -> PyResult<Self> {
        let inner = design_io::from_dict(d)?;
        Design::loaded(d.py(), inner)
    }

    /// This design with some keys changed, resolved again by the one resolution: a dict of
    /// dotted keys ``"section.key"`` to values, e.g. ``{"pixel.bins": 4,
    /// "acquisition.seed": 7}``; ``None`` removes a key (back to its default: ``{"pixel.
    /// frame_pulses": None}``). Every other key keeps its value. ``tofprobe.ConfigError``
    /// names an unknown key or a refused value by its dotted path.
    fn with_overrides(&self, py: Python<'_>, overrides: &Bound<'_, PyAny>) -> PyResult<Self> {
        let inner = design_io::with_overrides(&self.inner, overrides)?;
        Design::loaded(py, inner)
    }

    /// A design serialised by ``to_json`` (no resolution runs again).
    #[staticmethod]
    fn from_json(py: Python<'_>, text: &str) -> PyResult<Self> {
        py.detach(|| ResolvedDesign::from_json(text))
            .map(Design::new)
            .map_err(value_error)
    }

    /// The resolved design as JSON (floats round-trip exactly); ``from_json`` reads it.
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_json().map_err(value_error)
    }

    /// The configuration document as TOML text (``Design.from_toml`` reads it back to the
    /// same resolution).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.inner.document).map_err(value_error)
    }

    /// Where the design came from: the file path, ``<embedded default>``, ``<TOML text>``
    /// or ``<dict>`` (``... with overrides of KEYS`` after ``with_overrides``).
    #[getter]
    fn origin(&self) -> &str {
        &self.inner.origin
    }

    /// The resolved values as a dict (the letters as in ``help(tofprobe.Design)``):
    /// ``mode``, ``bins`` (ROM bin indices k: B of them),
    /// ``frequencies_hz`` (f_k = k·f_s/L), ``tdc_bits`` (T), ``width`` (W),
    /// ``frame_pulses`` (N), ``rom_depth`` (L), ``registers`` (2B, or 2^(U+1) − 1 Haar),
    /// ``shift`` (S), ``frac_bits`` (F), ``register_frac_bits`` (G: the registers count
    /// 2^−G codes), ``adders`` (A), ``cycles_per_pulse`` (C),
    /// ``pulses`` (the acquisition), ``seed``, ``laser_rate_hz``, ``tdc_lsb_mm``, ``notes``
    /// ``array`` (``(rows, cols)`` of pixels, or ``None``) and ``superpixel`` (G: SPADs per
    /// pixel side, so the written SPAD grid is G·rows × G·cols; ``None`` without an array).
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = &self.inner;
        let p = &d.pixel;
        let fs = d.sensor().laser_rate_hz;
        let out = PyDict::new(py);
        out.set_item("origin", &d.origin)?;
        out.set_item("mode", p.mode.to_string())?;
        out.set_item("bins", d.bins.clone())?;
        let freqs: Vec<f64> = d
            .bins
            .iter()
            .map(|&k| tofprobe_dsp::dft::bin_frequency_hz(k as f64, p.rom_depth, fs))
            .collect();
        out.set_item("frequencies_hz", freqs)?;
        out.set_item("tdc_bits", p.tdc_bits)?;
        out.set_item("width", p.width)?;
        out.set_item("frame_pulses", p.frame_pulses)?;
        out.set_item("rom_depth", p.rom_depth)?;
        out.set_item("registers", p.registers())?;
        out.set_item("shift", p.shift)?;
        out.set_item("frac_bits", p.frac_bits)?;
        out.set_item("register_frac_bits", p.register_frac_bits())?;
        out.set_item("adders", p.adders)?;
        out.set_item("cycles_per_pulse", p.cycles_per_pulse)?;
        out.set_item("haar_scales", p.haar_scales)?;
        out.set_item("pulses", d.pulses())?;
        out.set_item("seed", d.document.acquisition.seed)?;
        out.set_item("laser_rate_hz", fs)?;
        out.set_item("tdc_lsb_mm", d.sensor().tdc_lsb_mm())?;
        out.set_item("notes", d.notes.clone())?;
        out.set_item("array", d.array.as_ref().map(|a| (a.rows, a.cols)))?;
        out.set_item("superpixel", d.array.as_ref().map(|a| a.superpixel))?;
        Ok(out)
    }

    /// One frame's photons: ``(valid, tdc)``, numpy ``bool`` and ``uint16`` arrays of N =
    /// ``frame_pulses`` pulses (``tdc`` is 0 where ``valid`` is False; TDC codes have at most
    /// 16 bits, and the narrowest dtype is the cheapest for ``run_pixel`` to read: any
    /// integer dtype is accepted there). The same photons as
    /// ``tofprobe simulate``'s bit-true frame; ``seed`` replaces ``[acquisition] seed``.
    /// For an ``[array]`` design, ``pixel=(row, col)`` gives that pixel's own stream (its
    /// rates, the scene at its centre, its own seed), the one ``simulate_array`` runs.
    ///
    /// ``threads``: the cores to draw on (a rayon pool of that size; default all);
    /// ``progress``: a callable ``progress(done, total)`` in pulses (called about every
    /// 50 ms and at the end), or ``True`` for a tqdm bar (``tofprobe[progress]``). The
    /// photons do not depend on ``threads``. Ctrl-C stops the call between chunks of 2^20
    /// pulses.
    #[pyo3(signature = (seed=None, pixel=None, *, progress=None, threads=None))]
    fn simulate_scene<'py>(
        &self,
        py: Python<'py>,
        seed: Option<u64>,
        pixel: Option<(usize, usize)>,
        progress: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let mut design = self.inner.clone();
        if let Some(s) = seed {
            design.document.acquisition.seed = s;
        }
        let source = match pixel {
            Some((r, c)) => design.pixel_source(r, c),
            None => design.photon_source(),
        }
        .map_err(value_error)?;
        let n = design.pixel.frame_pulses;
        let pool = long_call::pool(threads)?;
        let progress = Progress::new(py, progress, "simulate_scene", "pulses", n)?;
        let (valid, tdc) = frames::scene(py, &source, n, &progress, pool.as_ref())?;
        PyTuple::new(
            py,
            [
                valid.into_pyarray(py).into_any(),
                tdc.into_pyarray(py).into_any(),
            ],
        )
    }

    /// The registers after one frame of ``(valid, tdc)`` through the bit-true pixel (the
    /// transaction level, ``tofprobe_pixel::FrameDriver``): an int64 array of the
    /// sign-extended register words (2B: the I and the Q register of each of the B bins;
    /// Haar 2^(U+1) − 1), each W bits wide, counting 2^−G TDC codes.
    ///
    /// ``valid`` is a 1-D bool array, ``tdc`` a 1-D integer array of the same length, at
    /// most N = ``frame_pulses`` pulses; pulse i reads ROM address i mod L. A valid pulse's
    /// code must be in 0 .. 2^T − 1 (``tdc_bits``); an invalid pulse's code is ignored.
    ///
    /// The first call on a Fourier design generates the probe ROM (about 1.4 s for the
    /// default L = 20 000; kept for later calls); a 10^7-pulse frame then takes ≈ 15–30 ms.
    fn run_pixel<'py>(
        &self,
        py: Python<'py>,
        valid: &Bound<'py, PyAny>,
        tdc: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let valid_a = convert::bool_array("valid", valid)?;
        let tdc_a = convert::codes("tdc", tdc)?;
        let (valid_s, tdc_s) = self.checked_frame(&valid_a, &tdc_a)?;
        // The library reads (valid, tdc) in place (`tofprobe_pixel::ValidCodes`: a block of
        // pulses decoded at a time into the compact codes the driver steps, the range check
        // riding along): no conversion pass here (scripts/python-bench.py).
        Ok(frames::pixel(self, py, valid_s, tdc_s)?.into_pyarray(py))
    }

    /// The spectrum of a Fourier frame's registers (``tofprobe_pixel::spectrum::phasors``,
    /// the one readout → phasor function): ``(frequencies_hz, amplitude_um, phase_deg)``,
    /// float64 arrays of B bins in ROM order. ``pulses`` is the frame's length (default
    /// N = ``frame_pulses``).
    #[pyo3(signature = (registers, pulses=None))]
    fn spectrum<'py>(
        &self,
        py: Python<'py>,
        registers: &Bound<'py, PyAny>,
        pulses: Option<u64>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let regs = convert::int64_array("registers", registers)?;
        let words = convert::slice(&regs, "registers")?;
        let rom = self.fourier_rom(py, "spectrum")?;
        let pulses = pulses.unwrap_or(self.inner.pixel.frame_pulses);
        let lsb_mm = self.inner.sensor().tdc_lsb_mm();
        let params = &self.inner.pixel;
        let bins = py
            .detach(|| tofprobe_pixel::spectrum::phasors(params, rom, words, pulses, lsb_mm))
            .map_err(value_error)?;
        let f: Vec<f64> = bins.iter().map(|b| b.frequency_hz).collect();
        let a: Vec<f64> = bins.iter().map(|b| b.amplitude_um).collect();
        let p: Vec<f64> = bins.iter().map(|b| b.phase_deg).collect();
        PyTuple::new(
            py,
            [
                f.into_pyarray(py).into_any(),
                a.into_pyarray(py).into_any(),
                p.into_pyarray(py).into_any(),
            ],
        )
    }

    /// The ΣΔ probe ROM the pixel reads: an int8 array [L, 2B] of ±1 (row = ROM address,
    /// column = register: 2k is bin k's I, 2k + 1 its Q). ``ValueError`` in Haar mode.
    fn probe_rom<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rom = self.fourier_rom(py, "probe_rom")?;
        let (l, r) = (rom.image.depth(), rom.image.registers());
        // L·R bytes (512 MB at L = 2^24, R = 32): written in chunks of addresses, so Ctrl-C
        // stops the copy too (a pending interrupt would otherwise fail numpy's import below).
        const ADDRESSES: usize = 1 << 16;
        let progress = Progress::none(l as u64);
        let bits = long_call::run(py, &progress, None, |watch| {
            let mut v = Vec::with_capacity(l * r);
            for start in (0..l).step_by(ADDRESSES) {
                let end = (start + ADDRESSES).min(l);
                for a in start..end {
                    v.extend((0..r).map(|j| if rom.image.bit(a, j) { 1i8 } else { -1i8 }));
                }
                if !watch.advance((end - start) as u64) {
                    return Err(());
                }
            }
            Ok(v)
        })?
        .map_err(|()| {
            pyo3::exceptions::PyRuntimeError::new_err("tofprobe: the ROM copy was stopped")
        })?;
        let array = Array2::from_shape_vec((l, r), bits).map_err(value_error)?;
        Ok(array.into_pyarray(py).into_any())
    }

    /// Runs an ``[array]`` design (``tofprobe simulate CONFIG --out DIR``'s model, nothing
    /// written): a dict of numpy arrays ``registers`` (int64 [R, C, K]), ``detections``
    /// (uint64 [R, C]), ``level`` (int64 [R, C]: the ``[array] level`` each pixel ran at,
    /// 0 bit-true, 1 statistical, 2 closed-form — the set's ``level.npy``) and, for a
    /// Fourier pixel, ``frequencies_hz`` ([B]),
    /// ``amplitude_um`` and ``phase_deg`` (float64 [B, R, C]) — R × C the array's pixels,
    /// K = 2B registers a pixel. Pixel (r, c)'s registers are
    /// ``run_pixel(*simulate_scene(pixel=(r, c)))``.
    ///
    /// ``tiles`` (1 ..= R·C) splits the array into that many tiles (``tile_rects``); with
    /// ``client``, a ``dask.distributed.Client``, each tile is a task run in the workers
    /// (``tofprobe.dask.simulate_array``; default tiles: twice the cluster's threads).
    /// Any tiling, local or distributed, gives the same registers bit for bit.
    ///
    /// ``threads``: the cores to run on locally (a rayon pool of that size; default all);
    /// ``progress``: a callable ``progress(done, total)`` in pixel-pulses (R·C·N in all),
    /// or ``True`` for a tqdm bar (``tofprobe[progress]``). Ctrl-C stops a local run
    /// between chunks of each pixel's pulses. Both apply to the local run; with
    /// ``client`` the cluster sizes its workers and ``progress`` is not called.
    #[pyo3(signature = (tiles=None, client=None, *, progress=None, threads=None))]
    fn simulate_array<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
        tiles: Option<usize>,
        client: Option<&Bound<'py, PyAny>>,
        progress: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = slf.get();
        if let Some(client) = client.filter(|c| !c.is_none()) {
            // The ROM generated once here travels with the design to every task.
            d.rom(py)?;
            let out = py
                .import("tofprobe.dask")?
                .call_method1("simulate_array", (slf, tiles, client))?;
            return Ok(out.cast_into::<PyDict>()?);
        }
        let pool = long_call::pool(threads)?;
        let (frame, seconds) =
            tiles::run_local(d, py, tiles.unwrap_or(1), progress, pool.as_ref())?;
        tiles::array_dict(d, py, frame, seconds)
    }

    /// The partition of the array into ``tiles`` rectangles (``tofprobe simulate --shard
    /// i/n``'s): a list of ``((row_start, row_end), (col_start, col_end))``, every pixel
    /// in exactly one. ``ValueError`` unless 1 ≤ tiles ≤ R·C.
    fn tile_rects(&self, tiles: usize) -> PyResult<Vec<PyRect>> {
        Ok(tiles::rects(self, tiles)?
            .into_iter()
            .map(|(r, c)| ((r.start, r.end), (c.start, c.end)))
            .collect())
    }

    /// Runs one tile of the array on a rayon pool of ``threads`` threads (default: all
    /// cores): a dict ``rows``, ``cols`` (as given), ``registers`` (int64 [h, w, K]) and
    /// ``detections`` (uint64 [h, w]); ``merge_tiles`` joins them.
    #[pyo3(signature = (rows, cols, threads=None))]
    fn run_tile<'py>(
        &self,
        py: Python<'py>,
        rows: (usize, usize),
        cols: (usize, usize),
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let t = tiles::run_tile(self, py, rows.0..rows.1, cols.0..cols.1, threads)?;
        tiles::tile_dict(py, t)
    }

    /// Joins ``run_tile``'s dicts covering the array exactly once into
    /// ``simulate_array``'s dict (refusing a gap or an overlap, naming the pixel).
    fn merge_tiles<'py>(
        &self,
        py: Python<'py>,
        tiles: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let frame = tiles::merge(self, py, tiles)?;
        tiles::array_dict(self, py, frame, 0.0)
    }

    /// The float reference: the windowed DFT (the ROM's window, 2/(N·G)) of the frame's
    /// held depth at the design's bins — ``(frequencies_hz, amplitude_um, phase_deg)`` as
    /// ``spectrum`` gives for the pixel (``tofprobe_experiments::references::dft``).
    /// ``valid``/``tdc`` as for ``run_pixel``.
    fn dft<'py>(
        &self,
        py: Python<'py>,
        valid: &Bound<'py, PyAny>,
        tdc: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        analysis::reference(self, py, valid, tdc, "dft")
    }

    /// Float ΣΔ probing of the frame (the pixel's float twin: the same ROM, hold, priming
    /// and prefilter α = 2^−S): ``(frequencies_hz, amplitude_um, phase_deg)``.
    fn float_sd<'py>(
        &self,
        py: Python<'py>,
        valid: &Bound<'py, PyAny>,
        tdc: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        analysis::reference(self, py, valid, tdc, "float_sd")
    }

    /// The closed-form noise floor E|Y| in µm at each bin for a frame of ``pulses``
    /// (default N): eq. 12 with the TDC's a²/12, the 1NN hold and the first-arrival
    /// mixture of the design's scene.
    #[pyo3(signature = (pulses=None))]
    fn noise_floor<'py>(
        &self,
        py: Python<'py>,
        pulses: Option<u64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        analysis::noise_floor(self, py, pulses)
    }

    /// The ΣΔ noise transfer function the probe ROM was modulated with: a dict of
    /// ``zeros``, ``poles`` (complex128), ``frequencies_hz`` (``points`` from 0 to f_s/2)
    /// and ``magnitude`` (|NTF(e^{j2πf/f_s})|), and ``order``, ``osr``, ``h_inf``.
    #[pyo3(signature = (points=512))]
    fn ntf<'py>(&self, py: Python<'py>, points: usize) -> PyResult<Bound<'py, PyDict>> {
        analysis::ntf(self, py, points)
    }

    /// The resolved widths and the readout sizing (``tofprobe size``'s readout section):
    /// ``width`` (W), ``tdc_bits`` (T), ``frac_bits`` (F), ``register_frac_bits`` (G),
    /// ``operand_bits``, ``registers``, ``bits_per_frame`` (registers · W),
    /// ``readout_bits`` (whole bytes), ``memory`` (every figure) and, for an array,
    /// ``array_readout_bits``.
    fn widths<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        analysis::widths(self, py)
    }

    /// ``tofprobe size``'s report as a dict (synthesis with yosys, timing with OpenSTA,
    /// the B and W sweeps). ``RuntimeError`` naming the tool when yosys or OpenSTA is not
    /// installed.
    #[pyo3(signature = (liberty=None, sky130=false, sweep_bins=None, sweep_widths=None, node_nm=40.0))]
    fn size<'py>(
        &self,
        py: Python<'py>,
        liberty: Option<PathBuf>,
        sky130: bool,
        sweep_bins: Option<Vec<u64>>,
        sweep_widths: Option<Vec<u32>>,
        node_nm: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        analysis::size(self, py, liberty, sky130, sweep_bins, sweep_widths, node_nm)
    }

    /// Private (scripts/python-bench.py's, not the API): seconds the library's own pixel
    /// call takes on the frame, best of ``repeat``: the baseline of ``run_pixel``'s
    /// overhead. By default the call
    /// a Rust program holding the same (``valid``, ``tdc``) arrays makes — ``FrameDriver``
    /// run on ``tofprobe_pixel::ValidCodes`` (decoded in place), range check, readout —
    /// the very call ``run_pixel`` wraps. With ``codes=True`` the frame is first converted
    /// (untimed) to the drivers' compact codes, what the Monte Carlo hands the array: the
    /// difference is the decoding's cost, which the input's form, not Python, sets.
    #[pyo3(name = "_time_library_run_pixel", signature = (valid, tdc, repeat=1, codes=false))]
    fn time_library_run_pixel(
        &self,
        py: Python<'_>,
        valid: &Bound<'_, PyAny>,
        tdc: &Bound<'_, PyAny>,
        repeat: usize,
        codes: bool,
    ) -> PyResult<f64> {
        let valid_a = convert::bool_array("valid", valid)?;
        let tdc_a = convert::codes("tdc", tdc)?;
        let (valid_s, tdc_s) = self.checked_frame(&valid_a, &tdc_a)?;
        let max_code = self.max_code();
        let compact = if codes {
            Some(
                py.detach(|| tdc_s.compact(valid_s, max_code))
                    .map_err(value_error)?,
            )
        } else {
            None
        };
        let rom = self.rom(py)?.map(|r| &r.image);
        let params = &self.inner.pixel;
        py.detach(|| {
            let mut best = f64::INFINITY;
            for _ in 0..repeat.max(1) {
                let t0 = std::time::Instant::now();
                let mut driver = FrameDriver::new(params, rom)?;
                match &compact {
                    Some(c) => driver.run(c.as_slice(), 0)?,
                    None => tdc_s.run_pixel(valid_s, 0, max_code, &mut driver)?,
                }
                std::hint::black_box(driver.readout());
                best = best.min(t0.elapsed().as_secs_f64());
            }
            Ok::<_, PixelError>(best)
        })
        .map_err(value_error)
    }

    /// Pickling: the resolved design travels as its JSON, with its probe ROM once it has
    /// been generated (a Dask worker then does not generate it again).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, PickleState)> {
        let ctor = slf.get_type().getattr("_restore")?;
        let d = slf.get();
        let rom = match d.rom.get() {
            Some(r) => Some(serde_json::to_string(r).map_err(value_error)?),
            None => None,
        };
        Ok((ctor, (d.to_json()?, rom)))
    }

    /// Unpickling (`__reduce__`'s constructor): the design and, when it travelled, its ROM.
    #[staticmethod]
    #[pyo3(signature = (design, rom=None))]
    fn _restore(py: Python<'_>, design: &str, rom: Option<&str>) -> PyResult<Self> {
        let (inner, rom) = py
            .detach(|| -> Result<_, String> {
                let inner = ResolvedDesign::from_json(design).map_err(|e| e.to_string())?;
                let rom = rom
                    .map(serde_json::from_str::<Option<ProbeRom>>)
                    .transpose()
                    .map_err(|e| format!("the pickled probe ROM: {e}"))?;
                Ok((inner, rom))
            })
            .map_err(errors::input)?;
        let d = Design::new(inner);
        if let Some(r) = rom {
            let _ = d.rom.set(r);
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let p = &self.inner.pixel;
        format!(
            "Design(origin={:?}, mode={}, B={}, W={}, N={}, L={})",
            self.inner.origin, p.mode, p.bins, p.width, p.frame_pulses, p.rom_depth
        )
    }
}

/// tofprobe's library from Python: ``tofprobe.Design``.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // The ISA `TOFPROBE_ISA` forces is checked at import, as the CLI checks it at start-up:
    // a kernel cannot return the refusal (it would panic inside the call).
    tofprobe_io::isa::from_env().map_err(|e| errors::input(e.to_string()))?;
    m.add_class::<Design>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
