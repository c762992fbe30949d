//! The repair's parsing, net finding, script and splice on real excerpts of the default
//! pixel's logs.

use super::*;
use crate::qflow::{DrcBox, lvs_total, parse_drc_boxes};

/// The default pixel's routed DEF around its two DRC spots and its open net
/// (2026-11-28, density 0.5, stage 3 skipped), cut to three nets; `far` is a net
/// elsewhere, `up` a metal3 wire over the first spot.
const DEF: &str = "UNITS DISTANCE MICRONS 100 ;\nNETS 4 ;\n- y[0][5]\n  ( AOI22X1_862 A ) \n  ( NAND2X1_370 A ) \n  ( DFFPOSX1_198 Q ) \n  ( AOI22X1_435 D ) \n\
+ ROUTED metal1 ( 35840 35400 ) M2_M1 \n  NEW metal2 ( 35840 35400 ) ( * 35100 ) ( 35920 * ) ( * 34300 ) ( 35840 * ) ( * 33400 ) M2_M1 \n\
  NEW metal1 ( 35840 33400 ) ( 35920 * ) \n  NEW metal1 ( 35520 35500 ) ( 35840 * ) ( * 35400 ) \n  NEW metal1 ( 37600 34755 ) ( 37440 * ) M2_M1 \n\
  NEW metal2 ( 37440 34800 ) ( 37360 * ) M3_M2 \n  NEW metal3 ( 37360 34800 ) ( 35920 * ) M3_M2 ;\n\
- y[9][37]\n  ( AOI22X1_1053 A ) \n  ( DFFPOSX1_1381 Q ) \n+ ROUTED metal1 ( 25600 51500 ) M2_M1 \n  NEW metal2 ( 25600 51500 ) ( * 51400 ) M3_M2 \n\
  NEW metal2 ( 25600 51300 ) M3_M2 \n  NEW metal3 ( 25600 51300 ) M4_M3 ;\n\
- far\n  ( INVX1_1 Y ) ( INVX1_2 A ) \n+ ROUTED metal2 ( 10000 10000 ) ( * 12000 ) ;\n\
- up\n  ( INVX1_3 Y ) \n+ ROUTED metal3 ( 37000 34790 ) ( 37800 * ) ;\nEND NETS\n\
SPECIALNETS 2 ;\n- vdd\n+ ROUTED metal1 240 ( 0 0 ) ( 90000 * ) ;\n- y[0][5]\n+ ROUTED metal1 40 ( 37600 34740 ) ;\nEND SPECIALNETS\nEND DESIGN\n";

/// What the DRC script printed for that macro (magic 8.3, `cif scale out` = 0.1 µm).
const DRC: &str = "Loading\nTOFPROBE-SCALE 0.10000000149011612\n\
TOFPROBE-DRC 1 Metal2 spacing < 3 (Mosis #9.2)\nTOFPROBE-BOX 3739 3478 3745 3480 Metal2 spacing < 3 (Mosis #9.2)\n\
TOFPROBE-DRC 2 Metal2 area < 20 (Mosis #+++)\nTOFPROBE-BOX 2558 5128 2562 5132 Metal2 area < 20 (Mosis #+++)\n\
TOFPROBE-BOX 3742 3473 3746 3477 Metal2 area < 20 (Mosis #+++)\n";

/// netgen's comp.out for the open net (its NET mismatches block).
const COMP: &str = "Number of nets: 9437 **Mismatch**          |Number of nets: 9436 **Mismatch**          \n\
---------------------------------------------------------------------------------------\n\
NET mismatches: Class fragments follow (with fanout counts):\n\
Circuit 1: tofprobe_pixel                  |Circuit 2: tofprobe_pixel                  \n\n\
---------------------------------------------------------------------------------------\n\
Net: NAND2X1_370/A                         |Net: y[0][5]                               \n\
  NAND2X1/A = 1                            |  AOI22X1/D = 1                            \n\
                                       |                                           \n\
Net: DFFPOSX1_198/Q                        |(no matching net)                          \n\
  DFFPOSX1/Q = 1                           |                                           \n\
Netlists do not match.\n";

fn set(v: &[&str]) -> BTreeSet<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn drc_boxes_are_read_in_micrometres() {
    let b = parse_drc_boxes(DRC);
    assert_eq!(b.len(), 3);
    assert_eq!(b[0].rule, "Metal2 spacing < 3 (Mosis #9.2)");
    // 3739 magic units × 0.1 µm (the f32 scale: 1e-6 relative).
    assert!((b[0].x0 - 373.9).abs() < 1e-3 && (b[0].y1 - 348.0).abs() < 1e-3);
    // Without the scale line the units are unknown: no box.
    assert!(parse_drc_boxes(&DRC.replace("TOFPROBE-SCALE", "x")).is_empty());
}

