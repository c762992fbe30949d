//! How a `Design` is made, conversion only: a path (`str` or `os.PathLike`, never guessed
//! from the string's content), TOML text, a dict shaped like the document, or a design and
//! a dict of dotted-key overrides (`{"pixel.bins": 4}`), each through the one resolution
//! (`tofprobe_design::load` / `Document::from_toml_str` / `Document::from_table` /
//! `Document::with_overrides`, then `resolve`), run off the calling thread so Ctrl-C
//! returns at once (`long_call::detached`). Errors: `errors::design_error`.

use std::path::PathBuf;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use tofprobe_design::{Document, ResolvedDesign};
use toml::{Table, Value};

use crate::errors::{self, FileNotFoundError};
use crate::long_call::detached;

/// Origin of a design given as TOML text.
pub const TEXT_ORIGIN: &str = "<TOML text>";
/// Origin of a design given as a dict.
pub const DICT_ORIGIN: &str = "<dict>";

/// The path `source` names: a `str` as it is, an `os.PathLike` through `os.fspath` (to a
/// `str`); a `TypeError` for anything else (bytes included).
pub fn path_of(source: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    let kind = || source.get_type().name().map(|n| n.to_string());
    let text = if let Ok(s) = source.cast::<PyString>() {
        s.to_str()?.to_string()
    } else if source.hasattr("__fspath__")? {
        let p = source
            .py()
            .import("os")?
            .call_method1("fspath", (source,))?;
        p.cast::<PyString>()
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "`path`: os.fspath of the {} gave {}, not a str",
                    kind().unwrap_or_default(),
                    p.get_type()
                        .name()
                        .map(|n| n.to_string())
                        .unwrap_or_default()
                ))
            })?
            .to_str()?
            .to_string()
    } else {
        return Err(PyTypeError::new_err(format!(
            "`path` must be a str or os.PathLike (a configuration file), got {}; TOML text \
             goes to Design.from_toml_text, a dict to Design.from_dict",
            kind()?
        )));
    };
    let path = PathBuf::from(&text);
    if text.contains('\n') && !path.exists() {
        return Err(FileNotFoundError::new_err(format!(
            "configuration `{}…` does not exist: the path holds a newline, like TOML text; \
             TOML text goes to Design.from_toml_text(text)",
            tofprobe_io::text::clip(text.lines().next().unwrap_or(""), 60)
        )));
    }
    Ok(path)
}

/// The design in the file at `path`.
pub fn load(py: Python<'_>, path: PathBuf) -> PyResult<ResolvedDesign> {
    detached(py, move || tofprobe_design::load(Some(&path)))?.map_err(errors::design_error)
}

/// The design TOML `text` holds (`origin` names it).
pub fn from_text(py: Python<'_>, text: String, origin: &'static str) -> PyResult<ResolvedDesign> {
    detached(py, move || {
        let doc = Document::from_toml_str(&text, origin)?;
        tofprobe_design::resolve(doc, origin)
    })?
    .map_err(errors::design_error)
}

/// The design a dict of the document's tables holds.
pub fn from_dict(d: &Bound<'_, PyAny>) -> PyResult<ResolvedDesign> {
    let Some(Value::Table(table)) = to_toml(json_of(d, "d")?, "")? else {
        return Err(PyTypeError::new_err(format!(
            "`d` must be a dict of the configuration's tables, got {}",
            d.get_type().name()?
        )));
    };
    detached(d.py(), move || {
        let doc = Document::from_table(table, DICT_ORIGIN)?;
        tofprobe_design::resolve(doc, DICT_ORIGIN)
    })?
    .map_err(errors::design_error)
}

/// `design` with the dotted keys of `overrides` set (a `None` value removes the key, back
/// to its default), resolved again.
pub fn with_overrides(
    design: &ResolvedDesign,
    overrides: &Bound<'_, PyAny>,
) -> PyResult<ResolvedDesign> {
    let dict = overrides.cast::<PyDict>().map_err(|_| {
        PyTypeError::new_err(format!(
            "`overrides` must be a dict of dotted keys, e.g. {{\"pixel.bins\": 4}}, got {}",
            overrides
                .get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    let mut pairs = Vec::with_capacity(dict.len());
    for (k, v) in dict.iter() {
        let key: String = k.extract().map_err(|_| {
            PyTypeError::new_err("`overrides`: every key is a str, e.g. \"pixel.bins\"")
        })?;
        let value = if v.is_none() {
            None
        } else {
            to_toml(json_of(&v, &key)?, &key)?
        };
        pairs.push((key, value));
    }
    let keys: Vec<&str> = pairs.iter().map(|(k, _)| k.as_str()).collect();
    let origin = format!("{} with overrides of {}", design.origin, keys.join(", "));
    let document = design.document.clone();
    detached(overrides.py(), move || {
        let doc = document.with_overrides(&pairs, &origin)?;
        tofprobe_design::resolve(doc, &origin)
    })?
    .map_err(errors::design_error)
}

/// `value` through `json.dumps` (a value JSON cannot hold is a `TypeError` naming `at`).
fn json_of(value: &Bound<'_, PyAny>, at: &str) -> PyResult<serde_json::Value> {
    let text: String = value
        .py()
        .import("json")?
        .call_method1("dumps", (value,))
        .map_err(|e| {
            PyTypeError::new_err(format!(
                "`{at}` holds a value a configuration cannot (numbers, str, bool, lists and \
                 dicts of them): {e}"
            ))
        })?
        .extract()?;
    serde_json::from_str(&text).map_err(errors::input_error)
}

/// A JSON value as TOML (`None` for null at the top); a null inside, or an integer beyond
/// 64 bits, is a `ConfigError` naming its dotted path.
fn to_toml(v: serde_json::Value, at: &str) -> PyResult<Option<Value>> {
    use serde_json::Value as J;
    let join = |k: &str| {
        if at.is_empty() {
            k.to_string()
        } else {
            format!("{at}.{k}")
        }
    };
    let inner = |v: J, path: String| -> PyResult<Value> {
        to_toml(v, &path)?.ok_or_else(|| {
            errors::config(format!(
                "`{path}` is None: a configuration holds no None (leave the key out for its \
                 default)"
            ))
        })
    };
    Ok(Some(match v {
        J::Null => return Ok(None),
        J::Bool(b) => Value::Boolean(b),
        J::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) => Value::Integer(i),
            (None, Some(_)) if n.is_u64() => {
                return Err(errors::config(format!(
                    "`{at}` = {n} is out of range: integers up to 2^63 − 1"
                )));
            }
            (None, Some(f)) => Value::Float(f),
            (None, None) => return Err(errors::config(format!("`{at}` = {n} is not a number"))),
        },
        J::String(s) => Value::String(s),
        J::Array(a) => Value::Array(
            a.into_iter()
                .enumerate()
                .map(|(i, x)| inner(x, format!("{at}[{i}]")))
                .collect::<PyResult<_>>()?,
        ),
        J::Object(m) => Value::Table(
            m.into_iter()
                .map(|(k, x)| {
                    let p = join(&k);
                    inner(x, p).map(|v| (k, v))
                })
                .collect::<PyResult<Table>>()?,
        ),
    }))
}
