//! The boundary on lines of the 2-bin pixel's routed DEF (osu018, qrouter 1.4): its die
//! (−3.2, −3.0)–(522.4, 363.0) µm, tracks every 0.8 µm across x and 1.0 µm across y on
//! the edges, pins on the top edge, and `rd_data[14]` jogging at y = 364.0 µm.

use super::*;
use crate::boundary::{Geometry, Outside, outside_die};

const LEF: &str = "LAYER metal1\n  TYPE ROUTING ;\n  WIDTH 0.3 ;\nEND metal1\n\
LAYER metal2\n  TYPE ROUTING ;\n  WIDTH 0.3 ;\nEND metal2\n\
VIA M2_M1 DEFAULT\n  LAYER metal1 ;\n    RECT -0.200 -0.200 0.200 0.200 ;\n  LAYER metal2 ;\n    RECT -0.200 -0.200 0.200 0.200 ;\nEND M2_M1\n\
MACRO INVX1\n  SIZE 2.4 BY 10.0 ;\nEND INVX1\n";

fn def(route: &str) -> String {
    format!(
        "VERSION 5.6 ;\nUNITS DISTANCE MICRONS 100 ;\nDIEAREA ( -320 -300 ) ( 52240 36300 ) ;\n\
TRACKS Y -300 DO 367 STEP 100 LAYER metal1 ;\nTRACKS X -320.0 DO 658 STEP 80 LAYER metal2 ;\n\
VIAS 1 ;\n- viagen21_post\n+ RECT metal1 ( -80 -20 ) ( 80 20 )\n+ RECT metal2 ( -80 -20 ) ( 80 20 ) ;\nEND VIAS\n\
COMPONENTS 1 ;\n- INVX1_1 INVX1 + PLACED ( 29040 25600 ) N ;\nEND COMPONENTS\n\
PINS 3 ;\n- rd_data[14] + NET rd_data[14]\n  + LAYER metal2 ( -15 -15 ) ( 15 15 )\n  + PLACED ( 29840 36300 ) N ;\n\
- valid + NET valid\n  + LAYER metal2 ( -15 -15 ) ( 15 15 )\n  + PLACED ( -240 13500 ) N ;\n\
- vdd + NET vdd\n  + LAYER metal2 ( -80 -40 ) ( 80 40 )\n  + PLACED ( 5440 -260 ) N ;\nEND PINS\n\
NETS 1 ;\n- rd_data[14]\n  ( PIN rd_data[14] )\n  ( INVX1_1 Y )\n{route}END NETS\n\
SPECIALNETS 1 ;\n- vdd\n+ FIXED metal2 160 ( 5440 -300 ) ( * 36300 )\n  NEW metal1 40 ( 5440 50 ) ( * * ) viagen21_post ;\nEND SPECIALNETS\nEND DESIGN\n"
    )
}

/// qrouter's route of `rd_data[14]`: up from the pin on the edge track to y = 364.0.
const BEYOND: &str =
    "+ ROUTED metal2 ( 29840 36300 ) ( * 36400 ) ( 29200 * ) ( * 35800 ) M2_M1 ;\n";
/// The same net kept on the tracks inside: along the edge track at y = 363.0.
const ON_EDGE: &str = "+ ROUTED metal2 ( 29840 36300 ) ( 29200 * ) ( * 35800 ) M2_M1 ;\n";

fn outside(text: &str) -> Outside {
    let g = Geometry::from_lef(&[LEF]);
    outside_die(text, &g, &crate::def::lef_sizes(LEF), Path::new("t.def")).unwrap()
}

#[test]
fn the_lef_geometry_is_read() {
    let g = Geometry::from_lef(&[LEF]);
    assert_eq!(g.widths["metal2"], 0.3);
    assert_eq!(g.vias["M2_M1"], vec![(-0.2, -0.2, 0.2, 0.2); 2]);
}

