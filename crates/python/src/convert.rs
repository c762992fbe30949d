//! numpy in, Rust slices out, and the errors on the way: every array argument is taken
//! through `numpy.asarray`, checked for its dimension and dtype (a `TypeError` naming the
//! argument otherwise) and borrowed without a copy when it is aligned and contiguous (an
//! array rebuilt from a pickle or a Dask frame may be neither: it is copied once, then
//! borrowed). Library errors become `tofprobe.InputError` (a `ValueError`) with the
//! library's message, which names the field, the value and the allowed range.

use numpy::{Element, PyReadonlyArray1};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use tofprobe_pixel::{FrameDriver, PixelError, TdcCode, ValidCodes};

/// A library error (an argument's value refused) as a `tofprobe.InputError` (a
/// `ValueError`) carrying its message.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    crate::errors::input_error(e)
}

/// `numpy.asarray(obj)`, refused unless it is one-dimensional; `name` is the argument.
pub fn as_1d<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let array = py.import("numpy")?.call_method1("asarray", (obj,))?;
    let ndim: usize = array.getattr("ndim")?.extract()?;
    if ndim != 1 {
        let shape = array.getattr("shape")?.str()?.to_string();
        return Err(crate::errors::input(format!(
            "`{name}` must be a one-dimensional array, got shape {shape}"
        )));
    }
    Ok(array)
}

/// The dtype's name of an array (for messages).
pub fn dtype_name(array: &Bound<'_, PyAny>) -> String {
    array
        .getattr("dtype")
        .and_then(|d| d.str())
        .map(|s| s.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// A borrowed 1-D array of `T`, or `None` when its dtype is not `T`. Copies first when the
/// array is misaligned or not contiguous (then `as_slice` would refuse it).
pub fn try_borrow<'py, T: Element>(
    array: &Bound<'py, PyAny>,
) -> PyResult<Option<PyReadonlyArray1<'py, T>>> {
    let Ok(a) = array.extract::<PyReadonlyArray1<'py, T>>() else {
        return Ok(None);
    };
    if a.as_slice().is_ok() {
        return Ok(Some(a));
    }
    // `.copy()` is C-contiguous and aligned.
    let copy = array.call_method0("copy")?;
    Ok(Some(copy.extract::<PyReadonlyArray1<'py, T>>()?))
}

/// The slice of a borrowed array ([`try_borrow`] made it contiguous).
pub fn slice<'a, T: Element>(a: &'a PyReadonlyArray1<'_, T>, name: &str) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|e| crate::errors::input(format!("`{name}`: {e}")))
}

/// A bool array argument (`valid`): refused with a `TypeError` for any other dtype.
pub fn bool_array<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArray1<'py, bool>> {
    let array = as_1d(name, obj)?;
    try_borrow::<bool>(&array)?.ok_or_else(|| {
        PyTypeError::new_err(format!(
            "`{name}` must be a bool array, got dtype {}",
            dtype_name(&array)
        ))
    })
}

/// A register array argument: int64, or any integer dtype converted to it (`TypeError`
/// for floats and the rest).
pub fn int64_array<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArray1<'py, i64>> {
    let array = as_1d(name, obj)?;
    if let Some(a) = try_borrow::<i64>(&array)? {
        return Ok(a);
    }
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if kind != "i" && kind != "u" {
        return Err(PyTypeError::new_err(format!(
            "`{name}` must be an integer array (int64), got dtype {}",
            dtype_name(&array)
        )));
    }
    let converted = array.call_method1("astype", ("int64",))?;
    converted.extract::<PyReadonlyArray1<'py, i64>>()
}

