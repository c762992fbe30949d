//! The one finite-JSON check of every command's `--json` (docs/reliability.md): every
//! number is finite, and a `null` (which is what serde_json writes for NaN and ±inf) only
//! stands where the command documents an absent figure.

use serde_json::Value;

/// The keys whose value may be `null`, with why: each is an `Option` the command
/// documents, never a float that went bad.
pub const NULLABLE: &[&str] = &[
    // simulate/replay: statistics of an empty record (no detections / fewer than two).
    "mean_depth_mm",
    "sigma_depth_mm",
    // simulate/replay: the spectrum of a frame without detections.
    "amplitude_um",
    "phase_deg",
    "noise_estimate_um",
    "median_amplitude_um",
    "float_amplitude_um",
    "measured_floor_um",
    // replay: the closed-form floor needs ρ > 0 and two detections.
    "closed_form_floor_um",
    "floor_ratio",
    // replay: the first-pass fit, absent when a configuration is given.
    "fitted",
    // reproduce: a row's reference (the paper's, the closed form's) or its seed spread
    // where the row has none.
    "paper",
    "design",
    "closed_form",
    "same_record_dft",
    "same_record_tolerance",
    "seed_sd",
    "z_paper",
    "z_closed_form",
    "band_hz",
    // size: the paper's Section 8 figures that the paper does not print.
    "printed",
    // size: figures of a tool that was not run (--no-sky130, no timing on the liberty).
    "model",
    "sky130",
    "sky130_area_um2",
    // tradeoff: a scene whose tone is on no bin has no amplitude to score; a level that
    // was not run has no timing.
    "true_amplitude_um",
    "amplitude_err_vs_dft_um",
    "amplitude_err_vs_true_um",
    "seconds_per_sim_second",
    "coefficient_err_mm",
    "events",
    "event_time_err_vs_float_ms",
    "event_time_err_vs_true_ms",
    "rejected",
    "width_bits",
    "bins",
    "rom_depth_entries",
    "bit_true_seconds_per_sim_second",
    "noise_um",
    "float_dft_amplitude_um",
    "float_dft_noise_um",
    "noise_rel_err_vs_dft",
    "noise_rel_err_vs_closed_form",
    // bench: CPU time where the platform has no per-thread clock.
    "cpu_seconds",
    // cosim: figures of options not given (--coverage, --bare, --trace), no mismatch.
    "coverage_percent",
    "bare_verilator_seconds",
    "harness_overhead_ratio",
    "bare_cycle_model_seconds",
    "bare_cycle_model_vs_verilator",
    // cosim: CPU times where the platform has none (the Icarus testbench reports none).
    "cycle_model_cpu_seconds",
    "verilator_cpu_seconds",
    "cycle_model_cycles_per_cpu_s",
    "verilator_cycles_per_cpu_s",
    "first",
    "vcd",
    "first_mismatch_actual",
    "first_mismatch_cycle",
    "first_mismatch_expected",
    "first_mismatch_pulse",
    "first_mismatch_signal",
    "uncovered_lines",
    // bench sd: the SVG path when none was asked for.
    "svg",
];

/// Counts of one walk: numbers checked and nulls met (on allowed keys).
#[derive(Debug, Default, Clone, Copy)]
pub struct Walk {
    pub numbers: usize,
    pub nulls: usize,
}

/// Every number of `v` finite; a `null` only under a key of [`NULLABLE`]. Panics listing
/// the paths of every offence; returns what it checked.
pub fn assert_finite(what: &str, v: &Value) -> Walk {
    let mut w = Walk::default();
    let mut bad = Vec::new();
    walk("$", "", v, &mut w, &mut bad);
    assert!(
        bad.is_empty(),
        "{what}: null where no absent figure is documented (NaN or infinity?) or not finite: {bad:?}"
    );
    w
}

fn walk(path: &str, key: &str, v: &Value, w: &mut Walk, bad: &mut Vec<String>) {
    match v {
        Value::Null => {
            if !NULLABLE.contains(&key) {
                bad.push(path.to_string());
            }
            w.nulls += 1;
        }
        Value::Number(n) => {
            if !n.as_f64().is_some_and(f64::is_finite) {
                bad.push(format!("{path} = {n}"));
            }
            w.numbers += 1;
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                walk(&format!("{path}[{i}]"), key, x, w, bad);
            }
        }
        Value::Object(o) => {
            for (k, x) in o {
                walk(&format!("{path}.{k}"), k, x, w, bad);
            }
        }
        Value::Bool(_) | Value::String(_) => {}
    }
}

/// Parses one command's stdout as one JSON object and checks it; the text itself must not
/// spell NaN or infinity either.
pub fn assert_finite_output(what: &str, stdout: &[u8]) -> Walk {
    let text = String::from_utf8_lossy(stdout);
    let v: Value = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{what}: not one JSON object ({e}): {text}"));
    assert!(v.is_object(), "{what}: not an object");
    assert_finite(what, &v)
}
