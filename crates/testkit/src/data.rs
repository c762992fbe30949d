//! The real data the tests read, vendored in this checkout under `third_party/` (never a
//! folder beside it, so a fresh clone's tests pass on their own): PicoQuant's sample
//! time-tagged records (`third_party/picoquant-tttr`, BSD-3-Clause; its README.md says
//! where they come from). The sky130 PDK's directory is the library's own look-up,
//! `tofprobe_eda::pdk::vendored`.

use std::path::PathBuf;

/// The vendored PicoQuant records' directory, relative to the workspace root.
pub const TTTR_DIR: &str = "third_party/picoquant-tttr";

/// The vendored sample records, as the tests name them.
pub const TTTR_RECORDS: [&str; 4] = [
    "hydraharp_v20_t3.ptu",
    "hydraharp_v10_t3.ptu",
    "hydraharp_v20_t2.ptu",
    "picoharp_v30_t2.ptu",
];

/// The workspace root of this checkout.
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The vendored PicoQuant record `name` (e.g. `hydraharp_v20_t3.ptu`).
pub fn tttr_record(name: &str) -> PathBuf {
    workspace_root().join(TTTR_DIR).join(name)
}
