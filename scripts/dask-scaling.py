"""Dask scaling (docs/distributed.md "What scales"): the same 64 x 64 bit-true array in the
same tiles on a LocalCluster of one worker process and then of two (one thread each),
timed, with each worker's CPU seconds, the caller's (the scheduler runs in it) and the
CPU seconds the workers got per wall second (2.0 on two idle cores).

    target/py-venv/bin/python scripts/dask-scaling.py [PULSES] [TILES]

(the venv of scripts/python-package.sh; defaults 1,500,000 pulses per pixel, 16 tiles).
"""

import os
import resource
import sys
import time

import tofprobe
from dask.distributed import Client, LocalCluster

PULSES = int(sys.argv[1]) if len(sys.argv) > 1 else 1_500_000
TILES = int(sys.argv[2]) if len(sys.argv) > 2 else 16
DESIGN = tofprobe.Design.default().with_overrides({
    "acquisition.duration_s": None, "acquisition.pulses": PULSES,
    "array.rows": 64, "array.cols": 64, "array.pitch_um": 30.0, "array.mm_per_pixel": 1.0,
})


def cpu_seconds() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def run(workers: int):
    with LocalCluster(n_workers=workers, processes=True, threads_per_worker=1,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        before, mine = client.run(cpu_seconds), cpu_seconds()
        t = time.perf_counter()
        out = DESIGN.simulate_array(tiles=TILES, client=client)
        wall = time.perf_counter() - t
        after = client.run(cpu_seconds)
        used = [after[w] - before[w] for w in before]
        print(f"{workers} worker(s): {wall:.1f} s wall; workers' CPU-s "
              f"{[round(u, 1) for u in used]}, caller's {cpu_seconds() - mine:.1f}; "
              f"workers' CPU-s per wall-s {sum(used) / wall:.2f}", flush=True)
        return wall, sum(used), out["registers"]


if __name__ == "__main__":
    print(f"64 x 64 pixels x {PULSES} pulses in {TILES} tiles; load {os.getloadavg()}")
    w1, c1, r1 = run(1)
    w2, c2, r2 = run(2)
    print(f"speed-up {w1 / w2:.2f}x (two workers' CPU-s / one's: {c2 / c1:.2f}); "
          f"registers equal: {bool((r1 == r2).all())}; load {os.getloadavg()}")
