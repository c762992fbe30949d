//! The paper's transient figures render: Fig. 3 (N = 100,000, unequal halves) and Fig. 12
//! (the pixel's 2^19 frame) as SVG with their events, and as JSON. Set
//! TOFPROBE_SCALOGRAM_DIR to keep the files for a look.

use tofprobe_experiments::paper::haar_figures::{fig3, fig12};
use tofprobe_experiments::scalogram::{scalogram_json, scalogram_svg};

#[test]
fn paper_scalograms_render() {
    for (name, f) in [("fig3", fig3(1).unwrap()), ("fig12", fig12(1).unwrap())] {
        let svg = scalogram_svg(&f.scalogram, name, Some(&f.events)).unwrap();
        assert!(svg.matches("<rect").count() > 127 + 100, "{name}");
        assert!(!svg.contains("NaN"));
        // Readable at the size the file opens: every label ≥ 8 px (the colour bar's were 4).
        assert_eq!(
            tofprobe_experiments::paper::svg_check::problems(&svg),
            Vec::<String>::new(),
            "{name}"
        );
        let json = scalogram_json(&f.scalogram, Some(&f.events)).unwrap();
        assert!(json.contains("\"value_mm\""));
        if let Ok(dir) = std::env::var("TOFPROBE_SCALOGRAM_DIR") {
            std::fs::write(format!("{dir}/{name}.svg"), svg).unwrap();
            std::fs::write(format!("{dir}/{name}.json"), json).unwrap();
        }
    }
}

/// The reproduction's Fig. 3 and Fig. 12 carry the paper's values beside the measured ones
/// (Fig. 12's 1.5 ms scale and 27.7 m/s rate; Fig. 3's 127 coefficients) and pass the
/// layout check; without the notes the paper's rate would not be on the figure.
#[test]
fn reproduce_scalograms_mark_the_paper_values() {
    use tofprobe_experiments::paper::{svg_check, transients};
    let figs = transients::figures().unwrap();
    let svgs = transients::svgs(&figs).unwrap();
    let find = |name: &str| &svgs.iter().find(|(n, _)| n == name).unwrap().1;
    let fig12 = find("fig12_scalogram.svg");
    for text in [
        "(paper 27.7 m/s)",
        "(paper 1.5 ms)",
        "ramp-rate estimate 4·|w|/T_5: measured",
    ] {
        assert!(fig12.contains(text), "Fig. 12 lacks `{text}`");
    }
    assert!(find("fig3_scalogram.svg").contains("(paper 127)"));
    for (name, svg) in &svgs {
        assert_eq!(svg_check::problems(svg), Vec::<String>::new(), "{name}");
    }
    // The notes are what carries them: the bare heat map has no paper value.
    let bare =
        tofprobe_experiments::scalogram::scalogram_svg(&figs[1].scalogram, "x", None).unwrap();
    assert!(!bare.contains("27.7"));
}
