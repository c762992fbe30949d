//! End-to-end checks against the real tools (yosys, OpenSTA, osu018; CI installs them via
//! scripts/install-tools.sh). Each test runs one small synthesis of the fixture
//! (tests/fixtures/mini_pixel.v: 2·B registers of W bits, two shared adders, hold,
//! prefilter); results are cached under CARGO_TARGET_TMPDIR, so reruns are quick.

use std::path::{Path, PathBuf};
use tofprobe_eda::analysis::{ParamRtl, analyse_point};
use tofprobe_eda::liberty::Liberty;
use tofprobe_eda::synth::{SynthSpec, synthesise};

const OSU018: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

fn fixture() -> ParamRtl {
    ParamRtl {
        sources: vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mini_pixel.v")],
        top: "mini_pixel".into(),
        bins_param: "B".into(),
        width_param: "W".into(),
    }
}

fn cache(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("report-cache")
        .join(name)
}

#[test]
fn osu018_area_split_and_timing_of_the_fixture() {
    let lib = Liberty::load(Path::new(OSU018)).unwrap();
    let p = analyse_point(&fixture(), 2, 8, &lib, true, "clk", &cache("osu"), None).unwrap();
    // Independent area check: Σ count × liberty area must equal yosys's `Chip area`.
    let sum: f64 = p
        .synthesis
        .cells_by_type
        .iter()
        .map(|(t, n)| *n as f64 * lib.cells[t].area)
        .sum();
    assert!(
        (sum - p.synthesis.total_area_um2).abs() < 1e-6,
        "{sum} vs {}",
        p.synthesis.total_area_um2
    );
    // The split covers every cell exactly once.
    let s = &p.split;
    let cells = s.register_file.cells + s.adders.cells + s.hold_prefilter.cells + s.control.cells;
    assert_eq!(cells, p.synthesis.cell_count);
    assert!((s.total_area_um2() - p.synthesis.total_area_um2).abs() < 1e-6);
    // 2·B = 4 registers of W = 8 bits: 32 register-file flops of 96 µm² (DFFPOSX1).
    assert_eq!(s.registers_found, 4);
    assert_eq!(s.register_file.flops, 32);
    assert!(s.register_file.area_um2 >= 32.0 * 96.0);
    // Hold (T = 4 → up to 5 bits, the constant top bit may be swept) + x (T+1+F = 7 bits).
    assert!(
        (10..=12).contains(&s.hold_prefilter.flops),
        "{}",
        s.hold_prefilter.flops
    );
    assert!(s.adders.cells > 0, "the shared adders must be found");
    // Timing: at least a flop's clock-to-Q plus setup (≈ 0.2 + 0.17 ns in osu018), and an
    // 8-bit ripple adder with its muxes keeps it well under 20 ns.
    let t = p.timing.expect("osu018 carries timing");
    assert!(
        t.critical_path_ns > 0.37 && t.critical_path_ns < 20.0,
        "{t:?}"
    );
    assert!((t.f_max_mhz * t.critical_path_ns - 1e3).abs() < 1e-6);
    assert!(t.path_cells >= 3, "{t:?}");
}

#[test]
fn liberty_without_logic_gates_is_rejected_clearly() {
    // Only an inverter and a flop: abc cannot build the adders from it.
    let dir = cache("tiny");
    std::fs::create_dir_all(&dir).unwrap();
    let lib = dir.join("inv_dff.lib");
    std::fs::write(
        &lib,
        r#"library (invdff) {
  cell (INV) { area : 1 ; pin (A) { direction : input ; } pin (Y) { direction : output ; function : "!A" ; } }
  cell (DFF) { area : 5 ; ff (IQ, IQN) { next_state : "D" ; clocked_on : "CLK" ; }
    pin (D) { direction : input ; } pin (CLK) { direction : input ; clock : true ; }
    pin (Q) { direction : output ; function : "IQ" ; } }
}
"#,
    )
    .unwrap();
    let spec = SynthSpec {
        sources: fixture().sources,
        top: "mini_pixel".into(),
        params: vec![("B".into(), 1), ("W".into(), 7)],
        liberty: lib.clone(),
        delay_target_ps: None,
        keep: vec![],
    };
    let msg = synthesise(&spec, &dir).unwrap_err().to_string();
    assert!(
        msg.contains("inv_dff.lib") && msg.contains("abc") && msg.contains("pass a liberty"),
        "{msg}"
    );
}