#[test]
fn the_def_gives_wires_vias_and_pins() {
    let n = def_nets(DEF);
    assert_eq!(n.names, set(&["far", "up", "y[0][5]", "y[9][37]"]));
    assert_eq!(n.pins[&("DFFPOSX1_198".into(), "Q".into())], "y[0][5]");
    assert_eq!(n.pins[&("INVX1_2".into(), "A".into())], "far");
    // The `( * 35100 )` point continues the last x; `far` is one 20 µm wire.
    let far: Vec<&Wire> = n.wires.iter().filter(|w| w.net == "far").collect();
    assert_eq!(far.len(), 2); // the start point and the wire
    assert_eq!((far[1].x0, far[1].y0, far[1].y1), (100.0, 100.0, 120.0));
    assert!(
        n.wires
            .iter()
            .any(|w| w.via && w.layer == "M2_M1" && w.x0 == 374.4 && w.y0 == 347.55)
    );
    // Power stripes (SPECIALNETS) are not nets to re-route.
    assert!(!n.names.contains("vdd"));
}

#[test]
fn each_drc_box_names_the_nets_at_it() {
    let n = def_nets(DEF);
    let boxes = parse_drc_boxes(DRC);
    // The spacing/area boxes at (374, 347.5) µm lie on y[0][5]'s metal2; the area box
    // at (256, 513) µm on y[9][37]'s stacked via. `up`'s metal3 passes over the
    // first spot: not a metal2 rule's net; `far` is 250 µm away.
    assert_eq!(
        nets_at_boxes(&n, &boxes, NEAR_UM),
        set(&["y[0][5]", "y[9][37]"])
    );
    // A Metal3 rule at the same box takes `up` (and y[0][5]'s metal3 and its vias).
    let m3 = DrcBox {
        rule: "Metal3 spacing < 3".into(),
        ..boxes[0].clone()
    };
    assert_eq!(nets_at_boxes(&n, &[m3], NEAR_UM), set(&["up", "y[0][5]"]));
    // A box far from every wire names none.
    let nowhere = DrcBox {
        x0: 600.0,
        x1: 601.0,
        ..boxes[0].clone()
    };
    assert!(nets_at_boxes(&n, &[nowhere], NEAR_UM).is_empty());
}

#[test]
fn the_open_net_of_comp_out_is_the_def_net_on_its_pins() {
    let n = def_nets(DEF);
    // Both columns: the netlist's `y[0][5]`, and the layout's pin-named fragments
    // (DFFPOSX1_198/Q, NAND2X1_370/A) are on y[0][5] in the DEF.
    assert_eq!(lvs_nets(COMP, &n), set(&["y[0][5]"]));
    let only_pin = COMP.replace("|Net: y[0][5]", "|Net: zz");
    assert_eq!(lvs_nets(&only_pin, &n), set(&["y[0][5]"]));
    // A pin on no DEF net maps to nothing; a matching comp.out names nothing.
    let unknown = "NET mismatches\nNet: NOPE_1/A  |(no matching net)\n";
    assert!(lvs_nets(unknown, &n).is_empty());
    assert!(lvs_nets("Circuits match uniquely.\n", &n).is_empty());
    // netgen cuts long names to its column (the first ECO round's comp.out: `Net:
    // rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NO`): the DEF nets that begin so.
    let mut long = n.clone();
    for x in [
        "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_A",
        "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_B",
        "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_C",
    ] {
        long.names.insert(x.to_string());
    }
    let cut =
        "NET mismatches\n(no matching net)     |Net: rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NO \n";
    assert_eq!(
        lvs_nets(cut, &long),
        set(&[
            "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_A",
            "rd_data_DFFPOSX1_Q_9_D_AOI21X1_Y_B_NOR2X1_Y_B"
        ])
    );
}

#[test]
fn the_fence_holds_the_other_nets_wires_near_the_re_routed_ones() {
    let n = def_nets(DEF);
    let f = fence(&n, &set(&["y[0][5]"]));
    // `up`'s metal3 wire over y[0][5], as its metal (centre line ± 0.15 µm); `far`
    // (250 µm away) and y[9][37] (165 µm away) are beyond the 40 µm fence; the
    // re-routed net's own wires are not obstructions. (A route's first point is a
    // piece of its own, for routes that are one point and a via.)
    assert_eq!(
        f,
        vec![
            "obstruction 369.850 347.750 370.150 348.050 metal3",
            "obstruction 369.850 347.750 378.150 348.050 metal3"
        ]
    );
    // Re-routing `up` fences y[0][5]: its wires and, on both layers, its vias.
    let g = fence(&n, &set(&["up"]));
    assert!(
        g.contains(&"obstruction 374.200 347.350 374.600 347.750 metal1".to_string()),
        "{g:?}"
    );
    assert!(
        g.contains(&"obstruction 374.200 347.350 374.600 347.750 metal2".to_string()),
        "{g:?}"
    );
    assert!(
        g.iter()
            .all(|l| !l.ends_with("metal3") || !l.contains("369.850"))
    );
}

