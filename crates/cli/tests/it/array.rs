//! `tofprobe simulate CONFIG --out DIR` on `[array]` configurations, as users run it: the
//! set is written whole (summary.json listing every file, then the completion marker with
//! their hashes), the NPY arrays have the
//! documented shapes and read back, the UFF file holds its data sets, `--json` carries the
//! figures; bad arrays are refused naming the field with exit 2 and nothing written;
//! commands that run one pixel refuse an array, naming what runs it.

use std::path::Path;
use std::process::Command;

use tofprobe_io::npy;

fn config(dir: &Path, name: &str, motions: &str, array: &str) -> std::path::PathBuf {
    let text = include_str!("../../../../scenes/plate-mode.toml");
    let head = text.split("[[scene.motion]]").next().unwrap();
    let tail = &text[text.find("[acquisition]").unwrap()..];
    let tail = tail.split("[array]").next().unwrap();
    let tail = tail.replacen("pulses = 1000000", "pulses = 40000", 1);
    let p = dir.join(name);
    std::fs::write(&p, format!("{head}{motions}\n{tail}\n[array]\n{array}\n")).unwrap();
    p
}

const PLATE: &str = "[[scene.motion]]\nkind = \"plate_mode\"\nm = 2\nn = 1\nlength_x_mm = 40.0\n\
                     length_y_mm = 30.0\namplitude_mm = 1.0\nfrequency_hz = 1500.0\n";

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tofprobe"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn an_array_simulation_writes_its_whole_set() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = config(
        tmp.path(),
        "plate.toml",
        PLATE,
        "rows = 3\ncols = 4\npitch_um = 30.0\nmm_per_pixel = 10.0",
    );
    let out = tmp.path().join("out");
    let o = run(&[
        "simulate",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary, on_disk, "stdout's summary is the set's");
    let files: Vec<&str> = summary["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    assert_eq!(files.last(), Some(&"summary.json"), "the summary is last");
    let mut listed: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    listed.sort();
    // The files, and the completion marker listing each with its hash (written last).
    let mut want: Vec<String> = files.iter().map(|s| s.to_string()).collect();
    want.push("tofprobe-set.toml".into());
    want.sort();
    assert_eq!(listed, want, "exactly the listed files and the marker");
    let marked = tofprobe_io::check_set(&out, "tofprobe-set.toml").unwrap();
    let mut files_sorted: Vec<String> = files.iter().map(|s| s.to_string()).collect();
    files_sorted.sort();
    assert_eq!(
        marked, files_sorted,
        "the marker lists every file of the summary"
    );
    let regs = npy::from_bytes(&std::fs::read(out.join("registers.npy")).unwrap()).unwrap();
    assert_eq!(regs.shape, vec![3, 4, 8], "[R, C, 2B]");
    let amp = npy::from_bytes(&std::fs::read(out.join("amplitude_um.npy")).unwrap()).unwrap();
    assert_eq!(amp.shape, vec![4, 3, 4], "[B, R, C]");
    // The (2, 1) mode of a 40 × 30 mm plate seen by 10 mm pixels: columns 0 and 3 sit at
    // x = 5 and 35 mm, |sin(2π·5/40)| = 0.71 of 1 mm × sin(π·15/30) = 1 in row 1.
    let b = summary["dominant_bin"].as_u64().unwrap() as usize;
    assert_eq!(summary["dominant_frequency_hz"], 1500.0);
    let at = |r: usize, c: usize| amp.data[b * 12 + r * 4 + c];
    // Noise ≈ 70 µm at 40,000 pulses (eq. 12): 3σ.
    assert!((at(1, 0) - 707.0).abs() < 210.0, "{}", at(1, 0));
    assert!((at(1, 3) - 707.0).abs() < 210.0, "{}", at(1, 3));
    let uff = std::fs::read_to_string(out.join("vibration.uff")).unwrap();
    let sets: Vec<&str> = uff
        .lines()
        .collect::<Vec<_>>()
        .windows(2)
        .filter(|w| w[0] == "    -1" && w[1].len() == 80)
        .map(|w| w[1].trim())
        .collect();
    let mut want = vec!["151", "164", "15", "55", "55", "55", "55"];
    want.extend(["58"; 12]);
    assert_eq!(
        sets, want,
        "header, units, nodes, a shape per bin, a spectrum per pixel"
    );
    assert!(
        std::fs::read_to_string(out.join("deflection.svg"))
            .unwrap()
            .contains("<animate")
    );
}

#[test]
fn bad_arrays_are_refused_by_field_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let pgm = tmp.path().join("refl.pgm");
    let mut img = b"P5\n3 3\n255\n".to_vec();
    img.extend([128u8; 9]);
    std::fs::write(&pgm, img).unwrap();
    let ok_array = "rows = 4\ncols = 4\npitch_um = 30.0\nmm_per_pixel = 10.0";
    let cases: Vec<(&str, String, String, &str)> = vec![
        (
            "rows 0",
            PLATE.into(),
            ok_array.replace("rows = 4", "rows = 0"),
            "array.rows = 0",
        ),
        (
            "too large",
            PLATE.into(),
            "rows = 4096\ncols = 4096\npitch_um = 30.0\nmm_per_pixel = 0.01".into(),
            "GiB",
        ),
        (
            "too long",
            PLATE.into(),
            "rows = 2048\ncols = 2048\npitch_um = 30.0\nmm_per_pixel = 0.01".into(),
            "pixel-pulses",
        ),
        (
            "image size",
            PLATE.into(),
            format!("{ok_array}\nsignal_map = {{ kind = \"image\", path = \"refl.pgm\" }}"),
            "array.signal_map.path",
        ),
        (
            "mode 0",
            PLATE.replace("m = 2", "m = 0"),
            ok_array.into(),
            "scene.motion[0].m",
        ),
        (
            "rotor centre",
            "[[scene.motion]]\nkind = \"rotor\"\nblades = 2\nrpm = 600.0\ncentre_x_mm = 1e9\n\
             centre_y_mm = 0.0\nradius_mm = 5.0\nblade_mm = -1.0\n"
                .into(),
            ok_array.into(),
            "scene.motion[0].centre_x_mm",
        ),
        (
            "no mapping",
            PLATE.into(),
            "rows = 4\ncols = 4\npitch_um = 30.0".into(),
            "mm_per_pixel",
        ),
    ];
    for (what, motions, array, field) in cases {
        let cfg = config(tmp.path(), "bad.toml", &motions, &array);
        if what == "too large" {
            // 16 bins: 4096² pixels × (32 registers + 32 spectral values + 2 maps) × 8 bytes
            // = 8.9 GB, above the 4 GiB cap.
            let t = std::fs::read_to_string(&cfg).unwrap();
            let t = t.replacen("bins = 4 ", "bins = 16 ", 1).replacen(
                "cycles_per_pulse = 4 ",
                "cycles_per_pulse = 16 ",
                1,
            );
            std::fs::write(&cfg, t).unwrap();
        }
        if what == "too long" {
            // 2048² pixels × 400,000 pulses = 1.7·10^12 pixel-pulses, above the 2^40 cap.
            let t = std::fs::read_to_string(&cfg).unwrap();
            std::fs::write(&cfg, t.replacen("pulses = 40000", "pulses = 400000", 1)).unwrap();
        }
        let out = tmp.path().join("never");
        let o = run(&[
            "simulate",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(err.contains(field), "{what}: {err}");
        assert!(!out.exists(), "{what}: nothing is written");
    }
    // The PGM of the right size is read as value / maxval.
    let mut img = b"P5\n4 4\n255\n".to_vec();
    img.extend([255u8; 16]);
    std::fs::write(&pgm, img).unwrap();
    let cfg = config(
        tmp.path(),
        "img.toml",
        PLATE,
        &format!(
            "{ok_array}\nsignal_map = {{ kind = \"image\", path = \"refl.pgm\", scale = 0.5 }}"
        ),
    );
    let o = run(&["simulate", cfg.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // ρ_s = 0.5: half the pulses detect (no background), ± 5σ of a binomial of 40,000.
    let det = s["mean_detections_per_pixel"].as_f64().unwrap();
    assert!((det - 20_000.0).abs() < 5.0 * 100.0 / 4.0, "{det}");
    // A .npy map of R × C floats: ρ_s = 0.25 everywhere.
    let npy_map = tmp.path().join("refl.npy");
    std::fs::write(&npy_map, npy::to_bytes(&[4, 4], &[0.25f64; 16]).unwrap()).unwrap();
    let cfg = config(
        tmp.path(),
        "npy.toml",
        PLATE,
        &format!("{ok_array}\nsignal_map = {{ kind = \"image\", path = \"refl.npy\" }}"),
    );
    let o = run(&["simulate", cfg.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let det = s["mean_detections_per_pixel"].as_f64().unwrap();
    // 10,000 ± 5σ (σ = √(40,000·0.25·0.75)/4 pixels averaged = 87/4).
    assert!((det - 10_000.0).abs() < 5.0 * 87.0 / 4.0, "{det}");
    // A map of the wrong shape is refused naming the field.
    std::fs::write(&npy_map, npy::to_bytes(&[2, 8], &[0.25f64; 16]).unwrap()).unwrap();
    let o = run(&["simulate", cfg.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("array.signal_map.path") && err.contains("[2, 8]"),
        "{err}"
    );
}

#[test]
fn single_pixel_commands_refuse_an_array_and_spatial_motions_need_one() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = config(
        tmp.path(),
        "plate.toml",
        PLATE,
        "rows = 2\ncols = 2\npitch_um = 30.0\nmm_per_pixel = 10.0",
    );
    let c = cfg.to_str().unwrap();
    // (`tradeoff` measures an array's levels instead: tradeoff_array.rs.)
    let args = ["bench", "pixel", "--config", c, "--pulses", "4096"];
    let o = run(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains("simulate CONFIG --out DIR"), "{args:?}: {err}");
    // `rtl` renders an array (docs/pixel-contract.md "Array"): the array's module.
    let out = tmp.path().join("array-rtl");
    let o = run(&["rtl", c, "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("tofprobe_array.v").is_file());
    let text = std::fs::read_to_string(&cfg).unwrap();
    let single = tmp.path().join("single.toml");
    std::fs::write(&single, text.split("[array]").next().unwrap()).unwrap();
    let o = run(&["simulate", single.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("scene.motion[0].kind") && err.contains("[array]"),
        "{err}"
    );
}

/// `tofprobe bench array --json`, short: the rates are there, finite and consistent (the
/// pixel-pulses are R·C·N), the Monte Carlo alone is measured in the same run, and the
/// peak memory is far below the R·C·2B bound's scale (a 4 × 4 array: well under 1 GB).
#[test]
fn bench_array_prints_its_rates() {
    let o = run(&[
        "bench",
        "array",
        "--rows",
        "4",
        "--cols",
        "4",
        "--pulses",
        "40000,80000",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let runs = r["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    for (run, n) in runs.iter().zip([40_000.0, 80_000.0]) {
        assert_eq!(run["pixel_pulses"].as_f64().unwrap(), 16.0 * n);
        let rate = run["pixel_pulses_per_s"].as_f64().unwrap();
        let secs = run["seconds"].as_f64().unwrap();
        assert!((rate * secs / (16.0 * n) - 1.0).abs() < 1e-9);
        assert!(run["monte_carlo_pulses_per_cpu_s"].as_f64().unwrap() > 1e6);
        assert!(run["peak_memory_bytes"].as_f64().unwrap() < 1e9);
    }
    assert!(r["projected_64x64_1e7_seconds"].as_f64().unwrap() > 0.0);
    // One row per ISA this CPU runs, each naming its ISA with its own projection and pass.
    let rows = r["isas"].as_array().unwrap();
    assert_eq!(rows.len(), tofprobe_io::isa::Isa::supported().len());
    for row in rows {
        assert!(row["isa"].is_string() && row["pass"].is_boolean());
        assert!(row["projected_64x64_1e7_seconds"].as_f64().unwrap() > 0.0);
    }
    // The levels side by side at the last N: bit-true's row is the run's, each row names
    // its figures and units, the speed-up is bit-true's CPU-s over the level's, and the
    // targets judged are bit-true's and the statistical level's.
    let levels = r["levels"].as_array().unwrap();
    let names: Vec<&str> = levels
        .iter()
        .map(|l| l["level"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["bit-true", "statistical", "closed-form", "auto"]);
    let bt_cpu = levels[0]["cpu_seconds"].as_f64().unwrap();
    for l in levels {
        assert_eq!(l["pulses"], 80_000);
        let cpu = l["cpu_seconds"].as_f64().unwrap();
        let rate = l["pixel_pulses_per_cpu_second"].as_f64().unwrap();
        assert!((rate * cpu / (16.0 * 80_000.0) - 1.0).abs() < 1e-9, "{l}");
        let speedup = l["speedup_over_bit_true"].as_f64().unwrap();
        assert!((speedup * cpu / bt_cpu - 1.0).abs() < 1e-9, "{l}");
        assert!(
            l["projected_256x256_1e7_seconds"].as_f64().unwrap() > 0.0,
            "{l}"
        );
        assert!(l["model_cpu_seconds"].as_f64().unwrap() <= cpu, "{l}");
        let judged = matches!(names_of(l), "bit-true" | "statistical");
        assert_eq!(l["pass"].is_boolean(), judged, "{l}");
        assert_eq!(l["target_seconds"].is_number(), judged, "{l}");
    }
    assert_eq!(levels[0]["target_seconds"], 480.0);
    assert_eq!(levels[1]["target_seconds"], 10.0);
    // The default scene is one sine seen by every pixel: auto runs them all bit-true.
    assert_eq!(levels[3]["bit_true_pixels"], 16);
    assert_eq!(levels[1]["bit_true_pixels"], 0);
}

fn names_of(l: &serde_json::Value) -> &str {
    l["level"].as_str().unwrap_or_default()
}

/// The set as its users read it: numpy.load reads the .npy arrays and pyuff the UFF file
/// (scripts/array-crosscheck.sh, in the cached venv), and they agree with the summary, the
/// pixel grid and the maps; a perturbed map is caught. Needs python3 (required under CI).
#[test]
fn numpy_and_pyuff_read_the_set() {
    if !tofprobe_testkit::tools::have(&["python3"], "the numpy/pyuff reading of an array set") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let cfg = config(
        tmp.path(),
        "plate.toml",
        PLATE,
        "rows = 3\ncols = 5\npitch_um = 30.0\nfield_of_view_deg = 30.0\ndistance_mm = 100.0",
    );
    let out = tmp.path().join("out");
    let o = run(&[
        "simulate",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let check = |extra: &[&str]| {
        Command::new("bash")
            .arg(root.join("scripts/array-crosscheck.sh"))
            .arg(&out)
            .args(extra)
            .output()
            .unwrap()
    };
    let o = check(&[]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("array-check: ok (3 x 5 pixels, 4 bins"),
        "{text}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(
        !check(&["--break"]).status.success(),
        "a perturbed map must fail"
    );
}

/// The Haar example as users run it: `simulate scenes/edge-sweep.toml --out DIR` finds a
/// transition in every pixel, writes the event-time map, and fits the edge at its 10 m/s
/// along +x within 5 % and 3°.
#[test]
fn the_edge_sweep_example_measures_its_edge() {
    let tmp = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = tmp.path().join("edge");
    let o = run(&[
        "simulate",
        root.join("scenes/edge-sweep.toml").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // Columns 0 and 1 step 0.15 and 0.25 ms into the frame, within its first 0.2 ms segment
    // or just past it: the fit sees less than a segment of level before, so some of them
    // have no transition; every pixel from column 2 on has one (checked on the map below).
    let events = s["event_pixels"].as_u64().unwrap();
    assert!((30 * 32..=1024).contains(&events), "{events}");
    let v = s["edge_velocity_mm_per_s"].as_f64().unwrap();
    assert!((v / 10_000.0 - 1.0).abs() < 0.05, "{v}");
    assert!(s["edge_direction_deg"].as_f64().unwrap().abs() < 3.0);
    let t = npy::from_bytes(&std::fs::read(out.join("event_time_ms.npy")).unwrap()).unwrap();
    assert_eq!(t.shape, vec![32, 32]);
    // Column c (x = c + 0.5 mm) steps at (c + 0.5 + 1) mm / 10 m/s = (c + 1.5)·0.1 ms. A
    // pixel's time has sd ≈ 0.21 ms (measured over the map: the last segment's mean b
    // enters all 32 segments' terms), so a column's mean of 32 has sd ≈ 0.037 ms: 0.15 ms is
    // 4 sd (26 columns: a false failure ≈ 0.2 %). Columns 0–5 are left out: their times lie
    // within 3 sd of the frame start, where the clamp to [0, frame] biases the mean upwards
    // (column 0's expected mean is 0.20 ms, not 0.15).
    let col = |c: usize| (0..32).map(|r| t.data[r * 32 + c]).sum::<f64>() / 32.0;
    for c in 6..32 {
        let expected = (c as f64 + 1.5) * 0.1;
        assert!(
            (col(c) - expected).abs() < 0.15,
            "column {c}: mean {} ms, expected {expected} ms",
            col(c)
        );
    }
    // Every pixel from column 2 on has a transition (−1 marks none; a fitted time may lie
    // just before the frame start in columns 0–1).
    for c in 2..32 {
        assert!((0..32).all(|r| t.data[r * 32 + c] >= 0.0), "column {c}");
    }
    let missing = t.data.iter().filter(|&&x| x == -1.0).count() as u64;
    assert_eq!(missing, 1024 - events);
}
