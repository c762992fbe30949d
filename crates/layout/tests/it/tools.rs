//! The one tool locator (`tofprobe_io::tools::locate`) honoured by the layout flow, as by
//! eda (crates/eda/tests/it/tools.rs): `$TOFPROBE_STA` names the program the post-route
//! timing (`tofprobe_layout::sta::run`) runs — a script that records its call stands for
//! it —, and a variable naming nothing is the error of `sta::run` and of the flow's first
//! check (`tools::require_all`), naming the variable and its value. Before, the layout
//! flow searched PATH alone and ran the system's `sta` whatever the variable said. The
//! variable is set in a child process (`tofprobe_testkit::tools::override_is_honoured`).

use std::path::Path;

use tofprobe_layout::sta;
use tofprobe_layout::tools::require_all;
use tofprobe_testkit::tools::{NO_SUCH_TOOL, in_child, override_is_honoured};

#[test]
fn tofprobe_sta_names_the_opensta_layout_runs() {
    if !in_child() {
        let args = override_is_honoured(
            "tools::tofprobe_sta_names_the_opensta_layout_runs",
            "TOFPROBE_STA",
        );
        assert!(args.contains("post_route_sta-tt.tcl"), "{args}");
        return;
    }
    let work = tempfile::tempdir().unwrap();
    let w = work.path();
    let spef = w.join("x.spef");
    let r = sta::run(
        &w.join("x.lib"),
        &w.join("x.v"),
        &spef,
        "top",
        10.0,
        0,
        w,
        "tt",
    );
    if std::env::var_os("TOFPROBE_STA").is_some_and(|s| !Path::new(&s).exists()) {
        let named = format!("$TOFPROBE_STA = {NO_SUCH_TOOL}");
        let m = r.unwrap_err().to_string();
        assert!(m.contains(&named), "{m}");
        // The flow's first check fails too (on sta, or on a tool before it that is
        // missing here): the variable of the tool is named.
        let m = require_all().unwrap_err().to_string();
        assert!(m.contains("$TOFPROBE_"), "{m}");
    }
}
