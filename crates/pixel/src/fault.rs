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
    /// Reset forgets `primed` (Verilator's zero start hides it; random reset and Icarus's
    /// X show it).
    ResetPrimed,
    /// The pixel primes on a pulse without a detection.
    PrimeOnMiss,
    /// The readout does not clear the registers.
    ReadoutClear,
    /// The write enables ignore `acc_en` (a non-contributing pulse still writes).
    EnableDecode,
    /// The status word carries the register multiplexer instead of the refused counter.
    StatusWord,
    /// The refused counter does not count.
    RefusedCounter,
    /// Haar: a full frame accepts further pulses instead of refusing them.
    HaarFrameLimit,
    /// The read-ahead stage reads the register file before this edge's writes (no forward
    /// of the sum being written): a read-after-write hazard, visible only when K = 1.
    MissingForward,
    /// Reset clears the register file only when the pixel is idle (no pulse in flight):
    /// a reset while a pulse's slots are being written keeps the registers (and lets the
    /// slot write). Power-up's two reset cycles hide it; a reset in the middle of a frame
    /// (the directed sequencer) shows it. Rendered into the flop register file.
    ResetWhenIdle,
    /// An accumulate that overflows W bits holds the register instead of wrapping it.
    /// Frames whose registers stay inside W hide it; a long frame or a narrow W shows it.
    HoldOnOverflow,
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

    /// Faults of the refusal path, which the cycle model carries but the reference
    /// sequencer never shows (it refuses no pulse): the directed sequencer
    /// ([`crate::directed`]) shows each, at the cycle the model predicts. `HaarFrameLimit`
    /// is Haar only.
    pub const REFUSAL: [Fault; 3] = [
        Fault::StatusWord,
        Fault::RefusedCounter,
        Fault::HaarFrameLimit,
    ];

    /// Faults the cycle model has no hook for: the co-simulation must catch them, but the
    /// cycle where they first show is not predicted (the mutation tests check that they are
    /// caught, with the first mismatch reported).
    pub const UNMODELLED: [Fault; 6] = [
        Fault::ResetPrimed,
        Fault::PrimeOnMiss,
        Fault::ReadoutClear,
        Fault::EnableDecode,
        Fault::ResetWhenIdle,
        Fault::HoldOnOverflow,
    ];

    /// The unmodelled faults only the directed stimulus shows: a reset in the middle of a
    /// frame (`ResetWhenIdle`) and registers that leave W bits (`HoldOnOverflow`, in a
    /// pixel whose W is sized for its frame). The reference sequencer's frames pass them.
    pub const STIMULUS: [Fault; 2] = [Fault::ResetWhenIdle, Fault::HoldOnOverflow];

    /// The name used by templates and reports.
    pub fn name(self) -> &'static str {
        match self {
            Fault::SignFlip => "sign_flip",
            Fault::ScheduleLate => "schedule_late",
            Fault::NarrowRegister => "narrow_register",
            Fault::HoldInvalid => "hold_invalid",
            Fault::LogicalShift => "logical_shift",
            Fault::ResetPrimed => "reset_primed",
            Fault::PrimeOnMiss => "prime_on_miss",
            Fault::ReadoutClear => "readout_clear",
            Fault::EnableDecode => "enable_decode",
            Fault::StatusWord => "status_word",
            Fault::RefusedCounter => "refused_counter",
            Fault::HaarFrameLimit => "haar_frame_limit",
            Fault::MissingForward => "missing_forward",
            Fault::ResetWhenIdle => "reset_when_idle",
            Fault::HoldOnOverflow => "hold_on_overflow",
        }
    }
}
