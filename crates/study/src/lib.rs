//! What tofprobe studies on a resolved design (`tofprobe_design::ResolvedDesign`): the
//! bit-true spectrum ([`spectrum`]), the RTL rendering of the chip ([`rtl`]), the sizing
//! request ([`sizing`]), the main flow ([`flow`]), the paper reproduction ([`paper`]) and
//! the speed/accuracy trade-off ([`tradeoff`]). The CLI parses arguments, calls one of
//! these and prints the result.

pub mod error;
pub mod flow;
pub mod options;
pub mod paper;
pub mod records;
pub mod replay;
pub mod rtl;
pub mod signoff;
pub mod sizing;
pub mod spectrum;
pub mod tradeoff;
pub mod transients;

pub use error::StudyError;
