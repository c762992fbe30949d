//! The soak (`tofprobe cosim --random N --seed S`): random valid configurations
//! ([`crate::random`]) each co-simulated over a few frames, case by case, with a JUnit
//! suite per case. The cases run are a range of the seed's stream, so a share of a soak
//! (a batch farm's job) runs exactly the cases the whole soak would, with the same
//! configurations and stimuli.

use std::ops::Range;
use std::path::Path;

use crate::driver::{CosimOptions, CosimReport, Simulator, cosim};
use crate::error::CosimError;
use crate::junit::Suite;
use crate::random::{RandomCase, random_case};

/// How each case is co-simulated.
#[derive(Debug, Clone)]
pub struct SoakOptions<'a> {
    /// The stream of configurations (`--seed`).
    pub seed: u64,
    /// Frames per case.
    pub frames: u64,
    /// The simulator.
    pub simulator: Simulator,
    /// Verilator's random initial register values.
    pub x_seed: u64,
    /// Each case works in `out/random-<i>`.
    pub out: &'a Path,
}

/// One case's outcome.
#[derive(Debug, Clone)]
pub struct SoakCase {
    /// Its index in the seed's stream.
    pub index: u64,
    /// The drawn configuration and stimulus seed.
    pub case: RandomCase,
    /// Its co-simulation.
    pub report: CosimReport,
}

impl SoakCase {
    /// The first mismatch, in one line (`None` when it passed).
    pub fn first_mismatch(&self) -> Option<String> {
        self.report.first.as_ref().map(|m| {
            format!(
                "cycle {} pulse {} {} expected {} actual {}",
                m.cycle, m.pulse, m.signal, m.expected, m.actual
            )
        })
    }
}

/// What a soak (or a share of one) concluded.
#[derive(Debug, Clone, Default)]
pub struct SoakReport {
    /// Cases run.
    pub cases: u64,
    /// Cases that failed.
    pub failed: u64,
    /// One JUnit suite per case, in case order.
    pub suites: Vec<Suite>,
}

/// Runs the cases `cases` of the stream of `o.seed`, in order; `each` sees every case as
/// it finishes (to print it). A tool error stops the soak; a mismatch is a failed case.
pub fn run(
    cases: Range<u64>,
    o: &SoakOptions<'_>,
    mut each: impl FnMut(&SoakCase) -> Result<(), CosimError>,
) -> Result<SoakReport, CosimError> {
    let mut report = SoakReport::default();
    for i in cases {
        let c = random_case(o.seed, i);
        let mut co = CosimOptions::new(o.out.join(format!("random-{i}")));
        co.frames = o.frames;
        co.seed = c.seed;
        co.simulator = o.simulator;
        co.x_seed = o.x_seed;
        co.vcd_on_mismatch = false;
        let r = cosim(&c.params, &co)?;
        report.cases += 1;
        if !r.pass {
            report.failed += 1;
        }
        report.suites.push(crate::junit::suite(
            &format!("random-{i}"),
            &tofprobe_rtlgen::config_hash(&c.params),
            &r,
        ));
        each(&SoakCase {
            index: i,
            case: c,
            report: r,
        })?;
    }
    Ok(report)
}
