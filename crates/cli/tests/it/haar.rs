//! The Haar pixel through the binary (issue 18): `simulate` on the shipped Fig. 12 scene
//! (events, thresholds, the ramp rate; `--json`, `--svg`), `mode = "auto"`, the Haar frame's
//! refusals and notes through the one resolution, the Haar trade-off ladder, `flow` on a
//! small Haar frame and `reproduce`'s Fig. 3 / Fig. 12 rows.

use crate::common;

use std::path::PathBuf;

use common::{edit, tofprobe};
use serde_json::Value;

fn fig12() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/fig12-step.toml"
    ))
    .expect("scene")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tofprobe-haar-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch");
    dir
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p.to_str().expect("utf-8").to_string()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const SCENE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/fig12-step.toml");

/// Fig. 12's ramp is centred at 17.2032 ms; the event's centre must lie within one finest
/// wavelet (T/2^6 = 0.8192 ms) of it, and the rate 4|w|/T_5 within 5 sd of the noise
/// (0.29 m/s) of the closed form (2h/T_5)(1 − D/(2T_5)) = 26.79 m/s (scenes/fig12-step.toml).
/// The depth increases, so the peak coefficient is negative (the paper's convention).
#[test]
fn simulate_fig12_prints_the_step_event_with_its_rate() {
    let o = tofprobe(&["simulate", SCENE]);
    let text = stdout(&o);
    assert!(o.status.success(), "{text}{}", stderr(&o));
    for part in [
        "analysis mode      haar (pixel.mode)",
        "127 coefficients",
        "w > 0 = depth decreases",
        "false-alarm probability 0.01 per frame",
        "threshold mm",
        "1 event(s)",
        "depth increases",
        "scene transients: 17.003–17.403 ms",
    ] {
        assert!(text.contains(part), "missing `{part}`:\n{text}");
    }
    let line = text
        .lines()
        .find(|l| l.contains("event 1:"))
        .expect("an event");
    let centre: f64 = line
        .split("event 1: ")
        .nth(1)
        .and_then(|s| s.split(" ms").next())
        .and_then(|s| s.trim().parse().ok())
        .expect("centre");
    assert!((centre - 17.2032).abs() <= 0.8192, "{line}");
    let rate: f64 = line
        .split("paper's estimator −4w/T_u = ")
        .nth(1)
        .and_then(|s| s.split(" m/s").next())
        .and_then(|s| s.trim().parse().ok())
        .expect("rate");
    assert!((rate - 26.79).abs() < 0.29, "{line}");
    assert!(line.contains("peak w(5,10) = -"), "{line}");
    // The 0.4 ms ramp is shorter than a finest wavelet (0.819 ms): step-like, with bounds,
    // and the paper's figure flagged as averaged over a longer wavelet.
    assert!(
        line.contains("step-like (no finite duration resolved)"),
        "{line}"
    );
    assert!(line.contains("duration < 0.819 ms"), "{line}");
    assert!(line.contains("not its rate"), "{line}");
}

const SLOW_RAMP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/slow-ramp.toml");

