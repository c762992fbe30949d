//! `tofprobe rtl [CONFIG] --out DIR`: renders the pixel, probe ROM and top for the
//! configuration's `[pixel]` into DIR, atomically, refusing to overwrite files it did not
//! generate. The probe ROM is the configuration's ΣΔ ROM (`probe_rom::rtl_rom`: for the
//! default, periodic L = 20,000, 32 bitstreams) whenever it is at most
//! [`MAX_RENDERED_SD_DEPTH`] deep; a windowed ROM of a long frame (L = N) or `--rom-depth`
//! renders the sign-of-cosine probe instead, and the command says which. Also the shared
//! step "configuration → generator parameters" of the RTL commands (`vectors`, `cosim`,
//! `flow`).

use std::path::{Path, PathBuf};

use clap::Args;
use tofprobe_pixel::PixelContext;
use tofprobe_pixel::PixelParams;
use tofprobe_rtlgen::render::RenderOptions;
use tofprobe_rtlgen::stimulus::sign_probe_rom;
use tofprobe_rtlgen::write::write_generated;

use crate::commands::probe_rom::rtl_rom;
use crate::config::Config;
use crate::error::CliError;
use tofprobe_dsp::sd::ProbeRom;

/// ROM depth used when the configuration leaves L = N and N is a long frame: a periodic
/// probe of this depth (bin spacing f_s/L), not a 10^7-entry ROM.
pub const LONG_FRAME_ROM_DEPTH: usize = 4096;

/// Deepest ΣΔ ROM `tofprobe rtl` renders into a chip ROM (2^16 entries; deeper is a
/// windowed long-frame ROM, which no chip would store).
pub const MAX_RENDERED_SD_DEPTH: usize = 1 << 16;

/// Arguments of `tofprobe rtl`.
#[derive(Debug, Args)]
pub struct RtlArgs {
    /// Configuration file (default: the embedded default).
    pub config: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Override the ROM depth L and render the sign-of-cosine probe ROM instead of the ΣΔ
    /// ROM (default: the configuration's ΣΔ ROM; 4096 sign entries when that exceeds 65536).
    #[arg(long)]
    pub rom_depth: Option<usize>,
    /// Override the pulses per frame N (e.g. short frames for co-simulation).
    #[arg(long)]
    pub frame_pulses: Option<u64>,
}

/// The generator's parameters for a configuration file (or the embedded default), with
/// optional overrides of N and L.
pub fn rtl_params(
    config: Option<&Path>,
    frame_pulses: Option<u64>,
    rom_depth: Option<usize>,
) -> Result<PixelParams, CliError> {
    let loaded = Config::load(config)?;
    let c = &loaded.config;
    let ctx = PixelContext::from_sensor(&c.sensor, loaded.config.pulses());
    let resolved = c.pixel.resolve(&ctx).map_err(|e| CliError::Toml {
        origin: loaded.origin.clone(),
        message: format!("[pixel]: {e}"),
    })?;
    let mut p = resolved;
    if let Some(n) = frame_pulses {
        p.frame_pulses = n;
    }
    p.rom_depth = match rom_depth {
        Some(l) => l,
        None if p.rom_depth > 65_536 => LONG_FRAME_ROM_DEPTH,
        None => p.rom_depth,
    };
    // A periodic chip ROM stays L deep for a short frame (the frame reads its first N
    // entries); a windowed ROM is one frame deep by definition.
    let windowed = c.probe.rom_mode == tofprobe_dsp::sd::RomMode::Windowed;
    if frame_pulses.is_some() && rom_depth.is_none() && windowed {
        p.rom_depth = p.rom_depth.min(p.frame_pulses.max(1) as usize);
    }
    p.validate().map_err(tofprobe_rtlgen::RtlError::from)?;
    Ok(p)
}

/// The command line that regenerates `out` (recorded in every header).
pub fn regen_command(a: &RtlArgs) -> String {
    let mut s = String::from("tofprobe rtl");
    if let Some(c) = &a.config {
        s.push_str(&format!(" {}", c.display()));
    }
    s.push_str(&format!(" --out {}", a.out.display()));
    if let Some(n) = a.frame_pulses {
        s.push_str(&format!(" --frame-pulses {n}"));
    }
    if let Some(l) = a.rom_depth {
        s.push_str(&format!(" --rom-depth {l}"));
    }
    s
}

