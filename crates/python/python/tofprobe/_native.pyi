"""Type stubs of tofprobe's native module (crates/python/src/lib.rs)."""

import os
from collections.abc import Callable
from typing import Any, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

# progress=: a callable progress(done, total), True for a tqdm bar, or None.
Progress = Union[Callable[[int, int], Any], bool, None]

class Summary(TypedDict):
    origin: str
    mode: str
    bins: list[int]
    frequencies_hz: list[float]
    tdc_bits: int
    width: int
    frame_pulses: int
    rom_depth: int
    registers: int
    shift: int
    frac_bits: int
    register_frac_bits: int
    adders: int
    cycles_per_pulse: int
    haar_scales: int
    pulses: int
    seed: int
    laser_rate_hz: float
    tdc_lsb_mm: float
    notes: list[str]
    array: tuple[int, int] | None
    superpixel: int | None

class Design:
    """A tofprobe design resolved once; see ``help(tofprobe.Design)``."""

    @staticmethod
    def default() -> Design: ...
    @staticmethod
    def from_toml(path: str | os.PathLike[str]) -> Design: ...
    @staticmethod
    def from_toml_text(text: str) -> Design: ...
    @staticmethod
    def from_dict(d: dict[str, Any]) -> Design: ...
    def with_overrides(self, overrides: dict[str, Any]) -> Design: ...
    @staticmethod
    def from_json(text: str) -> Design: ...
    def to_json(self) -> str: ...
    def to_toml(self) -> str: ...
    @property
    def origin(self) -> str: ...
    def summary(self) -> Summary: ...
    def simulate_scene(
        self,
        seed: int | None = None,
        pixel: tuple[int, int] | None = None,
        *,
        progress: Progress = None,
        threads: int | None = None,
    ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.uint16]]: ...
    def run_pixel(
        self, valid: npt.ArrayLike, tdc: npt.ArrayLike
    ) -> npt.NDArray[np.int64]: ...
    def spectrum(
        self, registers: npt.ArrayLike, pulses: int | None = None
    ) -> tuple[
        npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]
    ]: ...
    def probe_rom(self) -> npt.NDArray[np.int8]: ...
    def simulate_array(
        self,
        tiles: int | None = None,
        client: Any | None = None,
        *,
        progress: Progress = None,
        threads: int | None = None,
    ) -> dict[str, npt.NDArray[Any]]: ...
    def tile_rects(self, tiles: int) -> list[tuple[tuple[int, int], tuple[int, int]]]: ...
    def run_tile(
        self, rows: tuple[int, int], cols: tuple[int, int], threads: int | None = None
    ) -> dict[str, Any]: ...
    def merge_tiles(self, tiles: list[dict[str, Any]]) -> dict[str, npt.NDArray[Any]]: ...
    def dft(
        self, valid: npt.ArrayLike, tdc: npt.ArrayLike
    ) -> tuple[
        npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]
    ]: ...
    def float_sd(
        self, valid: npt.ArrayLike, tdc: npt.ArrayLike
    ) -> tuple[
        npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]
    ]: ...
    def noise_floor(self, pulses: int | None = None) -> npt.NDArray[np.float64]: ...
    def ntf(self, points: int = 512) -> dict[str, Any]: ...
    def widths(self) -> dict[str, Any]: ...
    def size(
        self,
        liberty: str | os.PathLike[str] | None = None,
        sky130: bool = False,
        sweep_bins: list[int] | None = None,
        sweep_widths: list[int] | None = None,
        node_nm: float = 40.0,
    ) -> dict[str, Any]: ...
    def _time_library_run_pixel(
        self,
        valid: npt.ArrayLike,
        tdc: npt.ArrayLike,
        repeat: int = 1,
        codes: bool = False,
    ) -> float: ...
    def __reduce__(self) -> tuple[Any, tuple[str, str | None]]: ...
    @staticmethod
    def _restore(design: str, rom: str | None = None) -> Design: ...
