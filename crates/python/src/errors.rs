//! The exceptions the package raises, defined in Python (`tofprobe/errors.py`, under one
//! base `tofprobe.Error`, each also the builtin a user would catch) and raised from here:
//! a configuration that does not resolve is a `ConfigError` (a `ValueError`), a file that
//! does not exist a `tofprobe.FileNotFoundError` (the builtin's subclass), a directory or
//! an unreadable file a `FileError` (an `OSError`), a refused argument value an
//! `InputError` (a `ValueError`), a missing EDA tool a `ToolMissingError`.

use pyo3::PyErr;
use tofprobe_design::DesignError;

pyo3::import_exception!(tofprobe.errors, ConfigError);
pyo3::import_exception!(tofprobe.errors, InputError);
pyo3::import_exception!(tofprobe.errors, ToolMissingError);
pyo3::import_exception!(tofprobe.errors, FileError);
pyo3::import_exception!(tofprobe.errors, FileNotFoundError);

/// A library error (an argument's value refused) as an `InputError` carrying its message.
pub fn input_error(e: impl std::fmt::Display) -> PyErr {
    InputError::new_err(e.to_string())
}

/// A message as an `InputError`.
pub fn input(message: impl Into<String>) -> PyErr {
    InputError::new_err(message.into())
}

/// A configuration's error: the file's (missing, a directory, unreadable) as the file
/// errors, anything else as a `ConfigError`; the library's message either way.
pub fn design_error(e: DesignError) -> PyErr {
    let message = e.to_string();
    match &e {
        DesignError::Read { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            FileNotFoundError::new_err(message)
        }
        DesignError::Read { .. } | DesignError::IsDirectory { .. } => FileError::new_err(message),
        _ => ConfigError::new_err(message),
    }
}

/// A message as a `ConfigError`.
pub fn config(message: String) -> PyErr {
    ConfigError::new_err(message)
}

/// A missing tool as a `ToolMissingError`.
pub fn tool_missing(message: String) -> PyErr {
    ToolMissingError::new_err(message)
}