/// The probe ROM `tofprobe rtl` renders for `p` (setting `p.rom_depth` to its depth), and
/// a line saying which it is.
pub fn chip_rom(
    a: &RtlArgs,
    p: &mut PixelParams,
) -> Result<(Vec<u64>, String, Option<ProbeRom>), CliError> {
    let loaded = Config::load(a.config.as_deref())?;
    let sd_depth = loaded.config.probe.depth(p.frame_pulses);
    if a.rom_depth.is_some() || sd_depth > MAX_RENDERED_SD_DEPTH {
        let why = if a.rom_depth.is_some() {
            "--rom-depth given".to_string()
        } else {
            format!(
                "the {} ΣΔ ROM would be {sd_depth} entries deep (> {MAX_RENDERED_SD_DEPTH})",
                loaded.config.probe.rom_mode.name()
            )
        };
        return Ok((
            sign_probe_rom(p),
            format!("sign-of-cosine probe ROM (L = {}): {why}", p.rom_depth),
            None,
        ));
    }
    let r = rtl_rom(&loaded.config, &loaded.origin, p)?;
    Ok((r.words, r.note, r.sd))
}

/// The ΣΔ ROM's TOML manifest for the rendered hex file `hex_name` (`contents`, header
/// included): bins and frequencies, L, mode, order, OSR, H_inf, A_p, window and its gain,
/// the wrap figures, and the hex file's hash, so `RomManifest::read` loads and checks the
/// committed image and a readout can be normalised without the configuration.
fn rom_manifest(rom: &ProbeRom, hex_name: &str, contents: &str, header: &str) -> String {
    let mut m = rom.manifest();
    m.hex_file = hex_name.to_string();
    m.content_hash = format!("{:016x}", tofprobe_io::fnv1a64(contents.as_bytes()));
    m.depth = rom.depth();
    m.registers = rom.image.registers();
    // Serialising a plain struct of numbers, strings and vectors cannot fail.
    let body = toml::to_string(&m).unwrap_or_default();
    format!("{header}{body}")
}

/// Renders and writes; returns the file names.
pub fn render_to(
    p: &PixelParams,
    rom: &[u64],
    out: &Path,
    command: String,
    rom_note: String,
    sd: Option<&ProbeRom>,
) -> Result<Vec<String>, CliError> {
    let header = format!(
        "# Generated by tofprobe-rtlgen {}: the probe ROM's manifest. DO NOT EDIT: regenerate with `{command}`.\n",
        env!("CARGO_PKG_VERSION")
    );
    let files = tofprobe_rtlgen::render(
        p,
        rom,
        &RenderOptions {
            command,
            rom_note,
            ..RenderOptions::default()
        },
    )?;
    let mut pairs: Vec<(String, String)> =
        files.into_iter().map(|f| (f.name, f.contents)).collect();
    if let Some(sd) = sd {
        let hex = pairs.iter().find(|(n, _)| n.ends_with(".hex")).cloned();
        if let Some((name, contents)) = hex {
            let toml_name = name.trim_end_matches(".hex").to_string() + ".toml";
            pairs.push((toml_name, rom_manifest(sd, &name, &contents, &header)));
        }
    }
    write_generated(out, &pairs)?;
    Ok(pairs.into_iter().map(|(n, _)| n).collect())
}

/// Runs `tofprobe rtl`.
pub fn run(a: &RtlArgs) -> Result<(), CliError> {
    let mut p = rtl_params(a.config.as_deref(), a.frame_pulses, a.rom_depth)?;
    let (rom, note, sd) = chip_rom(a, &mut p)?;
    let names = render_to(
        &p,
        &rom,
        &a.out,
        regen_command(a),
        note.clone(),
        sd.as_ref(),
    )?;
    println!(
        "rtl: {:?} pixel, {} registers x {} bits, {} adder(s), {} cycles/pulse, N = {}, L = {}, hash {} -> {} ({}); {note}",
        p.mode,
        p.registers(),
        p.width,
        p.adders,
        p.cycles_per_pulse,
        p.frame_pulses,
        p.rom_depth,
        tofprobe_rtlgen::config_hash(&p),
        a.out.display(),
        names.join(", ")
    );
    Ok(())
}
