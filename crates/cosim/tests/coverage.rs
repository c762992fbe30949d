//! Line coverage of the pixel module under the CI stimuli (Verilator `--coverage`,
//! `verilator_coverage --annotate`): every line with a coverage point is hit, except the
//! ones listed in `NEEDS_REFUSALS` — lines that only a refused pulse can reach (the
//! reference sequencer never refuses one; see crates/cosim/tests/mutations.rs) — and
//! `DEAD`: the `default` arm of an adder's slot case (and of its read-ahead case) when the slot counter's 2^bits values
//! are all listed slots (K a power of two), kept so the case is full for lint.

mod common;
use common::*;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_pixel::Mode;

/// Source fragments of the lines only a refused pulse reaches (the refused counter's
/// increment and the saturation compare, the Haar frame-full compare's false arm).
const NEEDS_REFUSALS: &[&str] = &["refused <= refused +", "refused != "];
const DEAD: &[&str] = &["default: begin yin_", "default: begin rd_"];

#[test]
fn pixel_lines_are_covered_except_the_refusal_path() {
    if !tools_or_skip(
        &["verilator", "verilator_coverage"],
        "pixel_lines_are_covered_except_the_refusal_path",
    ) {
        return;
    }
    for mode in [Mode::Fourier, Mode::Haar] {
        let mut p = short_default(mode);
        p.frame_pulses = 16;
        p.rom_depth = 16;
        p.bins = 2;
        p.haar_scales = 2;
        p.adders = 2;
        p.cycles_per_pulse = 3;
        p.validate().expect("valid");
        let mut o = CosimOptions::new(work_dir(&format!("coverage-{mode:?}")));
        o.frames = 2;
        o.lead_misses = 3;
        o.coverage = true;
        o.vcd_on_mismatch = false;
        let r = cosim(&p, &o).expect("runs");
        assert!(r.pass, "{:?}", r.first);
        let c = r.coverage.expect("coverage measured");
        eprintln!(
            "{mode:?}: {} of {} lines with coverage points hit ({:.1}%); not hit: {:?}",
            c.covered,
            c.lines,
            c.percent(),
            c.uncovered
        );
        assert!(c.lines > 20, "too few coverage points: {c:?}");
        for (line, text) in &c.uncovered {
            assert!(
                NEEDS_REFUSALS.iter().chain(DEAD).any(|f| text.contains(f)),
                "{mode:?}: line {line} `{text}` is not covered"
            );
        }
    }
}
