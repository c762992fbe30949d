//! The paper's transient figures render: Fig. 3 (N = 100,000, unequal halves) and Fig. 12
//! (the pixel's 2^19 frame) as SVG with their events, and as JSON. Set
//! TOFPROBE_SCALOGRAM_DIR to keep the files for a look.

use tofprobe_dsp::haar::paper::{fig3, fig12};
use tofprobe_experiments::scalogram::{scalogram_json, scalogram_svg};

#[test]
fn paper_scalograms_render() {
    for (name, f) in [("fig3", fig3(1).unwrap()), ("fig12", fig12(1).unwrap())] {
        let svg = scalogram_svg(&f.scalogram, name, Some(&f.events)).unwrap();
        assert!(svg.matches("<rect").count() > 127 + 100, "{name}");
        assert!(!svg.contains("NaN"));
        let json = scalogram_json(&f.scalogram, Some(&f.events)).unwrap();
        assert!(json.contains("\"value_mm\""));
        if let Ok(dir) = std::env::var("TOFPROBE_SCALOGRAM_DIR") {
            std::fs::write(format!("{dir}/{name}.svg"), svg).unwrap();
            std::fs::write(format!("{dir}/{name}.json"), json).unwrap();
        }
    }
}
