"""The Ray runner (`python -m voronoi_fit.cluster`) on a local Ray cluster started here
(`ray start --head` with two worker slots on this machine), with one worker killed
(SIGKILL) in the middle of its fit: the batch completes, every mesh is published exactly
once, complete, nothing is left in the work area, the broken mesh is recorded as bad
input, and a rerun skips everything. The results equal `voronoi-fit batch`'s.
"""
import csv
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import ROOT, SHARED, run

VENV_BIN = Path(sys.executable).parent
OPTS = ["--sites", "256", "--steps", "80", "--samples", "20000", "--eval-samples", "2000", "--polish-steps", "100"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def cluster():
    env = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0"}
    port = free_port()
    start = [str(VENV_BIN / "ray"), "start", "--head", f"--port={port}", "--num-cpus=2", "--include-dashboard=false"]
    r = subprocess.run(start, capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    try:
        yield f"127.0.0.1:{port}"
    finally:
        subprocess.run([str(VENV_BIN / "ray"), "stop", "--force"], capture_output=True, env=env)


def manifest(tmp_path):
    meshes = [ROOT / "assets" / m for m in ("bunny.obj", "torus.obj", "icosphere.obj", "box_with_hole.obj")]
    meshes += [SHARED / "mikedh__soup.stl", ROOT / "tests" / "malformed" / "nan_vertex.obj"]
    m = tmp_path / "manifest.txt"
    m.write_text("# the test's meshes\n" + "\n".join(str(p) for p in meshes) + "\n")
    return m


def rows(out):
    with open(out / "summary.csv") as f:
        return list(csv.DictReader(f))


def test_a_killed_worker_is_retried_and_every_mesh_lands_once(cluster, tmp_path):
    man, out = manifest(tmp_path), tmp_path / "out"
    cmd = [sys.executable, "-m", "voronoi_fit.cluster", "--ray", cluster, str(man), "--out", str(out), "--quiet", *OPTS]
    env = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0"}
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    killed = None
    t0 = time.time()
    while killed is None and time.time() - t0 < 300 and proc.poll() is None:
        for pid_file in (out / ".work").glob("*/attempt.pid") if (out / ".work").exists() else []:
            try:
                pid = int(pid_file.read_text())
            except (OSError, ValueError):
                continue
            os.kill(pid, signal.SIGKILL)
            killed = (pid, pid_file.parent.name.split(".")[0])
            break
        time.sleep(0.02)
    stdout, stderr = proc.communicate(timeout=600)
    assert killed is not None, f"no worker was seen working: {stdout}\n{stderr}"
    assert proc.returncode == 1, f"one mesh is broken, so the runner exits 1: {stdout}\n{stderr}"
    got = rows(out)
    names = [r["name"] for r in got]
    assert len(names) == len(set(names)) == 6, names
    by = {r["name"]: r for r in got}
    assert by["nan_vertex"]["status"] == "bad input" and "nan_vertex.obj" in by["nan_vertex"]["error"]
    for n in ("bunny", "torus", "icosphere", "box_with_hole", "mikedh__soup"):
        assert by[n]["status"].startswith("fitted"), by[n]
        folder = out / n
        for suffix in ("glb", "sites.npz", "report.json"):
            assert (folder / f"{n}.voronoi.{suffix}").is_file(), (n, suffix)
        assert not (folder / "attempt.pid").exists()
    pid, name = killed
    assert by[name]["attempt_pid"] != str(pid), "the killed attempt cannot have published"
    assert list((out / ".work").iterdir()) == [], "nothing half made is left"
    assert sorted(p.name for p in out.iterdir() if p.is_dir() and p.name != ".work") == sorted(
        n for n in names if n != "nan_vertex"
    )
    stats = json.loads((out / "cluster.json").read_text())
    assert stats["fitted"] == 5 and stats["task_slots"] == 2 and 0 <= stats["overhead_share"] < 1

    # The same crusts as `voronoi-fit batch` with the same options (GLB bytes).
    bout = tmp_path / "batch"
    run("batch", ROOT / "assets" / "torus.obj", "--out", bout, "--quiet", "--", *OPTS)
    assert (bout / "torus/torus.voronoi.glb").read_bytes() == (out / "torus/torus.voronoi.glb").read_bytes()

    # A rerun publishes nothing new.
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    again = rows(out)
    assert [x["status"] for x in again if x["name"] != "nan_vertex"] == ["done earlier"] * 5, r.stdout + r.stderr
