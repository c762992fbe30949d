//! Running a built harness (or the Icarus testbench) and reading its output lines.

use crate::error::CosimError;
use std::path::Path;
use std::process::Command;

/// The first mismatch a simulator reported.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mismatch {
    pub cycle: u64,
    pub pulse: u64,
    pub signal: String,
    pub expected: String,
    pub actual: String,
}

/// A digest window whose digest differed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DigestMismatch {
    pub window: u64,
    pub first_pulse: u64,
    pub cycle_from: u64,
    pub cycle_to: u64,
}

/// What a run reported in its completion line, and its first mismatches.
#[derive(Debug, Clone, Default)]
pub struct RunOutcome {
    pub cycles: u64,
    pub frames: u64,
    pub mismatches: u64,
    /// Wall time of the replay.
    pub seconds: f64,
    /// CPU time of the replay (the Verilator harness reports it; the Icarus testbench not).
    pub cpu_seconds: Option<f64>,
    pub first: Option<Mismatch>,
    pub digest: Option<DigestMismatch>,
}

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace()
        .find_map(|t| t.strip_prefix(key).and_then(|r| r.strip_prefix('=')))
}

fn num(line: &str, key: &str) -> u64 {
    field(line, key).and_then(|v| v.parse().ok()).unwrap_or(0)
}

/// Parses the harness/testbench protocol (testbench/README.md).
pub fn parse_output(tool: &'static str, text: &str) -> Result<RunOutcome, CosimError> {
    let mut o = RunOutcome::default();
    let mut done = false;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("TOFPROBE-MISMATCH") && o.first.is_none() {
            o.first = Some(Mismatch {
                cycle: num(line, "cycle"),
                pulse: num(line, "pulse"),
                signal: field(line, "signal").unwrap_or("").to_string(),
                expected: field(line, "expected").unwrap_or("").to_string(),
                actual: field(line, "actual").unwrap_or("").to_string(),
            });
        } else if line.starts_with("TOFPROBE-DIGEST-MISMATCH") && o.digest.is_none() {
            o.digest = Some(DigestMismatch {
                window: num(line, "window"),
                first_pulse: num(line, "first_pulse"),
                cycle_from: num(line, "cycle_from"),
                cycle_to: num(line, "cycle_to"),
            });
        } else if line.starts_with("TOFPROBE-COSIM-DONE") {
            done = true;
            o.cycles = num(line, "cycles");
            o.frames = num(line, "frames");
            o.mismatches = num(line, "mismatches");
            o.seconds = field(line, "seconds")
                .and_then(|v| v.parse().ok())
                .unwrap_or(0.0);
            o.cpu_seconds = field(line, "cpu_seconds").and_then(|v| v.parse().ok());
        }
    }
    if done {
        Ok(o)
    } else {
        Err(CosimError::NoCompletion {
            tool,
            output: text.chars().take(4000).collect(),
        })
    }
}

/// Runs the Verilator harness from `rtl_dir` (where `$readmemh` finds the ROM image).
pub fn run(
    exe: &Path,
    rtl_dir: &Path,
    vec_dir: &Path,
    window: Option<(u64, u64)>,
    vcd: Option<(&Path, u64, u64)>,
    x_seed: u64,
) -> Result<RunOutcome, CosimError> {
    let mut cmd = Command::new(exe);
    cmd.current_dir(rtl_dir).arg(vec_dir);
    // Randomised initial register values (built with --x-initial unique): a register that
    // reset forgets starts from a seed-determined random value, not Verilator's zero.
    cmd.arg("+verilator+rand+reset+2")
        .arg(format!("+verilator+seed+{x_seed}"));
    if let Some((lo, hi)) = window {
        cmd.args(["--window", &lo.to_string(), &hi.to_string()]);
    }
    if let Some((f, lo, hi)) = vcd {
        cmd.arg("--vcd")
            .arg(f)
            .args([lo.to_string(), hi.to_string()]);
    }
    let out = cmd.output().map_err(|e| CosimError::io(exe, e))?;
    parse_output(
        "verilator harness",
        &format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// The bare model's times (same inputs, no checking): wall and CPU seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BareRun {
    pub seconds: f64,
    pub cpu_seconds: Option<f64>,
}

/// Runs the bare model (same inputs, no checking), for the overhead figure.
pub fn run_bare(exe: &Path, rtl_dir: &Path, vec_dir: &Path) -> Result<BareRun, CosimError> {
    let out = Command::new(exe)
        .current_dir(rtl_dir)
        .arg(vec_dir)
        .arg("--bare")
        .arg("+verilator+rand+reset+2")
        .arg("+verilator+seed+1")
        .output()
        .map_err(|e| CosimError::io(exe, e))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().find(|l| l.starts_with("TOFPROBE-BARE"));
    let seconds = line
        .and_then(|l| field(l, "seconds"))
        .and_then(|v| v.parse().ok())
        .ok_or(CosimError::NoCompletion {
            tool: "verilator harness --bare",
            output: text.clone().into_owned(),
        })?;
    Ok(BareRun {
        seconds,
        cpu_seconds: line
            .and_then(|l| field(l, "cpu_seconds"))
            .and_then(|v| v.parse().ok()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `seconds=` is not read from `cpu_seconds=` (the key is matched whole), and a line
    /// without `cpu_seconds` (the Icarus testbench's) leaves it unknown.
    #[test]
    fn completion_line_times_are_read_by_their_keys() {
        let o = parse_output(
            "t",
            "TOFPROBE-COSIM-DONE cycles=10 frames=1 mismatches=0 seconds=0.5 cpu_seconds=0.25\n",
        )
        .unwrap();
        assert_eq!((o.cycles, o.seconds, o.cpu_seconds), (10, 0.5, Some(0.25)));
        let o = parse_output(
            "t",
            "TOFPROBE-COSIM-DONE cycles=10 frames=1 mismatches=0 seconds=0.5\n",
        )
        .unwrap();
        assert_eq!((o.seconds, o.cpu_seconds), (0.5, None));
    }
}
