"""An array design run on a Dask cluster: one task per tile, merged in the caller.

    >>> from dask.distributed import Client, LocalCluster
    >>> client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
    >>> out = design.simulate_array(tiles=8, client=client)

Each task runs ``Design.run_tile`` in a worker process on a rayon pool sized to that
worker's threads; the caller merges the tiles with ``Design.merge_tiles`` (the Rust
library's merge), so the registers equal the single-process run bit for bit whatever the
tiling and the cluster. Orchestration only: partition, run and merge are the library's.
See docs/distributed.md for Slurm (``dask_jobqueue.SLURMCluster``) and hand-started
clusters.
"""

from __future__ import annotations

from typing import Any

from tofprobe._extras import require

# A missing Dask is an ImportError naming the extra to install.
require("dask", "tofprobe.dask (simulate_array(client=...))")


def worker_threads() -> int | None:
    """The threads of the Dask worker running the current task (``None`` outside one)."""
    from distributed import get_worker

    try:
        worker = get_worker()
    except ValueError:
        return None
    state = getattr(worker, "state", None)
    threads = getattr(state, "nthreads", None) or getattr(worker, "nthreads", None)
    return int(threads) if threads else None


def run_tile(design: Any, rows: tuple[int, int], cols: tuple[int, int]) -> dict:
    """One task: the tile's registers, on a rayon pool of the worker's threads."""
    return design.run_tile(rows, cols, threads=worker_threads())


def default_tiles(design: Any, client: Any) -> int:
    """Twice the cluster's threads (at most one pixel per tile)."""
    rows, cols = design.summary()["array"]
    threads = sum(client.nthreads().values()) or 1
    return max(1, min(2 * threads, rows * cols))


def simulate_array(design: Any, tiles: int | None, client: Any) -> dict:
    """``design.simulate_array(tiles, client=client)``: the tiles as tasks on ``client``."""
    if tiles is None:
        tiles = default_tiles(design, client)
    rects = design.tile_rects(tiles)
    futures = [client.submit(run_tile, design, r, c, pure=False) for r, c in rects]
    return design.merge_tiles(client.gather(futures))
