//! What a motion-model imputation would cost in a pixel (issue 46, point 6): registers,
//! adders, multipliers and dividers of each form, and an area estimate from the cells of
//! the sky130 liberty `tofprobe size` reads (the vendored `sky130_fd_sc_hd` typical
//! corner, `tofprobe_eda::pdk`): flop `dfxtp_1`, full adder `fa_1`, `and2_1`, `mux2_1`.
//! Cell areas only (no wiring, no sharing across cycles): a floor of the synthesised area.
//!
//! Widths, TDC codes of W_c bits (W_c = ⌈log2(window/LSB)⌉):
//! - **1NN hold** (the pixel's): the held code, W_c flops and their load multiplexer.
//! - **α-β, power-of-two gains** α = 2^−a, β = 2^−b: both products are shifts (no
//!   multiplier). The depth needs b fraction bits to add the velocity exactly each pulse:
//!   depth W_c + 1 + b bits (a sign/overflow guard for the extrapolation); velocity 2 + b
//!   (sign, ±1 LSB/pulse — 10 m/s at 1 mm and 10 MHz, beyond any vibration — and b
//!   fraction bits); the gate's settling counter ⌈log2(⌈1/α⌉ + 1)⌉. Adders: the
//!   prediction d + v, the innovation z − d, the two updates, |ν| and its comparison
//!   with the gate (two more depth-wide), the counter's increment.
//! - **Kalman (covariance)**: the α-β's state plus P_dd, P_dv, P_vv of 2·W_d bits (the
//!   square of the depth's range and resolution), two dividers for K = P/S and 12
//!   multipliers (K·ν twice, the Joseph update's ten products; the gate's ν² ≤ k²S one
//!   more minus the shared k²) and ten 2·W_d adders. A W×W array multiplier is W² AND2 and
//!   W(W − 1) full adders, an array divider W² full adders and W² multiplexers.

use serde::Serialize;
use tofprobe_eda::liberty::Liberty;
use tofprobe_io::markdown::Table;

use crate::ExperimentError;
use crate::paper::setup::{BG_WINDOW_MM, LSB_MM};

/// The cells' areas (µm²) the estimate uses, from one liberty.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellAreas {
    pub library: String,
    pub flop_um2: f64,
    pub full_adder_um2: f64,
    pub and2_um2: f64,
    pub mux2_um2: f64,
}

/// The sky130 cells by name (the error of [`CellAreas::from_liberty`] names them too).
const CELLS: [&str; 4] = ["dfxtp_1", "fa_1", "and2_1", "mux2_1"];

impl CellAreas {
    /// The cells of the sky130 typical corner `tofprobe size` uses (`Sky130Pdk::discover`:
    /// `$TOFPROBE_SKY130_PDK`, else the vendored PDK), decompressed into the synthesis
    /// cache; `Ok(None)` when no sky130 PDK is found.
    pub fn sky130() -> Result<Option<Self>, ExperimentError> {
        let Some(pdk) = tofprobe_eda::pdk::Sky130Pdk::discover(None)? else {
            return Ok(None);
        };
        let cache = tofprobe_eda::fsutil::synth_cache_dir(None);
        let lib = Liberty::load(&pdk.typical(&cache)?)?;
        Self::from_liberty(&lib).map(Some)
    }

    /// The areas of `lib`'s `*__dfxtp_1`, `*__fa_1`, `*__and2_1`, `*__mux2_1`.
    pub fn from_liberty(lib: &Liberty) -> Result<Self, ExperimentError> {
        let area = |suffix: &str| {
            lib.cells
                .iter()
                .find(|(n, _)| n.ends_with(&format!("__{suffix}")))
                .map(|(_, c)| c.area)
                .ok_or_else(|| {
                    ExperimentError::option(
                        "liberty",
                        lib.path.display(),
                        "a sky130_fd_sc_hd liberty with cells dfxtp_1, fa_1, and2_1, mux2_1",
                    )
                })
        };
        Ok(CellAreas {
            library: lib.name.clone(),
            flop_um2: area(CELLS[0])?,
            full_adder_um2: area(CELLS[1])?,
            and2_um2: area(CELLS[2])?,
            mux2_um2: area(CELLS[3])?,
        })
    }
}

