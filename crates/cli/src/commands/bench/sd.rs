//! `tofprobe bench sd [--json] [--svg PATH] [--rom-dir DIR]`: the ΣΔ probe design measured
//! (`tofprobe_bench::sd` measures; this prints). With `--svg`, the spectrum of a 50 kHz
//! probe (the paper's Fig. 2: the noise shaping).

use std::path::PathBuf;

use clap::Args;
use tofprobe_bench::sd::SdReport;

use crate::error::CliError;

/// Arguments of `tofprobe bench sd`.
#[derive(Debug, Args)]
pub struct SdBenchArgs {
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// Write the spectrum of a 50 kHz probe as SVG to this path.
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Also write the 16-bin ROM ($readmemh hex + TOML manifest) into this directory.
    #[arg(long)]
    rom_dir: Option<PathBuf>,
}

/// Runs the benchmark.
pub fn run(args: &SdBenchArgs) -> Result<(), CliError> {
    let report = tofprobe_bench::sd::measure(args.svg.as_deref(), args.rom_dir.as_deref())?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&report);
    }
    Ok(())
}

fn print_text(r: &SdReport) {
    println!("sigma-delta probe design (order 3, OSR 32, H_inf 1.5, f_s = 10 MHz)");
    println!(
        "  max stable amplitude: DC {:.4}, 1 kHz {:.4}, 4.5 kHz {:.4}, 50 kHz {:.4} (probe limit 0.9x)",
        r.max_stable_amplitude_dc,
        r.max_stable_amplitude_1khz,
        r.max_stable_amplitude_4500hz,
        r.max_stable_amplitude_50khz
    );
    println!("  in-band SNR at amplitude 0.5 (-6 dBFS), measured / eq. 4, dB:");
    print!("    order\\OSR");
    for osr in [8, 16, 32, 64, 128] {
        print!("{osr:>16}");
    }
    println!();
    for order in 1..=4 {
        print!("    {order:>9}");
        for row in r.snr_table.iter().filter(|x| x.order == order) {
            print!(
                "{:>16}",
                format!("{:.1} / {:.1}", row.measured_snr_db, row.eq4_snr_db)
            );
        }
        println!();
    }
    println!(
        "  band edge 156.25 kHz: {:.1} dB at A = 0.5, {:.1} dB at A = 0.7 (eq. 4: {:.1} dB)",
        r.snr_db_156khz_amplitude_0_5,
        r.snr_db_156khz_amplitude_0_7,
        r.eq4_snr_db_156khz_amplitude_0_7
    );
    println!(
        "  12 bits (74 dB = 6.02·12 + 1.76, ENOB = (SNR − 1.76)/6.02) up to {:.0} kHz measured (A = 0.7); eq. 4: {:.0} kHz at A = 0.7, {:.0} kHz at full scale; \
         the paper's 297 kHz reads ENOB = SNR_dB/6.02 (12 bits = 72.24 dB): eq. 4 at full scale gives {:.0} kHz that way",
        r.band_hz_12_bits_measured / 1e3,
        r.band_hz_12_bits_eq4 / 1e3,
        r.band_hz_12_bits_eq4_full_scale / 1e3,
        r.band_hz_12_bits_eq4_full_scale_paper_enob / 1e3
    );
    println!(
        "  ROM {} bins x N = {}: {:.3} s on {} threads, {:.3} s on one ({:.3e} / {:.3e} modulator samples/s); target <= {} s: {}",
        r.rom_bins,
        r.rom_pulses,
        r.rom_seconds_all_threads,
        r.threads,
        r.rom_seconds_one_thread,
        r.modulator_samples_per_s_all_threads,
        r.modulator_samples_per_s_one_thread,
        r.rom_target_seconds,
        if r.pass { "pass" } else { "FAIL" }
    );
    if let Some(c) = r.rom_cpu_seconds_all_threads {
        println!(
            "  ROM CPU time (all threads): {c:.3} s, i.e. {:.3} s of wall time on 2 idle cores",
            c / 2.0
        );
    }
    println!(
        "  default chip ROM (periodic, L = {}, 16 bins): {:.3} s; {} (clean at ≤ {:.0e}), state mismatch {:.3}",
        r.periodic_rom_depth,
        r.periodic_rom_seconds,
        r.periodic_rom_wrap_summary,
        tofprobe_dsp::sd::probe::WRAP_TOLERANCE,
        r.periodic_rom_wrap_state_mismatch
    );
    println!(
        "  full-band prober, one core: scalar reference {:.3e} steps/s; {} path: f64 lanes {:.3e} ({:.1}x), f32 lanes {:.3e} ({:.1}x); \
         baseline path: f64 {:.3e} ({:.1}x), f32 {:.3e} ({:.1}x)",
        r.scalar_reference_steps_per_s_per_core,
        r.fullband_path,
        r.fullband_f64_steps_per_s_per_core,
        r.fullband_f64_speedup_vs_scalar,
        r.fullband_f32_steps_per_s_per_core,
        r.fullband_f32_speedup_vs_scalar,
        r.fullband_f64_baseline_steps_per_s_per_core,
        r.fullband_f64_baseline_speedup_vs_scalar,
        r.fullband_f32_baseline_steps_per_s_per_core,
        r.fullband_f32_baseline_speedup_vs_scalar
    );
    if let Some(p) = &r.svg {
        println!("  spectrum of a 50 kHz probe: {p}");
    }
}
