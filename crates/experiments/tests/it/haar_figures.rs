//! The paper's transient figures (Fig. 3, Fig. 12) through `tofprobe_experiments::paper::haar_figures` (moved here from dsp with the reproduction):
//! every row passes its stated check on two seeds, the structural claims hold, and the
//! committed scene files are the same setups.

use tofprobe_dsp::haar::events::DepthChange;
use tofprobe_experiments::paper::haar_figures::{
    TransientSetup, fig3, fig3_setup, fig12, fig12_setup,
};
use tofprobe_scene::{SceneConfig, SensorConfig};

fn print(rows: &[tofprobe_experiments::paper::haar_figures::TransientRow]) {
    for r in rows {
        println!(
            "{} | {} | paper {:?} | measured {:.4} | reference {:?} | ±{} | {} | {}",
            r.figure, r.label, r.paper, r.measured, r.reference, r.tolerance, r.pass, r.note
        );
    }
}

#[test]
fn fig3_structure() {
    for seed in [1, 2] {
        let f = fig3(seed).unwrap();
        print(&f.rows);
        print!("{}", f.events.text());
        for r in &f.rows {
            assert!(r.pass, "seed {seed}: {r:?}");
        }
        assert_eq!(f.scalogram.coefficients.len(), 127);
        assert_eq!(f.scalogram.compression_ratio().round(), 787.0);
        // The impulse's event: up then down, peak at the finest scales.
        let imp = f
            .events
            .events
            .iter()
            .find(|e| e.start_s <= 1.55e-3 && 1.55e-3 < e.end_s)
            .expect("an event at the impulse");
        assert!(imp.peak.u >= 5, "{}", imp.text_line());
    }
}

#[test]
fn fig12_step() {
    for seed in [1, 2] {
        let f = fig12(seed).unwrap();
        print(&f.rows);
        print!("{}", f.events.text());
        for r in &f.rows {
            assert!(r.pass, "seed {seed}: {r:?}");
        }
        assert_eq!(f.events.events.len(), 1);
        let e = &f.events.events[0];
        assert_eq!(e.change, DepthChange::Increase);
        assert_eq!((e.peak.u, e.peak.v), (5, 10));
    }
}

/// A deliberately broken setup fails the check: with the ramp moved to the record's
/// centre (a scale-0 centre) the largest coefficient is no longer at scale 5.
#[test]
fn fig12_claim_can_fail() {
    let mut s = fig12_setup();
    if let tofprobe_scene::MotionConfig::Ramp { start_s, .. } = &mut s.scene.motions[0] {
        *start_s = 0.5 * (1u64 << 19) as f64 / 1e7 - 2e-4;
    }
    let x: Vec<f64> = (0..s.pulses)
        .map(|n| {
            tofprobe_scene::Scene::new(&s.scene)
                .unwrap()
                .depth_mm(n as f64 / 1e7)
        })
        .step_by(1)
        .collect();
    let sc = tofprobe_dsp::haar::Scalogram::from_depths_mm(&x, 6, 1e7).unwrap();
    assert_eq!(sc.largest().u, 0);
}

#[derive(serde::Deserialize)]
struct SceneFile {
    sensor: SensorConfig,
    scene: SceneConfig,
    acquisition: toml::Table,
    pixel: toml::Table,
}

fn load(name: &str) -> SceneFile {
    let path = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
    toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn same(file: &SceneFile, setup: &TransientSetup, pulses: u64) {
    assert_eq!(file.sensor, setup.sensor);
    assert_eq!(file.scene, setup.scene);
    assert_eq!(file.acquisition["pulses"].as_integer(), Some(pulses as i64));
    assert_eq!(file.pixel["mode"].as_str(), Some("haar"));
    assert_eq!(
        file.pixel["haar_scales"].as_integer(),
        Some(i64::from(setup.u_max))
    );
}

#[test]
fn scene_files_are_the_setups() {
    // Fig. 3's file runs the pixel's 2^17 frame over the same scene.
    same(&load("fig3-transients.toml"), &fig3_setup(), 1 << 17);
    same(&load("fig12-step.toml"), &fig12_setup(), 1 << 19);
}