#[test]
fn the_eco_script_routes_only_the_named_nets() {
    let cfg = "verbose 1\nread_lef /x.lef\ncatch {layers 6}\nobstruction 0 0 1 1 metal1\n\
               read_def top.def\nqrouter::standard_route top_route.def false true\nquit\n";
    let fenced = vec!["obstruction 1.000 2.000 3.000 4.000 metal2".to_string()];
    let s = eco_script(
        &cfg.replace("top", "tofprobe_pixel"),
        "tofprobe_pixel",
        &set(&["y[0][5]", "a"]),
        &fenced,
    );
    assert!(
        s.contains(
            "metal1\nobstruction 1.000 2.000 3.000 4.000 metal2\nread_def tofprobe_pixel.def\n"
        ),
        "{s}"
    );
    assert!(s.starts_with("verbose 1\nread_lef /x.lef\ncatch {layers 6}\nobstruction"));
    assert!(!s.contains("standard_route"), "{s}");
    // Braces keep Tcl from substituting the bus brackets.
    assert!(s.contains("set eco_nets [list {a} {y[0][5]}]"), "{s}");
    assert_eq!(s.matches("read_def").count(), 1);
    // Stage 1 only: other nets are blockages (stage 2 may route across a net it
    // then cannot rip up, a read-in route: a short).
    // One net at a time: removed, then routed, the others' routes in place.
    assert!(
        s.contains("remove net $n\n  set r [stage1 route $n]"),
        "{s}"
    );
    assert!(!s.contains("stage2"), "{s}");
    assert!(
        s.ends_with("write_def tofprobe_pixel_eco.def\nwrite_delays tofprobe_pixel_eco.rc\nquit\n")
    );
    assert_eq!(eco_failing("ECO route a: 0\nECO failing: 2\n"), Some(2));
    assert_eq!(eco_failing("Final: No failed routes!\n"), None);
    let changed = eco_changed("Ripping up blocking net b\n", &set(&["a"]));
    assert_eq!(changed, set(&["a", "b"]));
}

#[test]
fn the_splice_takes_only_the_repaired_nets_from_the_eco_def() {
    // qrouter's ECO DEF: y[0][5] re-routed (no stub now), `far` written back in pieces.
    let eco = "UNITS DISTANCE MICRONS 100 ;\nNETS 2 ;\n- far\n  ( INVX1_1 Y ) ( INVX1_2 A ) \n\
+ ROUTED metal2 ( 10000 10000 ) ( * 11000 ) \n  NEW metal2 ( 10000 11000 ) ( * 12000 ) ;\n\
- y[0][5]\n  ( DFFPOSX1_198 Q ) \n+ ROUTED metal1 ( 37760 34400 ) ( 37920 * ) M2_M1 ;\nEND NETS\n\
SPECIALNETS 1 ;\n- vdd\n+ ROUTED metal1 240 ( 0 0 ) ( 90000 * ) ;\nEND SPECIALNETS\n";
    let out = splice_def(DEF, eco, &set(&["y[0][5]"])).unwrap();
    assert!(out.contains("- y[0][5]\n  ( DFFPOSX1_198 Q ) \n+ ROUTED metal1 ( 37760 34400 ) ( 37920 * ) M2_M1 ;\n- y[9][37]"));
    assert!(!out.contains("( 37600 34755 )"), "the old route is gone");
    // `far` stays as it was, in one piece; the old stub of y[0][5] is dropped.
    assert!(out.contains("+ ROUTED metal2 ( 10000 10000 ) ( * 12000 ) ;"));
    assert!(out.contains("SPECIALNETS 1 ;\n- vdd\n") && !out.contains("37600 34740"));
    assert!(out.ends_with("END SPECIALNETS\nEND DESIGN\n"));
    // Nothing repaired: the DEF comes back line for line.
    assert_eq!(splice_def(DEF, eco, &set(&[])).unwrap(), DEF);
    // An ECO file without a NETS section is not spliced.
    assert!(splice_def(DEF, "garbage", &set(&["far"])).is_none());

    let rc = splice_rc(
        "a 1 X/Y 1 ( 2 3 P/A )\nb 1 Q/Y 0\n",
        "a 1 X/Y 1 ( 9 9 P/A )\nb 9\n",
        &set(&["a"]),
    );
    assert_eq!(rc, "a 1 X/Y 1 ( 9 9 P/A )\nb 1 Q/Y 0\n");
    assert_eq!(
        lvs_total("Total errors = 2\nDesign fails LVS with 2 errors.\n"),
        Some(2)
    );
}
