"""The array in tiles: the partition, tiles run and merged locally, tiles that travelled
through pickle (misaligned buffers, copied), bad tiles refused naming the argument, and
the array split into tasks on a real Dask LocalCluster of two worker processes: the
registers equal the single-process run bit for bit."""

import os
import pickle

import numpy as np
import pytest

import tofprobe


@pytest.fixture(scope="module")
def arr(array_text):
    return tofprobe.Design.from_toml_text(array_text)


@pytest.fixture(scope="module")
def whole(arr):
    return arr.simulate_array()


def same(a, b):
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def test_tile_rects_partition_the_array(arr):
    rows, cols = arr.summary()["array"]  # 4 × 3
    assert arr.tile_rects(1) == [((0, rows), (0, cols))]
    assert arr.tile_rects(5) == [((0, 1), (0, 3)), ((1, 2), (0, 3)), ((2, 3), (0, 3)),
                                 ((3, 4), (0, 1)), ((3, 4), (1, 3))]
    for n in range(1, rows * cols + 1):
        cover = np.zeros((rows, cols), int)
        for (r0, r1), (c0, c1) in arr.tile_rects(n):
            cover[r0:r1, c0:c1] += 1
        assert (cover == 1).all(), n


def test_the_level_map_names_the_level_each_pixel_ran(arr, whole):
    # The default level, bit-true (code 0), at every pixel: the set's level.npy.
    assert whole["level"].shape == whole["detections"].shape
    assert (whole["level"] == 0).all()


def test_local_tiles_give_the_same_array(arr, whole):
    for n in (2, 5, 12):
        same(arr.simulate_array(tiles=n), whole)
    # run_tile with its own pool, merged by hand in any order.
    parts = [arr.run_tile(r, c, threads=1) for r, c in arr.tile_rects(3)]
    assert parts[0]["registers"].dtype == np.int64 and parts[0]["registers"].shape == (1, 3, 8)
    assert parts[0]["detections"].dtype == np.uint64
    same(arr.merge_tiles(parts[::-1]), whole)


def test_tiles_that_travelled_through_pickle_merge_even_misaligned(arr, whole):
    parts = pickle.loads(pickle.dumps([arr.run_tile(r, c) for r, c in arr.tile_rects(4)]))
    for p in parts:
        regs = p["registers"]
        raw = np.zeros(regs.nbytes + 1, np.uint8)[1:].view(np.int64).reshape(regs.shape)
        raw[...] = regs
        assert not raw.flags.aligned
        p["registers"] = raw
    same(arr.merge_tiles(parts), whole)


def test_a_pickled_design_carries_its_rom_once_generated(arr):
    fresh = pickle.dumps(tofprobe.Design.from_json(arr.to_json()))
    rom = arr.probe_rom()  # generated now: the pickle carries it
    carried = pickle.dumps(arr)
    assert len(carried) > len(fresh) + rom.size // 8
    again = pickle.loads(carried)
    np.testing.assert_array_equal(again.probe_rom(), rom)
    assert again.to_json() == arr.to_json()
    np.testing.assert_array_equal(again.run_tile((0, 1), (0, 3))["registers"],
                                  arr.run_tile((0, 1), (0, 3))["registers"])
    with pytest.raises(ValueError, match="pickled probe ROM"):
        tofprobe.Design._restore(arr.to_json(), "{not json")


def test_bad_tiles_are_refused_naming_the_argument(arr):
    for bad in (0, 13):
        with pytest.raises(ValueError, match="tiles"):
            arr.simulate_array(tiles=bad)
        with pytest.raises(ValueError, match="tiles"):
            arr.tile_rects(bad)
    with pytest.raises(TypeError, match="tiles"):
        arr.simulate_array(tiles="four")
    with pytest.raises(OverflowError):
        arr.tile_rects(-1)
    with pytest.raises(ValueError, match="threads"):
        arr.run_tile((0, 1), (0, 1), threads=0)
    with pytest.raises(ValueError, match="not a non-empty part"):
        arr.run_tile((0, 9), (0, 1))
    parts = [arr.run_tile(r, c) for r, c in arr.tile_rects(2)]
    with pytest.raises(ValueError, match=r"pixel \(2, 0\) is in no tile"):
        arr.merge_tiles(parts[:1])
    with pytest.raises(ValueError, match="in two tiles"):
        arr.merge_tiles(parts + parts[:1])
    with pytest.raises(TypeError, match="list"):
        arr.merge_tiles(tuple(parts))
    with pytest.raises(TypeError, match=r"tiles\[1\]"):
        arr.merge_tiles([parts[0], 7])
    short = dict(parts[1], registers=parts[1]["registers"][:1])
    with pytest.raises(ValueError, match=r"`tiles\[1\]`: rows 2..4"):
        arr.merge_tiles([parts[0], short])
    with pytest.raises(TypeError, match=r"tiles\[0\]\['registers'\]"):
        arr.merge_tiles([dict(parts[0], registers=parts[0]["registers"] * 0.5), parts[1]])
    with pytest.raises(ValueError, match=r"\[array\]"):
        tofprobe.Design.default().tile_rects(2)


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                       dashboard_address=None, silence_logs=40)
    c = distributed.Client(cluster)
    c.wait_for_workers(2)
    yield c
    c.close()
    cluster.close()


def test_dask_tasks_run_in_two_worker_processes_and_merge_exactly(arr, whole, client):
    pids = client.run(os.getpid)
    assert len(set(pids.values())) == 2 and os.getpid() not in pids.values()
    # Each task sizes its rayon pool to its worker's one thread.
    import tofprobe.dask

    threads = client.gather(client.map(lambda _: tofprobe.dask.worker_threads(), range(4)))
    assert threads == [1, 1, 1, 1]
    assert tofprobe.dask.worker_threads() is None  # outside a task
    for tiles in (None, 5, 12):
        same(arr.simulate_array(tiles=tiles, client=client), whole)
    # The design travels to the workers (pickled as JSON) and back unchanged.
    echoed = client.submit(lambda d: d.to_json(), arr).result()
    assert echoed == arr.to_json()
    with pytest.raises(ValueError, match="tiles"):
        arr.simulate_array(tiles=0, client=client)
