"""The exceptions tofprobe raises, all under one base, ``tofprobe.Error``.

Each is also the builtin exception a Python user would catch without knowing tofprobe, so
``except ValueError`` and ``except FileNotFoundError`` keep working:

- ``ConfigError`` (a ``ValueError``): a configuration — TOML file or text, dict, overrides —
  that does not resolve; the message names the key, the value, the allowed range and a
  value that works.
- ``InputError`` (a ``ValueError``): an argument's value refused (a TDC code out of range,
  a frame longer than ``frame_pulses``, tiles that do not cover the array), named.
- ``ToolMissingError`` (a ``RuntimeError``): an EDA tool (yosys, OpenSTA) that ``size``
  needs is not installed.
- ``FileError`` (an ``OSError``): a configuration path that is a directory, not a regular
  file, or unreadable, named; its subclass ``FileNotFoundError`` (also the builtin
  ``FileNotFoundError``) for a path that does not exist.

A wrong Python type (a float array for ``tdc``, a number for a path) stays a plain
``TypeError``, as numpy raises it.
"""

import builtins


class Error(Exception):
    """The base of every error tofprobe raises itself."""


class ConfigError(Error, ValueError):
    """A configuration that does not resolve (the message names the key)."""


class InputError(Error, ValueError):
    """An argument's value that tofprobe refuses (the message names the argument)."""


class ToolMissingError(Error, RuntimeError):
    """An EDA tool the call needs is not installed (the message names it)."""


class FileError(Error, OSError):
    """A configuration path that cannot be read: a directory, not a regular file, unreadable."""


class FileNotFoundError(FileError, builtins.FileNotFoundError):  # noqa: A001 (the builtin's name, on purpose)
    """A configuration path that does not exist (also the builtin ``FileNotFoundError``)."""


__all__ = ["Error", "ConfigError", "InputError", "ToolMissingError", "FileError",
           "FileNotFoundError"]
