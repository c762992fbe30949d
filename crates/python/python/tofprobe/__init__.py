"""tofprobe from Python: a resolved design (``tofprobe.Design``) and numpy arrays in and out.

    >>> import tofprobe
    >>> d = tofprobe.Design.default()
    >>> valid, tdc = d.simulate_scene(seed=1)
    >>> freqs, amp_um, phase_deg = d.spectrum(d.run_pixel(valid, tdc))

Every computation is the Rust library's (the one resolution, the photon source, the
bit-true pixel, the one readout → phasor function, the array model); this package only
converts. ``help(tofprobe.Design)`` lists the calls and says what B, W, N, L and G are;
``tofprobe.errors`` the exceptions (all ``tofprobe.Error``). Optional parts and their
extras: ``tofprobe.dask`` (``pip install "tofprobe[dask]"``), ``tofprobe.plot``
(``[plot]``), ``progress=True`` bars (``[progress]``), Slurm clusters (``[slurm]``).
"""

from tofprobe import errors
from tofprobe._native import Design, __version__
from tofprobe.errors import ConfigError, Error, FileError, InputError, ToolMissingError

__all__ = ["Design", "Error", "ConfigError", "InputError", "ToolMissingError", "FileError",
           "errors", "__version__"]
# tofprobe.FileNotFoundError (tofprobe.errors.FileNotFoundError) is reachable but not in
# __all__: a star import must not shadow the builtin.
FileNotFoundError = errors.FileNotFoundError  # noqa: A001
