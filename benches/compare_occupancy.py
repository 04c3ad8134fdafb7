#!/usr/bin/env python3
"""Compare the occupancy crate (through `voronoi-fit query`) with libigl on the same
meshes and queries, in one run.

    python benches/compare_occupancy.py [--n 1000000] [--meshes bunny,teapot,icosphere,featuretype,menger]
                                        [--bin target/release/voronoi-fit] [--no-build]

Setup: `pip install -r benches/requirements-bench.txt` (numpy, libigl 2.6.3, trimesh) and
`cargo build --release --bin voronoi-fit` (done automatically unless --no-build).

Queries follow the issue: half uniform in the bounding box grown by 10% (5% per side),
half area-weighted surface samples plus Gaussian noise with sigma = 1% of the diagonal.
Every mesh is written as a float32 binary STL so both sides see bit-identical vertices.

What is timed, fairly on both sides:
  - ours: the compute times that `voronoi-fit query --timings` reports (oracle build,
    winding numbers, closest points; file reading and writing excluded). The table's
    "ours" columns include the oracle build, which libigl's calls also do internally.
  - libigl: the wall time of `igl.fast_winding_number(V, F, Q)`,
    `igl.winding_number(V, F, Q)` and `igl.point_mesh_squared_distance(Q, V, F)` (each
    builds its own tree, like ours), with arrays prepared before the clock starts.
Both sides use every core (rayon / igl::parallel_for); CPU seconds (all threads) are
printed too, since on a shared machine they are steadier than wall time. With
--repeats > 1 the minimum is kept. Ratios are libigl time / our time (> 1: we are faster).
Accuracy is printed alongside: max |w - igl exact| and inside/outside flips at 0.5.
"""
import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import igl
import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "meshes"
MESHES = {
    "bunny": "mikedh__bunny.ply",
    "teapot": "mikedh__teapot.stl",
    "soup": "mikedh__soup.stl",
    "icosphere": None,  # trimesh icosphere, 20,480 faces
    "featuretype": "mikedh__featuretype.STL",  # CAD: large coplanar faces
    "menger": "elalish__mengerSponge3.glb",  # CAD: long thin coplanar triangles
}


def load(name):
    if MESHES[name] is None:
        m = trimesh.creation.icosphere(subdivisions=5)
    else:
        m = trimesh.load(SHARED / MESHES[name], force="mesh", process=False)
    V = np.asarray(m.vertices, dtype=np.float64).astype(np.float32).astype(np.float64)
    F = np.asarray(m.faces, dtype=np.int64)
    return V, F


