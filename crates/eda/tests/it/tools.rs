//! The one tool locator (`tofprobe_io::tools::locate`) honoured by eda's OpenSTA runs:
//! `$TOFPROBE_STA` names the program `tofprobe_eda::sta::time_netlist` runs (a script that
//! records its call stands for it), and a variable naming nothing is the error, naming the
//! variable and its value, not a fall back to PATH. The layout flow's post-route timing
//! honours the same variable (crates/layout/tests/it/tools.rs). The variable is set in a
//! child process (`tofprobe_testkit::tools::override_is_honoured`), so no other test sees
//! it.

use std::path::Path;

use tofprobe_eda::EdaError;
use tofprobe_eda::sta::time_netlist;
use tofprobe_testkit::tools::{NO_SUCH_TOOL, in_child, override_is_honoured};

#[test]
fn tofprobe_sta_names_the_opensta_eda_runs() {
    if !in_child() {
        let args = override_is_honoured(
            "tools::tofprobe_sta_names_the_opensta_eda_runs",
            "TOFPROBE_STA",
        );
        assert!(args.contains("-exit"), "{args}");
        return;
    }
    let work = tempfile::tempdir().unwrap();
    let w = work.path();
    let e = time_netlist(&w.join("x.lib"), &w.join("x.v"), "top", "clk", w).unwrap_err();
    if std::env::var_os("TOFPROBE_STA").is_some_and(|s| Path::new(&s).exists()) {
        // The recording script ran (and failed, as it does).
        assert!(matches!(e, EdaError::ToolFailed { tool: "sta", .. }), "{e}");
    } else {
        let m = e.to_string();
        let named = format!("$TOFPROBE_STA = {NO_SUCH_TOOL}");
        assert!(m.contains(&named) && m.contains("opensta"), "{m}");
    }
}
