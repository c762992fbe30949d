//! The one tool locator (`tofprobe_io::tools::locate`) honoured by the layout flow, as by
//! eda (crates/eda/tests/it/tools.rs): `$TOFPROBE_STA` names the program the post-route
//! timing (`tofprobe_layout::sta::run`) runs — a script that records its call stands for
//! it —, and a variable naming nothing is the error of `sta::run` and of the flow's first
//! check (`tools::require_all`), naming the variable and its value. Before, the layout
//! flow searched PATH alone and ran the system's `sta` whatever the variable said. The
//! variable is set in a child process (`tofprobe_testkit::tools::run_in_child`).

use std::path::Path;

use tofprobe_layout::sta;
use tofprobe_layout::tools::require_all;
use tofprobe_testkit::tools::{in_child, recording_tool, run_in_child};

const NAME: &str = "tools::tofprobe_sta_names_the_opensta_layout_runs";

#[test]
fn tofprobe_sta_names_the_opensta_layout_runs() {
    if in_child() {
        let set = std::env::var_os("TOFPROBE_STA").expect("set by the parent");
        let work = tempfile::tempdir().unwrap();
        let w = work.path();
        let r = sta::run(
            &w.join("x.lib"),
            &w.join("x.v"),
            &w.join("x.spef"),
            "top",
            10.0,
            0,
            w,
            "tt",
        );
        if !Path::new(&set).exists() {
            let m = r.unwrap_err().to_string();
            assert!(m.contains("$TOFPROBE_STA = /no/such/sta"), "{m}");
            let m = require_all().unwrap_err().to_string();
            assert!(m.contains("TOFPROBE_"), "{m}");
        }
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("recording-sta");
    let called = recording_tool(&script);
    run_in_child(NAME, &[("TOFPROBE_STA", script.as_os_str())]);
    let args = std::fs::read_to_string(&called).expect("the override was run");
    assert!(args.contains("post_route_sta-tt.tcl"), "{args}");
    run_in_child(NAME, &[("TOFPROBE_STA", "/no/such/sta".as_ref())]);
}
