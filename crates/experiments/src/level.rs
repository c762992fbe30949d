//! The fidelity levels of tofprobe, one enum with its registry: what a user trades speed for
//! accuracy with. The speed/accuracy study ([`crate::tradeoff`]) runs the Fourier ladder
//! and the Haar ladder from it, the paper's Table 2 columns name the level they measure,
//! and the options' accuracy runs only the two levels it compares. A new level is a
//! variant here, a row of [`REGISTRY`] and its measurement in the study that runs it
//! (`tradeoff::measure_level` for the Fourier ladder, `tradeoff::haar` for the Haar one).

use serde::{Deserialize, Serialize};

/// One fidelity level, cheapest (least faithful to the chip) first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Level {
    /// Closed forms: eq. 12 with the window's N_eff, the 1NN hold, the first-arrival mixture.
    ClosedForm,
    /// Float full DFT of the held depth record (rustfft): the reference of the Fourier levels.
    FullDft,
    /// Float DFT at the ROM's bins only, streamed.
    SelectedDft,
    /// Float ΣΔ probing: the pixel's float twin (same ROM, hold, priming, prefilter).
    FloatSd,
    /// Float Haar transform of the held record: the reference of the Haar levels.
    FloatHaar,
    /// The bit-true pixel at transaction level (one call per pulse).
    BitTrue,
    /// The bit-true pixel cycle by cycle (the RTL's schedule and readout).
    Cycle,
    /// The generated RTL under Verilator, co-simulated against the cycle model.
    Rtl,
}

/// What the registry knows of a level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LevelInfo {
    /// The level.
    pub level: Level,
    /// Its name in tables, JSON and messages.
    pub name: &'static str,
    /// In the Fourier ladder (spectrum at the bins).
    pub fourier: bool,
    /// In the Haar ladder (scalogram and events).
    pub haar: bool,
    /// Its registers are the chip's bit for bit (its accuracy is the bit-true model's).
    pub bit_exact: bool,
    /// Needs the EDA tools (Verilator).
    pub needs_tools: bool,
}

/// Every level, cheapest first.
pub const REGISTRY: &[LevelInfo] = &[
    LevelInfo {
        level: Level::ClosedForm,
        name: "closed form",
        fourier: true,
        haar: false,
        bit_exact: false,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::FullDft,
        name: "float full DFT",
        fourier: true,
        haar: false,
        bit_exact: false,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::SelectedDft,
        name: "float selected-bin DFT",
        fourier: true,
        haar: false,
        bit_exact: false,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::FloatSd,
        name: "float ΣΔ probing",
        fourier: true,
        haar: false,
        bit_exact: false,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::FloatHaar,
        name: "float Haar",
        fourier: false,
        haar: true,
        bit_exact: false,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::BitTrue,
        name: "bit-true transaction",
        fourier: true,
        haar: true,
        bit_exact: true,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::Cycle,
        name: "cycle-accurate",
        fourier: true,
        haar: true,
        bit_exact: true,
        needs_tools: false,
    },
    LevelInfo {
        level: Level::Rtl,
        name: "Verilator RTL",
        fourier: true,
        haar: true,
        bit_exact: true,
        needs_tools: true,
    },
];

impl Level {
    /// The registry's row of this level.
    pub fn info(self) -> &'static LevelInfo {
        REGISTRY
            .iter()
            .find(|i| i.level == self)
            .expect("every level has a registry row")
    }

    /// Its name in tables and JSON.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// The level named `name` (as printed, or its kebab-case key), if any.
    pub fn from_name(name: &str) -> Option<Level> {
        REGISTRY
            .iter()
            .find(|i| {
                i.name.eq_ignore_ascii_case(name)
                    || serde_json::to_value(i.level)
                        .ok()
                        .and_then(|v| v.as_str().map(|s| s == name))
                        == Some(true)
            })
            .map(|i| i.level)
    }

    /// The Fourier ladder, cheapest first; `tools`: with the Verilator level.
    pub fn fourier_ladder(tools: bool) -> Vec<Level> {
        REGISTRY
            .iter()
            .filter(|i| i.fourier && (tools || !i.needs_tools))
            .map(|i| i.level)
            .collect()
    }

    /// The Haar ladder, cheapest first; `tools`: with the Verilator level.
    pub fn haar_ladder(tools: bool) -> Vec<Level> {
        REGISTRY
            .iter()
            .filter(|i| i.haar && (tools || !i.needs_tools))
            .map(|i| i.level)
            .collect()
    }
}

impl std::fmt::Display for Level {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registry_is_complete_ordered_and_named_once() {
        let levels: Vec<Level> = REGISTRY.iter().map(|i| i.level).collect();
        let mut sorted = levels.clone();
        sorted.sort();
        assert_eq!(
            levels, sorted,
            "the registry lists the levels cheapest first"
        );
        sorted.dedup();
        assert_eq!(sorted.len(), levels.len());
        for i in REGISTRY {
            assert_eq!(Level::from_name(i.name), Some(i.level));
            assert_eq!(i.level.name(), i.name);
        }
        assert_eq!(Level::from_name("bit-true"), Some(Level::BitTrue));
        assert_eq!(Level::from_name("no such level"), None);
        assert_eq!(Level::fourier_ladder(false).len(), 6);
        assert_eq!(
            Level::haar_ladder(true),
            vec![Level::FloatHaar, Level::BitTrue, Level::Cycle, Level::Rtl]
        );
    }
}