/// Issue 32 through the binary: the slow ramp (−6 mm over 8 ms, ρ_s = 1, 2^19 pulses,
/// U = 6) is one event, in text and in `--json`, a resolved ramp whose measured mean rate
/// is −0.75 m/s within 20 % and duration 8 ms within 20 %; the paper's estimator sits
/// under its own key, and every number's key names its unit.
#[test]
fn simulate_a_slow_ramp_reports_one_event_with_its_measured_rate() {
    let o = tofprobe(&["simulate", SLOW_RAMP]);
    let text = stdout(&o);
    assert!(o.status.success(), "{text}{}", stderr(&o));
    assert!(text.contains("1 event(s)"), "{text}");
    assert!(
        text.contains("event 1:") && !text.contains("event 2:"),
        "{text}"
    );
    let line = text.lines().find(|l| l.contains("event 1:")).unwrap();
    let rate: f64 = line
        .split("height/duration = ")
        .nth(1)
        .and_then(|s| s.split(" ± ").next())
        .and_then(|s| s.trim().parse().ok())
        .expect("the measured rate");
    assert!((rate / -0.75 - 1.0).abs() < 0.2, "{line}");

    let o = tofprobe(&["simulate", SLOW_RAMP, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    let ev = v["haar"]["events"]["events"].as_array().expect("events");
    assert_eq!(ev.len(), 1, "{}", v["haar"]["events"]);
    let e = &ev[0];
    assert_eq!(e["shape"], "ramp");
    let r = e["mean_rate_m_per_s"].as_f64().expect("measured rate");
    assert!((r / -0.75 - 1.0).abs() < 0.2, "{e}");
    let d = e["duration_s"].as_f64().expect("measured duration");
    assert!((d / 8e-3 - 1.0).abs() < 0.2, "{e}");
    assert!(e["height_mm"].as_f64().unwrap() < -5.0, "{e}");
    assert!(e["paper_rate_m_per_s"].as_f64().is_some(), "{e}");
    assert!(e.get("rate_m_per_s").is_none(), "{e}");
    assert!(e["duration_upper_bound_s"].is_null() && e["abs_rate_lower_bound_m_per_s"].is_null());
    // Fig. 12's 0.4 ms ramp is step-like in JSON too: bounds, no measured rate.
    let o = tofprobe(&["simulate", SCENE, "--json"]);
    let v: Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    let e = &v["haar"]["events"]["events"][0];
    assert_eq!(e["shape"], "step", "{e}");
    assert!(e["mean_rate_m_per_s"].is_null(), "{e}");
    assert_eq!(e["peak_wavelet_longer_than_event"], true, "{e}");
    let lb = e["abs_rate_lower_bound_m_per_s"]
        .as_f64()
        .expect("a lower bound");
    // |h|/T_6 = 25 mm / 0.8192 ms = 30.5 m/s: below the true 62.5 m/s, as a bound must be.
    assert!(lb > 25.0 && lb < 62.5, "{e}");
}

#[test]
fn simulate_fig12_json_carries_the_scalogram_and_svg_draws_it() {
    let dir = scratch("json");
    let svg = dir.join("fig12.svg");
    let o = tofprobe(&["simulate", SCENE, "--json", "--svg", svg.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    assert_eq!(v["mode"], "haar");
    let h = &v["haar"];
    let cs = h["scalogram"]["coefficients"]
        .as_array()
        .expect("coefficients");
    assert_eq!(cs.len(), 127);
    // Register 2^5 − 1 + 10 = 41 is w(5,10): the ramp's wavelet, 16.384–18.022 ms.
    let c = &cs[41];
    assert_eq!((c["u"].as_u64(), c["v"].as_u64()), (Some(5), Some(10)));
    assert!((c["start_s"].as_f64().unwrap() - 0.016384).abs() < 1e-12);
    assert!((c["end_s"].as_f64().unwrap() - 0.0180224).abs() < 1e-12);
    assert!(c["value_mm"].as_f64().unwrap() < -10.0, "{c}");
    let ev = h["events"]["events"].as_array().expect("events");
    assert_eq!(ev.len(), 1);
    assert_eq!(ev[0]["change"], "increase");
    assert_eq!(h["events"]["family_rate"].as_f64(), Some(0.01));
    assert_eq!(h["thresholds"].as_array().map(Vec::len), Some(7));
    let text = std::fs::read_to_string(&svg).expect("svg written");
    assert!(text.starts_with("<svg") || text.starts_with("<?xml"), "svg");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `mode = "auto"`: the ramp scene picks Haar (U = 6 when not given), the default's tone
/// picks Fourier, a mixed scene gets a note, and N not a power of two names the nearest.
#[test]
fn mode_auto_picks_from_the_scene_and_says_why() {
    let dir = scratch("auto");
    let auto = edit(
        fig12(),
        &[
            ("mode = \"haar\"", "mode = \"auto\""),
            ("haar_scales = 6", ""),
        ],
    );
    let p = write(&dir, "auto.toml", &auto);
    let o = tofprobe(&["config", &p]);
    let text = stdout(&o);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        text.contains("haar (pixel.mode = \"auto\": transient motion only: scene.motion[0] (ramp)"),
        "{text}"
    );
    assert!(text.contains("U = 6 (127 registers)"), "{text}");
    let o = tofprobe(&["simulate", &p]);
    assert!(stdout(&o).contains("event 1:"), "{}", stdout(&o));

    let tone = edit(
        common::default_text(),
        &[("mode = \"fourier\"", "mode = \"auto\"")],
    );
    let o = tofprobe(&["config", &write(&dir, "tone.toml", &tone)]);
    assert!(
        stdout(&o).contains("fourier (pixel.mode = \"auto\": periodic motion only"),
        "{}",
        stdout(&o)
    );
    let mixed = edit(
        tone,
        &[(
            "[acquisition]",
            "[[scene.motion]]\nkind = \"step\"\nat_s = 0.5\nheight_mm = 1.0\n\n[acquisition]",
        )],
    );
    let o = tofprobe(&["config", &write(&dir, "mixed.toml", &mixed)]);
    let text = stdout(&o);
    assert!(
        text.contains("note: the scene also has transients (scene.motion[1] (step))")
            && text.contains("mode = \"haar\""),
        "{text}"
    );
    let odd = edit(auto, &[("pulses = 524288", "pulses = 500000")]);
    let o = tofprobe(&["config", &write(&dir, "odd.toml", &odd)]);
    let e = stderr(&o);
    assert!(!o.status.success());
    assert!(
        e.contains("picked by pixel.mode = \"auto\"")
            && e.contains("acquisition.pulses")
            && e.contains("262144 (2^18) and 524288 (2^19)"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad Haar input is refused (or noted) by the one resolution: every command says the same.
#[test]
fn haar_refusals_and_notes_are_the_same_for_every_command() {
    let dir = scratch("bad");
    let cases = [
        (
            edit(fig12(), &[("pulses = 524288", "pulses = 600000")]),
            "524288 (2^19) and 1048576 (2^20)",
        ),
        (
            edit(fig12(), &[("haar_scales = 6", "haar_scales = 19")]),
            "U = 18 is the largest that works",
        ),
        (
            edit(
                fig12(),
                &[(
                    "haar_scales = 6",
                    "haar_scales = 6\nfrequencies_hz = [4500.0]",
                )],
            ),
            "pixel.frequencies_hz",
        ),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let p = write(&dir, &format!("bad{i}.toml"), text);
        for cmd in ["config", "simulate", "tradeoff", "size"] {
            let o = tofprobe(&[cmd, &p]);
            let e = stderr(&o);
            assert!(!o.status.success(), "{cmd} accepted case {i}");
            assert!(e.contains(want), "{cmd}, case {i}: {e}");
        }
    }
    // A transient after the frame, and a [probe] the Haar pixel ignores: notes.
    let late = edit(
        fig12(),
        &[
            ("start_s = 17.0032e-3", "start_s = 0.1"),
            ("[pixel]", "[probe]\norder = 2\n\n[pixel]"),
        ],
    );
    let p = write(&dir, "late.toml", &late);
    for cmd in ["config", "simulate"] {
        let o = tofprobe(&[cmd, &p]);
        let text = stdout(&o);
        assert!(
            text.contains("scene.motion[0] (ramp of 25 mm from 100.000000 ms")
                && text.contains("starts after the frame ends at 52.428800 ms"),
            "{cmd}: {text}"
        );
        // The ignored [probe] is a warning on stderr (issue 31), from every command.
        let e = stderr(&o);
        assert!(
            e.contains("[probe] is set but pixel.mode is Haar"),
            "{cmd}: {e}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Haar ladder: the bit-true and cycle-accurate levels equal the float Haar exactly
/// (the held codes times a dyadic LSB of 0.75 mm sum exactly in f64, and the lengths are
/// powers of two), and the event lies within one finest wavelet of the scene's step.
#[test]
fn tradeoff_on_a_haar_scene_has_the_haar_rows() {
    let dir = scratch("tradeoff");
    let small = edit(
        fig12(),
        &[
            ("pulses = 524288", "pulses = 65536"),
            ("start_s = 17.0032e-3", "start_s = 2.4e-3"),
            ("haar_scales = 6", "haar_scales = 4"),
        ],
    );
    let p = write(&dir, "small.toml", &small);
    let o = tofprobe(&["tradeoff", &p, "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Value = serde_json::from_slice(&o.stdout).expect("json");
    let levels = v["haar_scenes"][0]["levels"].as_array().expect("levels");
    let names: Vec<&str> = levels.iter().filter_map(|l| l["level"].as_str()).collect();
    assert_eq!(
        names,
        ["float Haar", "bit-true transaction", "cycle-accurate"]
    );
    for l in levels {
        assert_eq!(l["coefficient_err_mm"].as_f64(), Some(0.0), "{l}");
        assert_eq!(l["events"].as_u64(), Some(1), "{l}");
        assert!(
            l["event_time_err_vs_true_ms"].as_f64().unwrap() <= 0.4096,
            "{l}"
        );
        assert!(l["seconds_per_sim_second"].as_f64().unwrap() > 0.0);
    }
    let o = tofprobe(&["tradeoff", &p]);
    assert!(
        stdout(&o).contains("| bit-true transaction | "),
        "{}",
        stdout(&o)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `flow` on a small Haar frame (U = 4: 31 registers, within the harness's 64): the
/// co-simulated readout becomes the transient analysis and `scalogram.svg`.
#[test]
fn flow_on_a_haar_frame_reports_the_events_and_the_scalogram() {
    if !common::have_tools(&["verilator"]) {
        return;
    }
    let dir = scratch("flow");
    let small = edit(
        fig12(),
        &[
            ("pulses = 524288", "pulses = 4096"),
            ("start_s = 17.0032e-3", "start_s = 0.1e-3"),
            ("duration_s = 4.0e-4", "duration_s = 1.0e-4"),
            ("haar_scales = 6", "haar_scales = 4"),
        ],
    );
    let p = write(&dir, "flow.toml", &small);
    let out = dir.join("out");
    let o = tofprobe(&[
        "flow",
        &p,
        "--out",
        out.to_str().unwrap(),
        "--frame-pulses",
        "4096",
        "--no-size",
    ]);
    let text = stdout(&o);
    assert!(o.status.success(), "{text}{}", stderr(&o));
    assert!(
        text.contains("flow PASS") && text.contains("31 Haar coefficients, 1 event(s)"),
        "{text}"
    );
    let md = std::fs::read_to_string(out.join("report.md")).expect("report");
    assert!(
        md.contains("## Haar transient analysis") && md.contains("event 1:"),
        "{md}"
    );
    assert!(out.join("scalogram.svg").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// `reproduce --quick --json`: the Fig. 3 and Fig. 12 rows with the paper's values beside,
/// passing, and both scalogram SVGs written. (Exit status 1 means another family's row
/// missed; this test judges the Haar rows only.)
#[test]
fn reproduce_shows_fig3_and_fig12() {
    // The one shared run of this test binary (reproduce.rs reads it too).
    let (o, dir) = common::reproduce_quick();
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(o));
    let v: Value = serde_json::from_slice(&o.stdout).expect("json");
    let rows = v["rows"].as_array().expect("rows");
    let haar: Vec<&Value> = rows
        .iter()
        .filter(|r| r["family"].as_str().is_some_and(|f| f.contains("(Haar)")))
        .collect();
    assert!(haar.len() >= 10, "{haar:?}");
    for r in &haar {
        assert_eq!(r["pass"], true, "{r}");
    }
    let rate = haar
        .iter()
        .find(|r| r["label"].as_str().unwrap().starts_with("ramp-rate"))
        .expect("rate row");
    assert_eq!(rate["paper"].as_f64(), Some(27.7));
    let fig3 = haar
        .iter()
        .find(|r| r["label"] == "compression, 100,000 timestamps")
        .expect("fig3 compression");
    assert_eq!(fig3["paper"].as_f64(), Some(787.0));
    assert!(dir.join("fig3_scalogram.svg").is_file() && dir.join("fig12_scalogram.svg").is_file());
}
