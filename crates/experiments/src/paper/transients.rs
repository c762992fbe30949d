//! The paper's transient figures in the reproduction: Fig. 3 (the float Haar scalogram of
//! an impulse, a fast and a slow edge) and Fig. 12 (a 25 mm step from the pixel's Haar
//! registers: the largest coefficient's scale, the event time and the ramp rate), computed
//! by `paper::haar_figures` and mapped to the reproduction's [`Row`]s, plus their
//! scalogram SVGs.
//!
//! A `TransientRow` is judged by an absolute tolerance (or a structural claim stated in its
//! note) that the dsp crate evaluates; the row keeps that verdict ([`Tolerance::Bound`],
//! the tolerance written into the note) and shows its reference in the closed-form column.

use super::haar_figures::{TransientFigure, TransientRow, fig3, fig12};

use super::{Row, Tolerance};
use crate::ExperimentError;

/// The seed of both figures' photon records.
pub const SEED: u64 = 1;

fn family(figure: &str) -> &'static str {
    match figure {
        "Fig. 3" => "Fig. 3 (Haar)",
        "Fig. 12" => "Fig. 12 (Haar)",
        _ => "Haar",
    }
}

fn unit(u: &str) -> &'static str {
    match u {
        "ms" => "ms",
        "m/s" => "m/s",
        "mm" => "mm",
        "×" => "×",
        "scale" => "scale",
        _ => "",
    }
}

/// One `TransientRow` as a reproduction [`Row`] (its verdict kept).
pub fn row(t: &TransientRow) -> Row {
    let tol = if t.tolerance.is_infinite() {
        "a structural claim".to_string()
    } else if t.tolerance == 0.0 {
        "exact".to_string()
    } else if t.tolerance >= 1e-3 {
        format!("±{:.3} {}", t.tolerance, t.unit)
    } else {
        format!("±{:.0e} {}", t.tolerance, t.unit)
    };
    let note = if t.note.is_empty() {
        format!("tolerance: {tol}")
    } else {
        format!("{}; tolerance: {tol}", t.note)
    };
    let mut r = Row::judge(
        family(&t.figure),
        t.label.clone(),
        unit(&t.unit),
        t.paper,
        None,
        t.measured,
        t.reference,
        Tolerance::Bound,
        note,
    );
    r.pass = t.pass && t.measured.is_finite();
    r
}

/// The two figures (seed [`SEED`]).
pub fn figures() -> Result<Vec<TransientFigure>, ExperimentError> {
    Ok(vec![fig3(SEED)?, fig12(SEED)?])
}

/// The rows of both figures, in figure order.
pub fn rows(figs: &[TransientFigure]) -> Vec<Row> {
    figs.iter().flat_map(|f| f.rows.iter().map(row)).collect()
}

/// Renders `fig3_scalogram.svg` and `fig12_scalogram.svg`: (file name, SVG text), staged
/// by the caller with the other figures.
pub fn svgs(figs: &[TransientFigure]) -> Result<Vec<(String, String)>, ExperimentError> {
    let mut out = Vec::new();
    for f in figs {
        let name = match f.rows.first().map(|r| r.figure.as_str()) {
            Some("Fig. 3") => "fig3_scalogram.svg",
            _ => "fig12_scalogram.svg",
        };
        let title = format!(
            "{}: Haar scalogram, N = {}, U = {}",
            f.rows.first().map_or("Haar", |r| r.figure.as_str()),
            f.scalogram.pulses,
            f.scalogram.scales
        );
        // The paper's value beside each measured one (event time, scale, rate, counts).
        let notes: Vec<String> = f
            .rows
            .iter()
            .map(|r| {
                let paper = r.paper.map_or("the paper prints none".to_string(), |p| {
                    format!("paper {p} {}", r.unit).trim_end().to_string()
                });
                let measured = if r.measured.fract() == 0.0 {
                    format!("{:.0}", r.measured)
                } else {
                    format!("{:.4}", r.measured)
                };
                format!("{}: measured {measured} {} ({paper})", r.label, r.unit).replace("  ", " ")
            })
            .collect();
        let svg = crate::scalogram::scalogram_svg_with_notes(
            &f.scalogram,
            &title,
            Some(&f.events),
            &notes,
        )
        .map_err(|message| ExperimentError::Plot {
            path: name.to_string(),
            message,
        })?;
        out.push((name.to_string(), svg));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The verdict travels: a failing transient row stays failing, and the tolerance is in
    /// the note.
    #[test]
    fn rows_keep_the_verdict() {
        let mut t = TransientRow {
            figure: "Fig. 12".into(),
            label: "ramp rate".into(),
            unit: "m/s".into(),
            paper: Some(27.7),
            measured: 26.8,
            reference: Some(26.79),
            tolerance: 0.5,
            pass: true,
            note: String::new(),
        };
        let r = row(&t);
        assert!(r.pass && r.family == "Fig. 12 (Haar)" && r.unit == "m/s");
        assert!(r.note.contains("±0.500 m/s"), "{}", r.note);
        t.pass = false;
        assert!(!row(&t).pass);
        t.pass = true;
        t.measured = f64::NAN;
        assert!(!row(&t).pass);
    }
}
