//! Deliberate faults for the co-simulation's mutation tests. tofprobe-rtlgen renders each
//! into the RTL, and the one cycle model carries the same fault through its hooks, so the
//! cycle where a fault first shows is predicted by the model, independently of any
//! simulator. With no fault the hooks are a never-taken branch (`tofprobe bench pixel`).

/// A deliberate fault of the pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Fault {
    /// Every accumulate subtracts where it should add and vice versa.
    SignFlip,
    /// Register writes land one clock edge late.
    ScheduleLate,
    /// Register 0 is one bit narrower (W−1 bits, sign-extended when read).
    NarrowRegister,
    /// The hold takes the TDC code of pulses without a detection too.
    HoldInvalid,
    /// The prefilter shifts logically instead of arithmetically.
    LogicalShift,
    /// The read-ahead stage reads the register file before this edge's writes (no forward
    /// of the sum being written): a read-after-write hazard, visible only when K = 1.
    MissingForward,
}

impl Fault {
    /// All faults, in a fixed order.
    pub const ALL: [Fault; 6] = [
        Fault::SignFlip,
        Fault::ScheduleLate,
        Fault::NarrowRegister,
        Fault::HoldInvalid,
        Fault::LogicalShift,
        Fault::MissingForward,
    ];

    /// The name used by templates and reports.
    pub fn name(self) -> &'static str {
        match self {
            Fault::SignFlip => "sign_flip",
            Fault::ScheduleLate => "schedule_late",
            Fault::NarrowRegister => "narrow_register",
            Fault::HoldInvalid => "hold_invalid",
            Fault::LogicalShift => "logical_shift",
            Fault::MissingForward => "missing_forward",
        }
    }
}
