#!/usr/bin/env python3
"""How well a crust's caps follow the winding-number solid across an open mesh's holes.

    target/bench-venv/bin/python benches/cap_smoothness.py MESH CRUST [CRUST ...] [--away 0.02]

Where the mesh has holes, the winding-number solid (|w| >= 0.5) is closed by the
|w| = 0.5 level set, a smooth surface no input triangle covers, so the usual metrics
against the input say nothing about it. This script takes the crust's faces whose centres
are farther than `--away` (a share of the mesh's bounding-box diagonal) from the input
(from 400,000 area-uniform input samples, scipy's k-d tree) — the caps — and measures, with
libigl's exact generalized winding number:

- their area-weighted agreement with the level set's normal, mean |n_face · ∇w| / |∇w|
  (∇w by central differences at 1e-3 of the diagonal): 1 for a cap that turns with the
  level set, lower for a faceted one;
- their centres' distance to the level set, estimated as ||w| − 0.5| / |∇w|, mean and
  90th percentile, as % of the diagonal.

README, *Open meshes: caps across the holes*.
"""
import argparse

import igl
import numpy as np
import trimesh
from scipy.spatial import cKDTree


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("crusts", nargs="+")
    ap.add_argument("--away", type=float, default=0.02, help="share of the diagonal (default 0.02)")
    a = ap.parse_args()

    inp = trimesh.load(a.mesh, force="mesh", process=False)
    diag = float(np.linalg.norm(inp.bounds[1] - inp.bounds[0]))
    V = np.asarray(inp.vertices, dtype=np.float64)
    F = np.asarray(inp.faces, dtype=np.int64)
    samples, _ = trimesh.sample.sample_surface(inp, 400_000, seed=0)
    tree = cKDTree(samples)
    for path in a.crusts:
        crust = trimesh.load(path, force="mesh", process=False)
        dist, _ = tree.query(crust.triangles_center)
        cap = dist > a.away * diag
        if not cap.any():
            print(f"{path}: no crust face farther than {a.away:.3g} of the diagonal from the input (no caps)")
            continue
        q, n, area = crust.triangles_center[cap], crust.face_normals[cap], crust.area_faces[cap]
        w = igl.winding_number(V, F, q)
        e = 1e-3 * diag
        g = np.stack([(igl.winding_number(V, F, q + e * np.eye(3)[k]) - igl.winding_number(V, F, q - e * np.eye(3)[k]))
                      / (2 * e) for k in range(3)], 1)
        gn = np.linalg.norm(g, axis=1)
        ok = gn > 0
        off = np.abs(np.abs(w[ok]) - 0.5) / gn[ok] / diag * 100
        agree = np.abs((n[ok] * g[ok]).sum(1)) / gn[ok]
        print(f"{path}: {int(cap.sum())} cap faces; agreement with the level set's normal "
              f"{(agree * area[ok]).sum() / area[ok].sum():.4f}; distance to it mean {off.mean():.3f}, "
              f"90th percentile {np.percentile(off, 90):.3f} (% of the diagonal)")


if __name__ == "__main__":
    main()
