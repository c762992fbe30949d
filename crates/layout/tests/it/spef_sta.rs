//! The post-route timing path on a three-cell circuit (osu018): qrouter-format RC trees
//! become SPEF that OpenSTA reads without a complaint, heavier wires cost what an Elmore
//! estimate says at least, and a SPEF naming a net the netlist lacks is refused.

use std::path::Path;
use tofprobe_layout::{spef, sta};

const LIB: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";
const NETLIST: &str = "module t (clk, d, q);\ninput clk;\ninput d;\noutput q;\nwire n1;\nwire n2;\n\
DFFPOSX1 f1 ( .CLK(clk), .D(d), .Q(n1) );\nINVX1 i1 ( .A(n1), .Y(n2) );\n\
DFFPOSX1 f2 ( .CLK(clk), .D(n2), .Q(q) );\nendmodule\n";

fn timed(
    dir: &Path,
    r_ohm: f64,
    c_pf: f64,
    net: &str,
) -> Result<sta::PostRoute, tofprobe_layout::LayoutError> {
    let rc = format!(
        "{net} 1 f1/Q 1 ( {r} {c} i1/A )\nn2 1 i1/Y 1 ( {r} {c} f2/D )\n",
        r = r_ohm,
        c = c_pf
    );
    let nets = spef::parse_rc(&rc, Path::new("t.rc"))?;
    let spef_path = dir.join("t.spef");
    std::fs::write(&spef_path, spef::write_spef("t", &nets)).unwrap();
    let netlist = dir.join("t.v");
    std::fs::write(&netlist, NETLIST).unwrap();
    sta::run(
        Path::new(LIB),
        &netlist,
        &spef_path,
        "t",
        5.0,
        nets.len(),
        dir,
        "typical",
    )
}

#[test]
fn wires_from_the_rc_trees_slow_the_path_and_a_foreign_net_is_refused() {
    if !tofprobe_testkit::tools::have(&["sta", LIB], "tofprobe-layout spef_sta") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let light = timed(dir.path(), 0.1, 1e-5, "n1").unwrap();
    let heavy = timed(dir.path(), 2000.0, 0.05, "n1").unwrap();
    assert_eq!(light.setup_path, ("f1".into(), "f2".into()));
    assert_eq!(light.spef_nets, 2);
    // Each 2 kΩ wire delays its sink by at least R·C = 2000 Ω · 0.05 pF = 0.1 ns (Elmore,
    // the wire's own capacitance at its far end); two such wires, and the gates slow down
    // under the load too.
    let cost = light.setup_slack_ns - heavy.setup_slack_ns;
    assert!(cost > 0.2, "light {light:?} heavy {heavy:?}");
    assert!(heavy.f_max_mhz < light.f_max_mhz);
    // A SPEF whose net the netlist does not have: OpenSTA warns; the flow refuses.
    let e = timed(dir.path(), 0.1, 1e-5, "no_such_net")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("post-route timing") && e.contains("no_such_net"),
        "{e}"
    );
}