def write_stl(path, V, F):
    rec = np.zeros(len(F), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = V[F].astype("<f4")
    with open(path, "wb") as f:
        f.write(b"voronoi-fit compare_occupancy".ljust(80, b" "))
        f.write(np.uint32(len(F)).tobytes())
        f.write(rec.tobytes())


def issue_queries(V, F, n, seed=1):
    rng = np.random.default_rng(seed)
    lo, hi = V.min(0), V.max(0)
    ext = hi - lo
    uniform = lo - 0.05 * ext + rng.random((n // 2, 3)) * 1.1 * ext
    tri = V[F]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    m = n - n // 2
    t = rng.choice(len(F), size=m, p=area / area.sum())
    r1 = np.sqrt(rng.random(m))[:, None]
    r2 = rng.random(m)[:, None]
    surf = (1 - r1) * tri[t, 0] + r1 * (1 - r2) * tri[t, 1] + r1 * r2 * tri[t, 2]
    near = surf + rng.normal(size=(m, 3)) * 0.01 * np.linalg.norm(ext)
    return np.ascontiguousarray(np.concatenate([uniform, near]))


def timed(f, repeats):
    best = None
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        r = f()
        w, cpu = time.perf_counter() - t, time.process_time() - c
        if best is None or w < best[0]:
            best = (w, cpu, r)
    return best


def ours(binary, stl, qpath, out, exact, repeats):
    best = None
    for _ in range(repeats):
        args = [str(binary), "query", str(stl), str(qpath), "-o", str(out), "--timings"]
        if exact:
            args.append("--exact")
        r = subprocess.run(args, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"voronoi-fit failed: {r.stderr}")
        t = json.loads(r.stderr.strip().splitlines()[-1])
        if best is None or t["winding_s"] < best["winding_s"]:
            best = t
    return best, dict(np.load(out))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--meshes", default="bunny,teapot,icosphere,featuretype,menger")
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "voronoi-fit"))
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--repeats", type=int, default=1)
    a = ap.parse_args()
    if not a.no_build:
        subprocess.run(["cargo", "build", "--release", "--bin", "voronoi-fit"], cwd=ROOT, check=True)
    rows = []
    simd = None
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name in a.meshes.split(","):
            V, F = load(name)
            Q = issue_queries(V, F, a.n)
            stl, qpath = tmp / f"{name}.stl", tmp / f"{name}.npy"
            write_stl(stl, V, F)
            np.save(qpath, Q)
            t_fast, o_fast = ours(a.bin, stl, qpath, tmp / "fast.npz", False, a.repeats)
            t_exact, o_exact = ours(a.bin, stl, qpath, tmp / "exact.npz", True, a.repeats)
            simd = t_fast.get("simd", "unknown")
            igl_fast = timed(lambda: igl.fast_winding_number(V, F, Q), a.repeats)
            igl_exact = timed(lambda: igl.winding_number(V, F, Q), a.repeats)
            igl_dist = timed(lambda: igl.point_mesh_squared_distance(Q, V, F), a.repeats)
            w_ref = igl_exact[2]
            build = t_fast["build_s"]
            sq = igl_dist[2][0]
            rel = np.abs(o_exact["squared_distance"] - sq) / np.maximum(sq, np.finfo(float).tiny)
            rows.append(
                dict(
                    mesh=f"{name} ({len(F)} faces)",
                    fast=(build + t_fast["winding_s"], t_fast["winding_cpu_s"], igl_fast[0], igl_fast[1]),
                    exact=(build + t_exact["winding_s"], t_exact["winding_cpu_s"], igl_exact[0], igl_exact[1]),
                    dist=(build + t_fast["distance_s"], t_fast["distance_cpu_s"], igl_dist[0], igl_dist[1]),
                    err_ours=np.abs(o_fast["winding"] - w_ref).max(),
                    fallback_share=t_fast["exact_fallbacks"] / len(Q),
                    err_igl=np.abs(igl_fast[2] - w_ref).max(),
                    flips_ours=int(np.count_nonzero((o_fast["winding"] >= 0.5) != (w_ref >= 0.5))),
                    flips_igl=int(np.count_nonzero((igl_fast[2] >= 0.5) != (w_ref >= 0.5))),
                    exact_err=np.abs(o_exact["winding"] - w_ref).max(),
                    dist_rel=rel.max(),
                )
            )
    print(f"\n{a.n} queries per mesh; wall seconds (CPU seconds, all threads); ratio = libigl wall / ours wall;"
          f" our fast winding packets use {simd} (VORONOI_FIT_SIMD=avx2 or sse2 caps it)")
    print("| mesh | kind | ours s | libigl s | ratio | accuracy |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        for kind, key, acc in [
            ("fast winding", "fast", f"max err ours {r['err_ours']:.2e} ({r['flips_ours']} flips; {100 * r['fallback_share']:.3f}% recomputed exactly), libigl {r['err_igl']:.2e} ({r['flips_igl']} flips)"),
            ("exact winding", "exact", f"max |ours - igl| {r['exact_err']:.1e}"),
            ("squared distance", "dist", f"max rel. diff {r['dist_rel']:.1e}"),
        ]:
            ow, oc, iw, ic = r[key]
            oc = "?" if oc is None else f"{oc:.2f}"
            print(f"| {r['mesh']} | {kind} | {ow:.3f} ({oc}) | {iw:.3f} ({ic:.2f}) | {iw / ow:.2f} | {acc} |")


if __name__ == "__main__":
    main()
