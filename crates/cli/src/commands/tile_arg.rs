//! `cosim --tile ROW,COL,ROWS,COLS`: the tile of an `[array]` to co-simulate, parsed and
//! checked against the design before anything is built. Every number is a 64-bit decimal;
//! the sums and the product are checked (no wrap: `0,0,1,18446744073709551615` and
//! `0,0,4294967297,4294967295` are refused, naming the option, its value and the range that
//! fits), and a whole array larger than is co-simulated whole (`MAX_COSIM_PIXELS`) is refused at once, naming
//! its keys and `--tile`, not after the stimulus was built.

use tofprobe_cosim::array::MAX_COSIM_PIXELS;
use tofprobe_design::ResolvedDesign;
use tofprobe_rtlgen::array::ArrayTile;

use crate::error::CliError;

/// The refusal of `--tile = text`, with what is allowed.
fn bad(text: &str, allowed: String) -> CliError {
    CliError::option("tile", tofprobe_io::text::clip(text, 200), allowed)
}

/// The tile `--tile` names for `design` (checked), or the whole array when it is absent
/// and small enough to render; `None` for a whole array that renders.
pub fn tile_for(
    design: &ResolvedDesign,
    tile: Option<&str>,
) -> Result<Option<ArrayTile>, CliError> {
    let Some(a) = design.array.as_ref() else {
        return match tile {
            Some(t) => Err(bad(
                t,
                "an [array] configuration only (a single pixel is co-simulated whole)".into(),
            )),
            None => Ok(None),
        };
    };
    let (nr, nc) = (a.rows as u64, a.cols as u64);
    let example = format!(
        "e.g. 0,0,{},{} for the {nr} × {nc} array",
        nr.min(8),
        nc.min(8)
    );
    let Some(text) = tile else {
        if nr.saturating_mul(nc) > MAX_COSIM_PIXELS as u64 {
            return Err(CliError::option(
                "tile",
                "none",
                format!(
                    "a tile of at most {MAX_COSIM_PIXELS} pixels (64 × 64) for the {nr} × {nc} \
                     array (array.rows × array.cols): arrays up to that many are co-simulated \
                     whole; co-simulate a tile of it with --tile ROW,COL,ROWS,COLS ({example})"
                ),
            ));
        }
        return Ok(None);
    };
    let fields: Vec<&str> = text.split(',').map(str::trim).collect();
    let [row0, col0, rows, cols] = fields[..] else {
        return Err(bad(
            text,
            format!("four whole numbers ROW,COL,ROWS,COLS ({example})"),
        ));
    };
    let mut v = [0u64; 4];
    for ((slot, field), name) in v
        .iter_mut()
        .zip([row0, col0, rows, cols])
        .zip(["ROW", "COL", "ROWS", "COLS"])
    {
        *slot = field.parse().map_err(|_| {
            bad(
                text,
                format!(
                    "{name} = `{}` is not a whole number of 0..=18446744073709551615 ({example})",
                    tofprobe_io::text::clip(field, 40)
                ),
            )
        })?;
    }
    let [row0, col0, rows, cols] = v;
    let inside = |start: u64, len: u64, n: u64| {
        len >= 1 && start.checked_add(len).is_some_and(|end| end <= n)
    };
    if !inside(row0, rows, nr) || !inside(col0, cols, nc) {
        return Err(bad(
            text,
            format!(
                "ROWS, COLS >= 1 with ROW + ROWS <= {nr} and COL + COLS <= {nc}: a non-empty \
                 tile inside the {nr} × {nc} array ({example})"
            ),
        ));
    }
    // Both sides fit the array (≤ 4096 each): the product cannot wrap.
    if rows * cols > MAX_COSIM_PIXELS as u64 {
        return Err(bad(
            text,
            format!(
                "ROWS × COLS <= {MAX_COSIM_PIXELS} (64 × 64, what is co-simulated whole), \
                 not {rows} × {cols} ({example})"
            ),
        ));
    }
    let us =
        |x: u64| usize::try_from(x).map_err(|_| bad(text, "a tile this machine addresses".into()));
    Ok(Some(ArrayTile {
        row0: us(row0)?,
        col0: us(col0)?,
        rows: us(rows)?,
        cols: us(cols)?,
    }))
}
