#!/usr/bin/env python3
"""The Hausdorff floor at a buried point of a mesh that is not a union of closed bodies
(open meshes, patch models such as the Utah teapot): the distance from the point to the
boundary of its winding-number solid, |w| >= 0.5, found along rays.

    target/bench-venv/bin/python benches/winding_floor.py MESH.obj [PRED.glb ...] [--point X Y Z]

Faces buried inside the solid (the teapot's spout and handle where they enter the body)
are part of the reference, and no closed surface comes near them, so the certified
Hausdorff distance of any closed surface has a floor there: the distance from the buried
point to the solid's boundary. A surface measured *below* it lies inside the true boundary
near that point. `benches/union_floor.py` builds the whole boundary exactly where the mesh
is a union of closed bodies; this script measures the one point that sets the figure.

Without --point, the point is the input-side witness of `voronoi-fit eval` for the first
PRED (the input point farthest from that crust). From the point, 4,000 rays (a Fibonacci
lattice of directions) are cut by bisection (40 halvings) where |w| (libigl's exact
generalized winding number) first drops below 0.5 within a fifth of the diagonal; the
floor is the shortest. Directions are sampled, so the figure is an upper bound of the true
distance, tight to about r·(1 − cos 1.6°) = 4e-4·r. Each PRED's distance from the point
(its own Hausdorff witness distance when that is the point) is printed beside it.

A witness *outside* the solid (a stray face with the solid on neither side, such as
snowden's) has the distance to the solid's boundary as its floor: the nearest of 1,000,000
area-uniform input samples that have the solid on exactly one side (an upper bound; caps
across holes, which no sample covers, are not counted).
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path

import igl
import numpy as np
import trimesh


def evaluate(bin_path, mesh, pred):
    out = subprocess.run([bin_path, "eval", str(mesh), str(pred), "--json", "--no-validity"],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("preds", nargs="*")
    ap.add_argument("--point", nargs=3, type=float, help="the buried point (default: the first PRED's witness)")
    ap.add_argument("--bin", default=str(Path(__file__).resolve().parent.parent / "target/release/voronoi-fit"))
    ap.add_argument("--rays", type=int, default=4000)
    ap.add_argument("--boundary-samples", type=int, default=1_000_000,
                    help="input samples for a point outside the solid (default 1,000,000)")
    a = ap.parse_args()

    m = trimesh.load(a.mesh, force="mesh", process=False)
    V = np.asarray(m.vertices, dtype=np.float64)
    F = np.asarray(m.faces, dtype=np.int64)
    diag = float(np.linalg.norm(m.bounds[1] - m.bounds[0]))
    evals = [evaluate(a.bin, a.mesh, p) for p in a.preds]
    if a.point is not None:
        q = np.array(a.point)
    elif evals:
        h = evals[0]["hausdorff"]
        if h["witness_direction"] != 0:
            sys.exit(f"{a.preds[0]}: its Hausdorff witness is on the crust, not the input; give --point")
        q = np.array(h["witness_point"])
    else:
        sys.exit("give --point or a prediction")

    def inside(p):
        return np.abs(igl.winding_number(V, F, p)) >= 0.5

    w = igl.winding_number(V, F, q[None])[0]
    if abs(w) < 0.5:
        # A stray face outside the solid (the solid on neither side): its floor is the
        # distance to the solid's boundary, estimated from input samples with the solid on
        # exactly one side (libigl's fast winding number at ±1e-4 of the diagonal along the
        # face normal); an upper bound, and caps across holes are not counted.
        pts, fi = trimesh.sample.sample_surface(m, a.boundary_samples, seed=0)
        nrm = m.face_normals[fi]
        eps = 1e-4 * diag
        side = [np.abs(igl.fast_winding_number(V, F, pts + s * eps * nrm)) >= 0.5 for s in (1.0, -1.0)]
        bnd = side[0] != side[1]
        if not bnd.any():
            sys.exit("no input sample is on the solid's boundary")
        floor = float(np.linalg.norm(pts[bnd] - q, axis=1).min())
        print(f"point {q.tolist()}, w = {w:.3f} (outside: a stray face); nearest of {int(bnd.sum())} boundary samples "
              f"{floor:.5f} ({100 * floor / diag:.4f}% of the mesh's diagonal {diag:.4f})")
        report(a.preds, evals, q, floor)
        return
    n = a.rays
    i = np.arange(n) + 0.5
    phi, theta = np.arccos(1 - 2 * i / n), np.pi * (1 + 5 ** 0.5) * i
    d = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], 1)
    lo, hi = np.zeros(n), np.full(n, 0.2 * diag)
    reach = ~inside(q + hi[:, None] * d)
    for _ in range(40):
        mid = (lo + hi) / 2
        ins = inside(q + mid[:, None] * d)
        lo, hi = np.where(ins, mid, lo), np.where(ins, hi, mid)
    if not reach.any():
        sys.exit("no ray leaves the solid within a fifth of the diagonal")
    floor = float(hi[reach].min())
    print(f"point {q.tolist()}, w = {w:.3f}; floor {floor:.5f} ({100 * floor / diag:.4f}% of the mesh's diagonal {diag:.4f})")
    report(a.preds, evals, q, floor)


def report(preds, evals, q, floor):
    for p, e in zip(preds, evals):
        h = e["hausdorff"]
        same = h["witness_direction"] == 0 and np.allclose(h["witness_point"], q)
        note = "its witness is this point" if same else "its witness is elsewhere"
        print(f"{p}: Hausdorff {h['hi']:.5f} ({100 * h['hi'] / h['diagonal']:.4f}% of {h['diagonal']:.4f}); {note}; "
              f"{'above' if h['hi'] > floor else 'below'} the floor by {abs(h['hi'] - floor):.5f}")


if __name__ == "__main__":
    main()