/// One form's cost.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImputationCost {
    pub form: String,
    /// The signal rate whose gains it uses (none for the hold).
    pub rho_s: Option<f64>,
    pub depth_bits: u32,
    pub velocity_bits: u32,
    /// Each of the three covariance registers (Kalman only).
    pub covariance_bits: u32,
    pub flops: u32,
    /// Full-adder cells (adders, multipliers' and dividers' arrays).
    pub full_adders: u32,
    pub multipliers: u32,
    pub dividers: u32,
    pub and2: u32,
    pub mux2: u32,
    pub area_um2: f64,
    pub library: String,
}

fn log2_ceil(x: f64) -> u32 {
    x.log2().ceil().max(1.0) as u32
}

/// One scene's α-β gains, what the widths follow from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    pub rho_s: f64,
    pub alpha: f64,
    pub beta_per_pulse: f64,
}

/// The costs: the hold, and per signal rate the α-β form and the Kalman filter.
pub fn costs(scenes: &[Gains], cells: &CellAreas) -> Vec<ImputationCost> {
    let wc = log2_ceil(BG_WINDOW_MM / LSB_MM);
    let area = |f: u32, fa: u32, and2: u32, mux: u32| {
        f64::from(f) * cells.flop_um2
            + f64::from(fa) * cells.full_adder_um2
            + f64::from(and2) * cells.and2_um2
            + f64::from(mux) * cells.mux2_um2
    };
    let row = |form: &str, rho_s, d, v, p, flops, fa, mul, div, and2, mux| ImputationCost {
        form: form.into(),
        rho_s,
        depth_bits: d,
        velocity_bits: v,
        covariance_bits: p,
        flops,
        full_adders: fa,
        multipliers: mul,
        dividers: div,
        and2,
        mux2: mux,
        area_um2: area(flops, fa, and2, mux),
        library: cells.library.clone(),
    };
    let mut out = vec![row("1NN hold", None, wc, 0, 0, wc, 0, 0, 0, 0, wc)];
    let mut seen: Vec<f64> = Vec::new();
    for sc in scenes {
        if seen.contains(&sc.rho_s) {
            continue;
        }
        seen.push(sc.rho_s);
        let b = (-sc.beta_per_pulse.log2()).round().max(0.0) as u32;
        let settle = (1.0 / sc.alpha).ceil();
        let (wd, wv, ws) = (wc + 1 + b, 2 + b, log2_ceil(settle + 1.0));
        let ab_flops = wd + wv + ws;
        let ab_fa = 5 * wd + wv + ws;
        out.push(row(
            "alpha-beta (power-of-two gains)",
            Some(sc.rho_s),
            wd,
            wv,
            0,
            ab_flops,
            ab_fa,
            0,
            0,
            0,
            wd + wv,
        ));
        let wp = 2 * wd;
        let (mul, div) = (12u32, 2u32);
        let fa = ab_fa + 10 * wp + mul * wp * (wp - 1) + div * wp * wp;
        out.push(row(
            "Kalman (covariance)",
            Some(sc.rho_s),
            wd,
            wv,
            wp,
            ab_flops + 3 * wp,
            fa,
            mul,
            div,
            mul * wp * wp,
            wd + wv + 3 * wp + div * wp * wp,
        ));
    }
    out
}

/// The cost table.
pub fn markdown(rows: &[ImputationCost]) -> String {
    if rows.is_empty() {
        return "\n(pixel cost: no sky130 liberty found; see `tofprobe size`)\n".into();
    }
    let mut t = Table::numeric([
        "form",
        "ρ_s",
        "depth bits",
        "velocity bits",
        "covariance bits",
        "flops",
        "full adders",
        "multipliers",
        "dividers",
        "area µm²",
    ]);
    for r in rows {
        t.row([
            r.form.to_string(),
            r.rho_s.map(|x| x.to_string()).unwrap_or_else(|| "–".into()),
            r.depth_bits.to_string(),
            r.velocity_bits.to_string(),
            r.covariance_bits.to_string(),
            r.flops.to_string(),
            r.full_adders.to_string(),
            r.multipliers.to_string(),
            r.dividers.to_string(),
            format!("{:.0}", r.area_um2),
        ]);
    }
    format!(
        "\n#### Pixel cost (cells of {}, no wiring or sharing)\n\n{t}",
        rows[0].library
    )
}
