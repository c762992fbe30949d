//! The laid-out netlist proven by the project's equivalence check (yosys, osu018): a
//! 2-bit register `r <= ~d` whose DEF puts its flops on a clock buffer the synthesised
//! netlist does not have and names their outputs after the ports (`r` is the netlist's
//! alias of `q`); the same DEF with the flops' inputs swapped is refused, naming a pair.

use std::path::Path;
use tofprobe_eda::equiv::{EquivSpec, check_equivalence_cached};
use tofprobe_layout::netlist::from_def;

const LIB: &str = "/usr/share/qflow/tech/osu018/osu018_stdcells.lib";

const RTL: &str = "module t(clk, d, q);\n  input clk;\n  input [1:0] d;\n  output [1:0] q;\n\
  reg [1:0] r;\n  always @(posedge clk) r <= ~d;\n  assign q = r;\nendmodule\n";

/// As yosys writes the synthesised netlist.
const SYNTH: &str = "module t(clk, d, q);\n  input clk;\n  wire clk;\n  input [1:0] d;\n  wire [1:0] d;\n\
  output [1:0] q;\n  wire [1:0] q;\n  wire [1:0] r;\n  wire n0;\n  wire n1;\n\
  INVX1 i0 (\n    .A(d[0]),\n    .Y(n0)\n  );\n  INVX1 i1 (\n    .A(d[1]),\n    .Y(n1)\n  );\n\
  DFFPOSX1 f0 (\n    .CLK(clk),\n    .D(n0),\n    .Q(r[0])\n  );\n  DFFPOSX1 f1 (\n    .CLK(clk),\n    .D(n1),\n    .Q(r[1])\n  );\n\
  assign q = r;\nendmodule\n";

const DEF: &str = "UNITS DISTANCE MICRONS 100 ;\nCOMPONENTS 6 ;\n\
- INVX1_1 INVX1 + PLACED ( 0 0 ) N ;\n- INVX1_2 INVX1 + PLACED ( 240 0 ) N ;\n\
- DFFPOSX1_1 DFFPOSX1 + PLACED ( 480 0 ) N ;\n- DFFPOSX1_2 DFFPOSX1 + PLACED ( 480 1000 ) FS ;\n\
- CLKBUF1_1 CLKBUF1 + PLACED ( 0 1000 ) FS ;\n- FILL_1 FILL + PLACED ( 2400 0 ) N ;\nEND COMPONENTS\n\
NETS 8 ;\n- clk\n  ( PIN clk ) ( CLKBUF1_1 A )\n+ ROUTED metal2 ( 0 0 ) ( 0 100 ) ;\n\
- clk_bF$buf0\n  ( CLKBUF1_1 Y ) ( DFFPOSX1_1 CLK ) ( DFFPOSX1_2 CLK ) ;\n\
- d[0]\n  ( PIN d[0] ) ( INVX1_1 A ) ;\n- d[1]\n  ( PIN d[1] ) ( INVX1_2 A ) ;\n\
- n0\n  ( INVX1_1 Y ) ( DFFPOSX1_1 D ) ;\n- n1\n  ( INVX1_2 Y ) ( DFFPOSX1_2 D ) ;\n\
- q[0]\n  ( PIN q[0] ) ( DFFPOSX1_1 Q ) ;\n- q[1]\n  ( PIN q[1] ) ( DFFPOSX1_2 Q ) ;\nEND NETS\n";

fn prove(dir: &Path, def: &str) -> tofprobe_eda::Result<tofprobe_eda::equiv::Equivalence> {
    let n = from_def(def, SYNTH, "t", Path::new("t.def")).unwrap();
    assert_eq!(n.cells, 5);
    let rtl = dir.join("t.v");
    std::fs::write(&rtl, RTL).unwrap();
    let netlist = dir.join("laid-out.v");
    std::fs::write(&netlist, &n.verilog).unwrap();
    check_equivalence_cached(
        &EquivSpec {
            rtl: vec![rtl],
            top: "t".into(),
            params: vec![],
            netlist,
            liberty: LIB.into(),
        },
        dir,
        None,
    )
}

#[test]
fn the_laid_out_netlist_is_proven_and_a_miswired_one_refused() {
    if !tofprobe_testkit::tools::have(&["yosys", LIB], "tofprobe-layout laid_out") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let e = prove(dir.path(), DEF).unwrap();
    // The register's two bits and the outputs' two, each paired and proven.
    assert!(e.points >= 4 && e.proven == e.points, "{e:?}");
    // The flops' inputs swapped: bit 0 of the register now takes ~d[1].
    let swapped = DEF
        .replace(
            "( INVX1_1 Y ) ( DFFPOSX1_1 D )",
            "( INVX1_1 Y ) ( DFFPOSX1_2 D )",
        )
        .replace(
            "( INVX1_2 Y ) ( DFFPOSX1_2 D )",
            "( INVX1_2 Y ) ( DFFPOSX1_1 D )",
        );
    match prove(dir.path(), &swapped) {
        Err(tofprobe_eda::EdaError::NotEquivalent(f)) => {
            assert!(f.unproven > 0 && f.first.contains('r'), "{f:?}")
        }
        other => panic!("a miswired netlist passed: {other:?}"),
    }
}
