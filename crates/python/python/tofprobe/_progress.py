"""``progress=True``: a tqdm bar fed by the native calls' ``progress(done, total)``.

The native calls take ``progress`` as a callable ``progress(done, total)`` (called from the
calling thread, with the GIL, about every 50 ms and once at the end), ``True`` for this bar,
or ``None``.
"""

from __future__ import annotations


class Bar:
    """A tqdm bar as a ``progress(done, total)`` callable; ``close()`` ends it."""

    def __init__(self, desc: str, unit: str) -> None:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            raise ImportError(
                "progress=True draws a tqdm bar, and tqdm is not installed: "
                'pip install "tofprobe[progress]" (or pip install tqdm), or pass '
                "progress=callable(done, total)"
            ) from None
        self._tqdm = tqdm
        self._desc, self._unit = desc, unit
        self._bar = None

    def __call__(self, done: int, total: int) -> None:
        if self._bar is None:
            self._bar = self._tqdm(total=total, desc=self._desc, unit=self._unit,
                                   unit_scale=True, leave=False)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