#[test]
fn a_route_past_the_die_is_found_and_measured() {
    let o = outside(&def(BEYOND));
    // The jog at y = 364.0 with half its 0.3 µm width: 1.15 µm past 363.0; the top pin
    // and the edge-track pieces stick out too (0.15 µm each).
    assert!((o.worst_um - 1.15).abs() < 1e-9, "{o:?}");
    assert!(o.examples[0].contains("rd_data[14]"), "{o:?}");
    // On the edge track only: half a width out (the wire, the pin), nothing further.
    let o = outside(&def(ON_EDGE));
    assert!((o.worst_um - 0.15).abs() < 1e-9, "{o:?}");
    // Cell, 3 pins, 3 wire pieces and a 2-layer via, a stripe and a 2-layer DEF via.
    assert_eq!(o.shapes, 1 + 3 + 3 + 2 + 1 + 2, "{o:?}");
}

#[test]
fn the_grown_die_holds_the_edge_tracks_and_the_pins_reach_it() {
    let (grown, g) = grow_die(&def(ON_EDGE), Path::new("t.def")).unwrap();
    // One pitch each side: 0.8 µm across x, 1.0 µm across y.
    assert_eq!((g.margin_x_um, g.margin_y_um), (0.8, 1.0));
    assert!(
        grown.contains("DIEAREA ( -400 -400 ) ( 52320 36400 ) ;"),
        "{grown}"
    );
    // Every pin was within a pitch of an edge: the top one now reaches y = 364.0, the left
    // one x = −4.0, the power pin y = −4.0; their placements are unchanged.
    assert_eq!(g.pins_extended, 3);
    assert!(grown.contains("- rd_data[14] + NET rd_data[14]\n  + LAYER metal2 ( -15 -15 ) ( 15 100 )\n  + PLACED ( 29840 36300 ) N ;\n"), "{grown}");
    assert!(
        grown.contains("+ LAYER metal2 ( -160 -15 ) ( 15 15 )\n  + PLACED ( -240 13500 ) N ;"),
        "{grown}"
    );
    assert!(
        grown.contains("+ LAYER metal2 ( -80 -140 ) ( 80 40 )"),
        "{grown}"
    );
    let o = outside(&grown);
    assert_eq!((o.outside, o.worst_um), (0, 0.0), "{o:?}");
    // The route past the old edge still fails in the grown die (1.15 − 1.0 µm): the
    // keep-out is what stops it at the source.
    let (grown, _) = grow_die(&def(BEYOND), Path::new("t.def")).unwrap();
    assert!((outside(&grown).worst_um - 0.15).abs() < 1e-9);
}

#[test]
fn the_keep_out_fences_every_layer_half_a_pitch_past_each_edge() {
    let f = frame(&def(ON_EDGE), Path::new("t.def")).unwrap();
    assert_eq!(f.layers, vec!["metal1", "metal2"]);
    let k = keep_out(&f);
    assert_eq!(k.len(), 8);
    // The top strip starts half a y pitch above the top edge track (363.0 + 0.5).
    assert!(
        k.contains(&"obstruction -13.200 363.500 532.400 373.000 metal2".to_string()),
        "{k:?}"
    );
    // The right strip starts 0.4 µm right of x = 522.4.
    assert!(
        k.contains(&"obstruction 522.800 -13.000 532.400 373.000 metal1".to_string()),
        "{k:?}"
    );
    let cfg = "verbose 1\nobstruction -4.0 361.0 523.2 364.0 metal1\nread_def t.def\nquit\n";
    let with = with_keep_out(cfg, &k).unwrap();
    let read = with.find("read_def").unwrap();
    assert!(with[..read].contains("363.500") && with.ends_with("read_def t.def\nquit\n"));
    assert!(with_keep_out("verbose 1\n", &k).is_none());
    // A DEF without tracks is named.
    let e = frame(
        "UNITS DISTANCE MICRONS 100 ;\nDIEAREA ( 0 0 ) ( 10 10 ) ;\n",
        Path::new("t.def"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("TRACKS"), "{e}");
}
