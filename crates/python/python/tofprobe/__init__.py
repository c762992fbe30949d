"""tofprobe from Python: a resolved design (``tofprobe.Design``) and numpy arrays in and out.

    >>> import tofprobe
    >>> d = tofprobe.Design.default()
    >>> valid, tdc = d.simulate_scene(seed=1)
    >>> freqs, amp_um, phase_deg = d.spectrum(d.run_pixel(valid, tdc))

Every computation is the Rust library's (the one resolution, the photon source, the
bit-true pixel, the one readout → phasor function, the array model); this package only
converts. ``help(tofprobe.Design)`` lists the calls.
"""

from tofprobe._native import Design, __version__

__all__ = ["Design", "__version__"]
