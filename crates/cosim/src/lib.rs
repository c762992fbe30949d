//! Co-simulation of the generated RTL against the cycle-accurate reference: a Verilator
//! driver (cached builds, the C++ harness of `testbench/`), an Icarus driver for the plain
//! self-checking testbench, the first-mismatch report and its JUnit XML for CI.

pub mod array;
pub mod check;
pub mod coverage;
pub mod driver;
pub mod error;
pub mod gate_level;
pub mod harness;
pub mod icarus;
pub mod junit;
pub mod random;
mod runtime;
pub mod soak;
pub mod tools;
pub mod verilator;

pub use driver::{
    CosimOptions, CosimReport, Simulator, cosim, render_into, render_with_rom, rom_from_rtl,
};
pub use error::CosimError;
pub use harness::{Mismatch, RunOutcome};
pub use verilator::BuildProfile;
