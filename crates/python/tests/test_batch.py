"""Batch farms: the Slurm job-array script (scripts/slurm-array.sh) run locally with
SLURM_ARRAY_TASK_ID set gives tile sets whose merge is the single run's set; the
dask-jobqueue SLURMCluster's job script checked offline; a real Slurm run is opt-in
(`TOFPROBE_SLURM=1 pytest -m slurm`, docs/distributed.md)."""

import os
import subprocess

import numpy as np
import pytest

import tofprobe
from conftest import ROOT

SCRIPT = ROOT / "scripts" / "slurm-array.sh"


def test_the_job_array_script_parses():
    subprocess.run(["bash", "-n", str(SCRIPT)], check=True)


def test_the_job_array_script_runs_a_tiny_array_locally(cli, tmp_path, array_text):
    config = tmp_path / "plate.toml"
    config.write_text(array_text)
    out = tmp_path / "out"
    n = 3
    env = dict(os.environ, TOFPROBE=cli, SLURM_ARRAY_TASK_COUNT=str(n), SLURM_CPUS_PER_TASK="1")
    for i in range(n):
        subprocess.run(["bash", str(SCRIPT), "simulate", str(config), str(out)], check=True,
                       env=dict(env, SLURM_ARRAY_TASK_ID=str(i)), capture_output=True)
        assert (out / f"tile-{i}-of-{n}" / "manifest.json").is_file()
    subprocess.run(["bash", str(SCRIPT), "merge", str(out), str(n)], check=True, env=env,
                   capture_output=True)
    whole = tmp_path / "whole"
    subprocess.run([cli, "simulate", str(config), "--out", str(whole)], check=True,
                   capture_output=True)
    for name in ["registers.npy", "detections.npy", "amplitude_um.npy", "vibration.uff"]:
        assert (out / "array" / name).read_bytes() == (whole / name).read_bytes(), name
    want = tofprobe.Design.from_toml(config).simulate_array()["registers"]
    np.testing.assert_array_equal(np.load(out / "array" / "registers.npy"), want)
    # Outside a job array the script says what is missing.
    r = subprocess.run(["bash", str(SCRIPT), "simulate", str(config), str(out)], env={
        k: v for k, v in env.items() if k != "SLURM_ARRAY_TASK_ID"}, capture_output=True,
        text=True)
    assert r.returncode != 0 and "SLURM_ARRAY_TASK_ID" in r.stderr


def slurm_cluster(**extra):
    jq = pytest.importorskip("dask_jobqueue")
    return jq.SLURMCluster(queue="compute", account="proj123", cores=4, processes=2,
                           memory="8GB", walltime="01:00:00",
                           python="/shared/venvs/tofprobe/bin/python",
                           job_extra_directives=["--constraint=cpu"],
                           scheduler_options={"dashboard_address": None}, **extra)


def test_slurm_cluster_job_script_offline():
    cluster = slurm_cluster()
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    # One job = 4 cores, 2 worker processes of 2 threads each, the venv's python.
    for line in ["#SBATCH -p compute", "#SBATCH -A proj123", "#SBATCH --cpus-per-task=4",
                 "#SBATCH --mem=8G", "#SBATCH -t 01:00:00", "#SBATCH --constraint=cpu"]:
        assert line in script.splitlines(), line
    assert "/shared/venvs/tofprobe/bin/python -m distributed.cli.dask_worker" in script
    assert "--nworkers 2" in script and "--nthreads 2" in script


@pytest.mark.slurm
def test_a_real_slurm_cluster_runs_the_array_exactly(array_text):
    if os.environ.get("TOFPROBE_SLURM") != "1":
        pytest.skip("a real Slurm run is opt-in: TOFPROBE_SLURM=1 (docs/distributed.md)")
    jq = pytest.importorskip("dask_jobqueue")
    from distributed import Client

    d = tofprobe.Design.from_toml_text(array_text)
    cluster = jq.SLURMCluster(queue=os.environ.get("TOFPROBE_SLURM_QUEUE", "debug"), cores=1,
                              processes=1, memory="1GB",
                              interface=os.environ.get("TOFPROBE_SLURM_INTERFACE", "lo"))
    cluster.scale(jobs=2)
    client = Client(cluster)
    try:
        client.wait_for_workers(2, timeout=120)
        got = d.simulate_array(tiles=4, client=client)
        np.testing.assert_array_equal(got["registers"], d.simulate_array()["registers"])
    finally:
        client.close()
        cluster.close()