/// The TDC codes of one pulse stream in any integer dtype, borrowed.
pub enum Codes<'py> {
    U8(PyReadonlyArray1<'py, u8>),
    U16(PyReadonlyArray1<'py, u16>),
    U32(PyReadonlyArray1<'py, u32>),
    U64(PyReadonlyArray1<'py, u64>),
    I8(PyReadonlyArray1<'py, i8>),
    I16(PyReadonlyArray1<'py, i16>),
    I32(PyReadonlyArray1<'py, i32>),
    I64(PyReadonlyArray1<'py, i64>),
}

impl std::fmt::Debug for Codes<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Codes")
    }
}

/// The `tdc` argument: any integer dtype, one-dimensional (`TypeError` otherwise).
pub fn codes<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<Codes<'py>> {
    let a = as_1d(name, obj)?;
    if let Some(x) = try_borrow::<i32>(&a)? {
        return Ok(Codes::I32(x));
    }
    if let Some(x) = try_borrow::<i64>(&a)? {
        return Ok(Codes::I64(x));
    }
    if let Some(x) = try_borrow::<u16>(&a)? {
        return Ok(Codes::U16(x));
    }
    if let Some(x) = try_borrow::<u8>(&a)? {
        return Ok(Codes::U8(x));
    }
    if let Some(x) = try_borrow::<u32>(&a)? {
        return Ok(Codes::U32(x));
    }
    if let Some(x) = try_borrow::<u64>(&a)? {
        return Ok(Codes::U64(x));
    }
    if let Some(x) = try_borrow::<i16>(&a)? {
        return Ok(Codes::I16(x));
    }
    if let Some(x) = try_borrow::<i8>(&a)? {
        return Ok(Codes::I8(x));
    }
    Err(PyTypeError::new_err(format!(
        "`{name}` must be an integer array (TDC codes), got dtype {}",
        dtype_name(&a)
    )))
}

/// A TDC code stream borrowed from numpy, whatever its integer type.
#[derive(Debug, Clone, Copy)]
pub enum CodeSlice<'a> {
    U8(&'a [u8]),
    U16(&'a [u16]),
    U32(&'a [u32]),
    U64(&'a [u64]),
    I8(&'a [i8]),
    I16(&'a [i16]),
    I32(&'a [i32]),
    I64(&'a [i64]),
}

impl<'py> Codes<'py> {
    /// The borrowed slice.
    pub fn slice(&self, name: &str) -> PyResult<CodeSlice<'_>> {
        Ok(match self {
            Codes::U8(a) => CodeSlice::U8(slice(a, name)?),
            Codes::U16(a) => CodeSlice::U16(slice(a, name)?),
            Codes::U32(a) => CodeSlice::U32(slice(a, name)?),
            Codes::U64(a) => CodeSlice::U64(slice(a, name)?),
            Codes::I8(a) => CodeSlice::I8(slice(a, name)?),
            Codes::I16(a) => CodeSlice::I16(slice(a, name)?),
            Codes::I32(a) => CodeSlice::I32(slice(a, name)?),
            Codes::I64(a) => CodeSlice::I64(slice(a, name)?),
        })
    }
}

impl CodeSlice<'_> {
    /// Number of codes.
    pub fn len(&self) -> usize {
        match self {
            CodeSlice::U8(s) => s.len(),
            CodeSlice::U16(s) => s.len(),
            CodeSlice::U32(s) => s.len(),
            CodeSlice::U64(s) => s.len(),
            CodeSlice::I8(s) => s.len(),
            CodeSlice::I16(s) => s.len(),
            CodeSlice::I32(s) => s.len(),
            CodeSlice::I64(s) => s.len(),
        }
    }
}

macro_rules! code_slice_from {
    ($($v:ident: $t:ty),*) => {$(
        impl<'a> From<&'a [$t]> for CodeSlice<'a> {
            fn from(s: &'a [$t]) -> Self {
                CodeSlice::$v(s)
            }
        }
    )*};
}
code_slice_from!(U8: u8, U16: u16, U32: u32, U64: u64, I8: i8, I16: i16, I32: i32, I64: i64);

/// Calls `$f::<T>($slice, args...)` for the integer type the codes arrived in (the one
/// dtype dispatch; the decoding itself is the library's, `tofprobe_pixel::ValidCodes`).
macro_rules! with_codes {
    ($codes:expr, |$s:ident| $body:expr) => {
        match $codes {
            CodeSlice::U8($s) => $body,
            CodeSlice::U16($s) => $body,
            CodeSlice::U32($s) => $body,
            CodeSlice::U64($s) => $body,
            CodeSlice::I8($s) => $body,
            CodeSlice::I16($s) => $body,
            CodeSlice::I32($s) => $body,
            CodeSlice::I64($s) => $body,
        }
    };
}

impl CodeSlice<'_> {
    /// Runs the frame (`valid`, these codes: pulses `first ..` of the frame) through
    /// `driver`, read in place by the library ([`ValidCodes`]: decoded a block at a time,
    /// the range check riding along); a valid code outside 0 ..= `max_code` is refused
    /// afterwards, naming the pulse (the driver's registers are then not to be read).
    pub fn run_pixel(
        &self,
        valid: &[bool],
        first: u64,
        max_code: u32,
        driver: &mut FrameDriver<'_>,
    ) -> Result<(), PixelError> {
        fn go<T: TdcCode>(
            valid: &[bool],
            tdc: &[T],
            first: u64,
            max_code: u32,
            driver: &mut FrameDriver<'_>,
        ) -> Result<(), PixelError> {
            let frame = ValidCodes::new(valid, tdc, max_code)?;
            driver.run(&frame, first)?;
            frame.check()
        }
        with_codes!(*self, |s| go(valid, s, first, max_code, driver))
    }

    /// The codes of pulses `r` (a chunk of the frame).
    pub fn range(&self, r: std::ops::Range<usize>) -> CodeSlice<'_> {
        with_codes!(*self, |s| CodeSlice::from(&s[r]))
    }

    /// The range check of the whole frame alone (the library's `ValidCodes::scan`).
    pub fn scan(&self, valid: &[bool], max_code: u32) -> Result<(), PixelError> {
        with_codes!(*self, |s| ValidCodes::new(valid, s, max_code)?.scan())
    }

    /// The frame (`valid`, these codes) in the drivers' compact form (the library's
    /// decode), range-checked.
    pub fn compact(&self, valid: &[bool], max_code: u32) -> Result<Vec<u32>, PixelError> {
        with_codes!(*self, |s| ValidCodes::new(valid, s, max_code)?.compact())
    }

    /// The frame (`valid`, these codes) as `Option`s (the float references' form),
    /// range-checked.
    pub fn options(&self, valid: &[bool], max_code: u32) -> Result<Vec<Option<u32>>, PixelError> {
        with_codes!(*self, |s| ValidCodes::new(valid, s, max_code)?.options())
    }
}

impl crate::Design {
    /// The borrowed frame `(valid, tdc)`, checked: equal lengths, at most one frame.
    pub(crate) fn checked_frame<'a>(
        &self,
        valid_a: &'a numpy::PyReadonlyArray1<'_, bool>,
        tdc_a: &'a Codes<'_>,
    ) -> PyResult<(&'a [bool], CodeSlice<'a>)> {
        let valid_s = slice(valid_a, "valid")?;
        let tdc_s: CodeSlice<'_> = tdc_a.slice("tdc")?;
        if valid_s.len() != tdc_s.len() {
            return Err(crate::errors::input(format!(
                "`valid` has {} pulses and `tdc` {}: one code per pulse",
                valid_s.len(),
                tdc_s.len()
            )));
        }
        let n = self.inner.pixel.frame_pulses;
        if valid_s.len() as u64 > n {
            return Err(crate::errors::input(format!(
                "{} pulses exceed one frame of pixel.frame_pulses = {n}: pass at most {n} \
                 (one frame; call once per frame)",
                valid_s.len()
            )));
        }
        Ok((valid_s, tdc_s))
    }

    /// The frame `(valid, tdc)` as the library's detections (`None` = no detection),
    /// checked like `run_pixel`'s.
    pub(crate) fn frame(
        &self,
        py: Python<'_>,
        valid: &Bound<'_, PyAny>,
        tdc: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<Option<u32>>> {
        let valid_a = bool_array("valid", valid)?;
        let tdc_a = codes("tdc", tdc)?;
        let (valid_s, tdc_s) = self.checked_frame(&valid_a, &tdc_a)?;
        let max_code = self.max_code();
        py.detach(|| tdc_s.options(valid_s, max_code))
            .map_err(value_error)
    }
}
