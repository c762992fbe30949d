"""Plots of tofprobe's arrays with matplotlib (``pip install "tofprobe[plot]"``): a
spectrum — the pixel's amplitudes beside the float DFT and the closed-form floor — and an
array's amplitude and phase maps at one bin. Each returns the matplotlib Figure; nothing
is shown or saved here (``fig.savefig(path)``).

    >>> from tofprobe import plot
    >>> fig = plot.spectrum(f, amp_um, dft_um=amp_dft, floor_um=d.noise_floor())
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tofprobe._extras import require

require("plot", "tofprobe.plot")

import matplotlib.pyplot as plt  # noqa: E402


def spectrum(frequencies_hz: Any, amplitude_um: Any, *, dft_um: Any = None,
             floor_um: Any = None, title: str = "") -> Any:
    """The pixel's amplitude per bin (µm, log scale), with the float DFT of the same
    photons and the closed-form noise floor when given."""
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.semilogy(frequencies_hz, amplitude_um, "o-", label="bit-true pixel (ΣΔ probe)")
    if dft_um is not None:
        ax.semilogy(frequencies_hz, dft_um, "x--", label="float DFT of the same photons")
    if floor_um is not None:
        ax.semilogy(frequencies_hz, floor_um, ":", label="closed-form noise floor (eq. 12)")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("amplitude (µm)")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    return fig


def vibration_map(maps: dict, bin_index: int | None = None) -> Any:
    """``simulate_array``'s amplitude and phase maps at ``bin_index`` (default: the bin of
    the largest mean amplitude), side by side."""
    k = int(np.argmax(maps["amplitude_um"].mean(axis=(1, 2)))) if bin_index is None \
        else bin_index
    f = maps["frequencies_hz"][k]
    fig, axes = plt.subplots(1, 2, figsize=(9, 4))
    for ax, data, label, cmap in [(axes[0], maps["amplitude_um"][k], "amplitude (µm)", "viridis"),
                                  (axes[1], maps["phase_deg"][k], "phase (deg)", "twilight")]:
        im = ax.imshow(data, cmap=cmap, origin="upper")
        ax.set_title(f"{label} at {f:.0f} Hz")
        ax.set_xlabel("column")
        ax.set_ylabel("row")
        fig.colorbar(im, ax=ax, shrink=0.8)
    fig.tight_layout()
    return fig
