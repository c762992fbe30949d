//! The one tool locator (`tofprobe_io::tools::locate`) honoured by eda's OpenSTA runs:
//! `$TOFPROBE_STA` names the program `tofprobe_eda::sta::time_netlist` runs (a script that
//! records its call stands for it), and a variable naming nothing is the error, naming the
//! variable and its value, not a fall back to PATH. The layout flow's post-route timing
//! honours the same variable (crates/layout/tests/it/tools.rs). The variable is set in a
//! child process (`tofprobe_testkit::tools::run_in_child`), so no other test sees it.

use std::path::Path;

use tofprobe_eda::EdaError;
use tofprobe_eda::sta::time_netlist;
use tofprobe_testkit::tools::{in_child, recording_tool, run_in_child};

const NAME: &str = "tools::tofprobe_sta_names_the_opensta_eda_runs";

#[test]
fn tofprobe_sta_names_the_opensta_eda_runs() {
    if in_child() {
        let sta = std::env::var_os("TOFPROBE_STA").expect("set by the parent");
        let work = tempfile::tempdir().unwrap();
        let w = work.path();
        let e = time_netlist(&w.join("x.lib"), &w.join("x.v"), "top", "clk", w).unwrap_err();
        if Path::new(&sta).exists() {
            // The script ran (and failed, as it does).
            assert!(matches!(e, EdaError::ToolFailed { tool: "sta", .. }), "{e}");
        } else {
            let m = e.to_string();
            assert!(
                m.contains("$TOFPROBE_STA = /no/such/sta") && m.contains("opensta"),
                "{m}"
            );
        }
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("recording-sta");
    let called = recording_tool(&script);
    run_in_child(NAME, &[("TOFPROBE_STA", script.as_os_str())]);
    let args = std::fs::read_to_string(&called).expect("the override was run");
    assert!(args.contains("-exit"), "{args}");
    run_in_child(NAME, &[("TOFPROBE_STA", "/no/such/sta".as_ref())]);
}
