//! The superpixel front end rendered (`templates/superpixel.v`): the averaging of
//! `tofprobe_pixel::Superpixel` — G² (valid, tdc) in, the pixel's (valid, tdc) out, the
//! reciprocal table as a case ROM and a multiply-shift — as a module of its own. The array
//! RTL (`templates/array.v`, `[array] superpixel = G > 1`) instantiates it once per pixel
//! over its G × G SPAD inputs (docs/pixel-contract.md "Superpixel"); it is linted,
//! simulated against the model (crates/rtlgen/tests/it/superpixel.rs) and synthesised for
//! the size report's area per SPAD (`tofprobe_eda::array::options`).

use askama::Template;
use tofprobe_pixel::{PixelParams, Superpixel};

use crate::array_fault::ArrayFault;
use crate::error::RtlError;
use crate::render::{RenderOptions, RtlFile, header};

/// The template's file name.
pub const TEMPLATE: &str = "superpixel.v";

#[derive(Template)]
#[template(path = "superpixel.v", escape = "none")]
struct SuperpixelT {
    header: String,
    name: String,
    n: u32,
    t: u32,
    k: u32,
    /// Bits of the sum of n codes.
    sw: u32,
    /// Bits of the count 0 ..= n.
    cw: u32,
    /// Bits of a table word.
    mw: u32,
    sum_expr: String,
    count_expr: String,
    /// (n, M\[n\]).
    table: Vec<(usize, u64)>,
    /// Per SPAD i, (i, the SPAD whose code it sums: itself but for the `spad_swap` mutant).
    codes: Vec<(u32, u32)>,
    /// The `superpixel_and` mutant: valid = AND of the SPADs.
    and_valid: bool,
}

/// The module name of the front end for a module prefix.
pub fn module_name(prefix: &str) -> String {
    format!("{prefix}_superpixel")
}

/// Renders the front end `sp` (G ≥ 2) of the pixel `p` (its T) as `<prefix>_superpixel.v`.
pub fn render_superpixel(
    p: &PixelParams,
    sp: &Superpixel,
    o: &RenderOptions,
) -> Result<RtlFile, RtlError> {
    render_superpixel_with(p, sp, o, None)
}

/// [`render_superpixel`] with a deliberate fault of the front end (the mutation tests:
/// [`ArrayFault::in_superpixel`]; another fault renders it correct).
pub fn render_superpixel_with(
    p: &PixelParams,
    sp: &Superpixel,
    o: &RenderOptions,
    fault: Option<ArrayFault>,
) -> Result<RtlFile, RtlError> {
    if sp.side() < 2 || sp.tdc_bits() != p.tdc_bits {
        return Err(RtlError::Pixel(tofprobe_pixel::PixelError::mismatch(
            "superpixel front end",
            format!("G = {}, T = {}", sp.side(), sp.tdc_bits()),
            format!("G >= 2 and the pixel's T = {}", p.tdc_bits),
        )));
    }
    let n = sp.spads();
    let join = |f: &dyn Fn(usize) -> String| (0..n).map(f).collect::<Vec<_>>().join(" + ");
    let name = module_name(&o.module_prefix);
    let t = SuperpixelT {
        header: match fault.filter(|f| f.in_superpixel()) {
            Some(f) => format!(
                "{}\n// DELIBERATELY BROKEN ({}) for the array mutation tests.",
                header(p, TEMPLATE, o),
                f.name()
            ),
            None => header(p, TEMPLATE, o),
        },
        name: name.clone(),
        n: n as u32,
        t: sp.tdc_bits(),
        k: sp.shift(),
        sw: sp.sum_bits(),
        cw: tofprobe_pixel::params::ceil_log2(n as u64 + 1),
        mw: sp.table_bits(),
        sum_expr: join(&|i| format!("code_{i}")),
        count_expr: join(&|i| format!("one_{i}")),
        table: sp
            .table()
            .iter()
            .enumerate()
            .map(|(i, &m)| {
                let wrong = fault == Some(ArrayFault::ReciprocalEntry) && i == 0;
                (i + 1, m - u64::from(wrong))
            })
            .collect(),
        codes: (0..n as u32)
            .map(|i| match (fault, i) {
                (Some(ArrayFault::SpadSwap), 0) => (0, 1),
                (Some(ArrayFault::SpadSwap), 1) => (1, 0),
                _ => (i, i),
            })
            .collect(),
        and_valid: fault == Some(ArrayFault::SuperpixelAnd),
    };
    Ok(RtlFile {
        name: format!("{name}.v"),
        template: TEMPLATE,
        contents: t.render().map_err(|e| RtlError::Render {
            template: TEMPLATE,
            message: e.to_string(),
        })? + "\n",
    })
}
