//! Line coverage of the pixel module under the CI stimuli (Verilator `--coverage`,
//! `verilator_coverage --annotate`). The CI set per mode: the reference sequencer with
//! frames starting with misses, and the directed sequencer (docs/pixel-contract.md, "The
//! directed sequencer") on the same RTL (only the top differs, so the pixel's lines add up
//! line by line). Together they hit every line with a coverage point: 100%. The read-ahead
//! case's `default` arm, unreachable for every K (its selector is slot + 1 ≤ K − 1, or 0)
//! and kept so the case is full for lint, is marked `verilator coverage_off` in the
//! template and has no coverage point. On a K = 3 pixel the directed run alone hits every
//! line.

use crate::common;
use common::*;
use std::collections::BTreeSet;
use tofprobe_cosim::{CosimOptions, cosim};
use tofprobe_pixel::{DirectedOptions, Mode};

/// Source fragments of the lines only a refused pulse reaches (the refused counter's
/// increment and the saturation compare): the reference sequencer alone misses them.
const NEEDS_REFUSALS: &[&str] = &["refused <= refused +", "refused != "];

#[test]
fn pixel_lines_are_covered_by_the_ci_set() {
    if !tools_or_skip(
        &["verilator", "verilator_coverage"],
        "pixel_lines_are_covered_by_the_ci_set",
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
        let run = |p: &tofprobe_pixel::PixelParams, name: &str, directed| {
            let mut o = CosimOptions::new(work_dir(&format!("coverage-{mode:?}-{name}")));
            o.frames = 2;
            o.lead_misses = 3;
            o.coverage = true;
            o.vcd_on_mismatch = false;
            o.directed = directed;
            let r = cosim(p, &o).expect("runs");
            assert!(r.pass, "{mode:?} {name}: {:?}", r.first);
            let c = r.coverage.expect("coverage measured");
            eprintln!(
                "{mode:?} {name}: {} of {} lines with coverage points hit ({:.1}%); not hit: {:?}",
                c.covered,
                c.lines,
                c.percent(),
                c.uncovered
            );
            assert!(c.lines > 20, "too few coverage points: {c:?}");
            c
        };
        let reference = run(&p, "reference", None);
        for (line, text) in &reference.uncovered {
            assert!(
                NEEDS_REFUSALS.iter().any(|f| text.contains(f)),
                "{mode:?}: line {line} `{text}` is not covered by the reference run"
            );
        }
        let directed = run(&p, "directed", Some(DirectedOptions::default()));
        assert_eq!(directed.lines, reference.lines, "the same pixel file");
        let missed = |c: &tofprobe_cosim::coverage::Coverage| -> BTreeSet<usize> {
            c.uncovered.iter().map(|(l, _)| *l).collect()
        };
        let both: Vec<_> = reference
            .uncovered
            .iter()
            .filter(|(l, _)| missed(&directed).contains(l))
            .collect();
        let set_covered = reference.lines - both.len();
        eprintln!(
            "{mode:?} CI set: {set_covered} of {} lines hit; not hit by either run: {both:?}",
            reference.lines
        );
        assert!(
            both.is_empty(),
            "{mode:?}: lines covered by no CI run: {both:?}"
        );
        // The unreachable default arm carries no coverage point (coverage_off), so 100% is
        // of every line that has one; a template losing the pragma fails here.
        assert_eq!(set_covered, reference.lines, "{mode:?}");
        // The refusal lines the reference run misses, the directed run hits.
        assert!(
            reference
                .uncovered
                .iter()
                .any(|(_, t)| NEEDS_REFUSALS.iter().any(|f| t.contains(f))),
            "{mode:?}: the reference run reaches the refusal lines: the test shows nothing"
        );
        // K = 3 (the slot counter idles at K, so the slot case's default arm is live): the
        // directed run alone hits every line.
        let k3 = directed_config(mode);
        let full = run(&k3, "directed-k3", Some(DirectedOptions::default()));
        assert!(full.uncovered.is_empty(), "{mode:?} K = 3: {full:?}");
    }
}
