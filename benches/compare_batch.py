#!/usr/bin/env python3
"""Meshes per minute through `voronoi-fit batch` and through the Ray runner
(`python -m voronoi_fit.cluster`), on the same meshes with the same options, in one run.

    target/venv/bin/python benches/compare_batch.py                  # ../shared/meshes, K = 2048, 300 steps
    target/venv/bin/python benches/compare_batch.py --sites 8192 --steps 600

Needs the CLI (`cargo build --profile ci`) and the package with Ray in the venv (what
tests/run.sh installs). Runs, sequentially, each into a fresh folder under
target/bench-batch/: `batch --jobs 1`, `batch --jobs 2`, and the Ray runner on a local
cluster with two task slots (`--ray local`, started inside the runner, so its start-up
counts). Each fit uses all of the machine's threads whatever the slot count (rayon's pool;
Ray's CPU count only limits how many tasks run at once). Writes
benches/results/batch_results.md.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--meshes", type=Path, default=ROOT.parent / "shared" / "meshes")
    ap.add_argument("--sites", default="2048")
    ap.add_argument("--steps", default="300")
    ap.add_argument("--eval-samples", default="200000")
    ap.add_argument("--out", type=Path, default=ROOT / "benches" / "results" / "batch_results.md")
    a = ap.parse_args()
    exe = ROOT / "target" / "ci" / "voronoi-fit"
    meshes = sorted(p for p in a.meshes.iterdir() if p.suffix.lower() in {".obj", ".stl", ".ply", ".off", ".glb", ".gltf"})
    work = ROOT / "target" / "bench-batch"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    manifest = work / "manifest.txt"
    manifest.write_text("\n".join(str(p) for p in meshes) + "\n")
    opts = ["--sites", a.sites, "--steps", a.steps, "--eval-samples", a.eval_samples]
    runs = []
    for jobs in (1, 2):
        out = work / f"batch-jobs{jobs}"
        t = time.time()
        r = subprocess.run([exe, "batch", *meshes, "--out", out, "--quiet", "--jobs", str(jobs), "--", *opts], capture_output=True, text=True)
        wall = time.time() - t
        print(r.stdout.strip(), r.stderr.strip()[-500:], sep="\n")
        runs.append((f"`voronoi-fit batch --jobs {jobs}`", wall, out, None))
    out = work / "ray"
    t = time.time()
    r = subprocess.run(
        [sys.executable, "-m", "voronoi_fit.cluster", "--ray", "local", manifest, "--out", out, "--quiet", *opts],
        capture_output=True,
        text=True,
        env={**os.environ, "RAY_USAGE_STATS_ENABLED": "0"},
    )
    wall = time.time() - t
    print(r.stdout.strip(), r.stderr.strip()[-500:], sep="\n")
    runs.append(("Ray runner, local cluster, 2 task slots (start-up included)", wall, out, json.loads((out / "cluster.json").read_text())))

    lines = [
        "# Meshes per minute: `voronoi-fit batch` and the Ray runner",
        "",
        f"`{' '.join(sys.argv)}` on {len(meshes)} meshes ({a.meshes}), options `{' '.join(opts)}`, "
        f"{os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}.",
        "",
        "| runner | wall s | meshes fitted | meshes per minute | seconds inside fits | slot time outside fits |",
        "|---|---|---|---|---|---|",
    ]
    for name, wall, out, stats in runs:
        import csv

        rows = list(csv.DictReader(open(out / "summary.csv")))
        fitted = [x for x in rows if x["status"].startswith("fitted")]
        inside = sum(float(x["seconds"] or 0) for x in fitted)
        slots = 2 if "2" in name else 1
        outside = stats["overhead_share"] if stats else max(0.0, 1 - inside / (wall * slots))
        lines.append(
            f"| {name} | {wall:.1f} | {len(fitted)} of {len(rows)} | {60 * len(fitted) / wall:.2f} | {inside:.1f} | {100 * outside:.0f}% |"
        )
    lines += [
        "",
        "\"Seconds inside fits\" sums each mesh's own wall time (its report's `total_seconds`); \"slot time outside "
        "fits\" is 1 − that sum / (wall time × concurrent slots): start-up, scheduling, writing, and tails where a slot "
        "waits for the last mesh. Two concurrent fits share the machine's two cores, so a fit takes longer inside a "
        "two-slot run than alone.",
    ]
    a.out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