#[test]
fn missing_rtl_and_liberty_name_the_file() {
    let spec = SynthSpec {
        sources: vec!["/nonexistent/pixel.v".into()],
        top: "pixel".into(),
        params: vec![],
        liberty: OSU018.into(),
        delay_target_ps: None,
        keep: vec![],
    };
    let msg = synthesise(&spec, &cache("none")).unwrap_err().to_string();
    assert!(
        msg.contains("/nonexistent/pixel.v") && msg.contains("tofprobe rtl"),
        "{msg}"
    );
    let spec = SynthSpec {
        liberty: "/nonexistent/cells.lib".into(),
        ..spec
    };
    let msg = synthesise(&spec, &cache("none")).unwrap_err().to_string();
    assert!(
        msg.contains("/nonexistent/cells.lib") && msg.contains("--liberty"),
        "{msg}"
    );
}

/// A latch register file (issue 30 point 4) on osu018: each register bit is the liberty's
/// `LATCH` (plus one per register in its latch-and-AND clock gate), and the area counts
/// them at their LEF outline, 56 µm², where the liberty's `area : 0` would count nothing.
#[test]
fn a_latch_pixel_maps_onto_osu018_latches_counted_at_their_lef_area() {
    use tofprobe_eda::analysis::RtlProvider;
    use tofprobe_eda::generated::GeneratedPixel;
    use tofprobe_pixel::{PixelParams, RegisterFile};
    let px = GeneratedPixel {
        base: PixelParams {
            bins: 2,
            tdc_bits: 4,
            frac_bits: 2,
            width: 10,
            frame_pulses: 1024,
            rom_depth: 16,
            register_file: RegisterFile::Latch,
            ..PixelParams::default()
        },
    };
    let v = px.rtl(2, 10, &cache("latch").join("rtl")).unwrap();
    let lib = Liberty::load(Path::new(OSU018)).unwrap();
    let syn = synthesise(
        &SynthSpec {
            sources: v.sources.clone(),
            top: v.top.clone(),
            params: v.params.clone(),
            liberty: PathBuf::from(OSU018),
            delay_target_ps: None,
            keep: vec![],
        },
        &cache("latch").join("syn"),
    )
    .unwrap();
    // R = 2·B = 4 registers of W = 10 bits, and 4 clock gates' enable latches.
    assert_eq!(syn.cells_by_type.get("LATCH"), Some(&44));
    assert_eq!(syn.area_from_lef.get("LATCH"), Some(&56.0));
    // Independent sum: every cell at its liberty area, LATCH at its LEF area (the liberty
    // reader's), equals the reported total (tolerance: f64 sums of decimal areas).
    let sum: f64 = syn
        .cells_by_type
        .iter()
        .map(|(t, n)| *n as f64 * lib.cells[t].area)
        .sum();
    assert!(
        (sum - syn.total_area_um2).abs() < 1e-6,
        "{sum} vs {}",
        syn.total_area_um2
    );
    assert!(syn.total_area_um2 >= 44.0 * 56.0);
}

/// Issue 45 item 13: the synthesis cache under concurrency. Three threads synthesise one
/// spec into a fresh cache at once: one yosys run (the others wait on the key's lock and
/// reuse it), every netlist whole. An entry whose netlist was cut short since (what a
/// reader once met while another run still wrote it) is synthesised again, not read.
#[test]
fn the_synthesis_cache_builds_one_entry_per_key_and_checks_it_on_read() {
    use tofprobe_eda::analysis::RtlProvider;
    let root = cache("concurrent");
    let _ = std::fs::remove_dir_all(&root);
    let px = fixture();
    let v = px.rtl(2, 8, &root.join("rtl")).unwrap();
    let spec = SynthSpec {
        sources: v.sources.clone(),
        top: v.top.clone(),
        params: v.params.clone(),
        liberty: PathBuf::from(OSU018),
        delay_target_ps: None,
        keep: vec![],
    };
    let syn_root = root.join("syn");
    let runs: Vec<_> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..3)
            .map(|_| s.spawn(|| synthesise(&spec, &syn_root).unwrap()))
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(
        runs.iter().filter(|r| r.yosys_seconds > 0.0).count(),
        1,
        "one yosys run for one key"
    );
    assert!(
        runs.windows(2)
            .all(|w| w[0].key == w[1].key && w[0].cell_count == w[1].cell_count)
    );
    let netlist = runs[0].netlist_verilog.clone();
    let whole = std::fs::read(&netlist).unwrap();
    assert!(String::from_utf8_lossy(&whole).contains("endmodule"));
    // Cut short in place: the entry fails its check and is built again.
    std::fs::write(&netlist, &whole[..whole.len() / 2]).unwrap();
    let again = synthesise(&spec, &syn_root).unwrap();
    assert!(
        again.yosys_seconds > 0.0,
        "a torn entry was read instead of rebuilt"
    );
    assert_eq!(std::fs::read(&netlist).unwrap(), whole);
    // Nothing temporary left beside the entries.
    let hidden: Vec<_> = std::fs::read_dir(&syn_root)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}
