#!/usr/bin/env python3
"""The Hausdorff floor of a mesh made of overlapping closed bodies: the exact boolean union
of its bodies, measured against the mesh by `voronoi-fit eval`, like any crust.

    target/bench-venv/bin/python benches/union_floor.py MESH.obj [PRED.glb ...] [--bin voronoi-fit]

Faces of one body buried inside another are part of the reference, and no closed surface
comes near them, so the certified Hausdorff distance of any closed surface has a floor:
the largest distance from a buried point to the solid's boundary. The union itself sits
on it. A surface measured *below* it is not better: it lies inside the true boundary
near the buried points farthest from it (on cad_union at K = 8,192: the union 13.898% of
the diagonal, our crust 13.896%, the VoroMesh-style fit 13.867% and marching cubes
13.882%; README, *Faces inside the solid*). Each PRED is measured too, and its side of
the Hausdorff distance to the union is given, which is how far it is from the solid's
true boundary.

The union is made by manifold3d (an exact-topology boolean library; its vertices are
float32, which moves them by at most ~1e-7 of the part's size here), from the mesh's
connected pieces, each oriented outward first. manifold3d is pinned in
benches/requirements-bench.txt (the benchmark's venv).
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]


def union_of_bodies(path):
    import manifold3d

    mesh = trimesh.load(path, force="mesh", process=False)
    bodies = mesh.split(only_watertight=False)
    total = None
    for body in bodies:
        body = body.copy()
        body.merge_vertices()
        if not body.is_watertight:
            sys.exit(f"{path}: a piece with {len(body.faces)} faces is not closed; the floor needs closed bodies")
        if body.volume < 0:
            body.invert()
        m = manifold3d.Manifold(
            manifold3d.Mesh(
                vert_properties=np.asarray(body.vertices, dtype=np.float32),
                tri_verts=np.asarray(body.faces, dtype=np.uint32),
            )
        )
        if m.status() != manifold3d.Error.NoError:
            sys.exit(f"{path}: manifold3d refused a piece: {m.status()}")
        total = m if total is None else total + m
    out = total.to_mesh()
    return trimesh.Trimesh(np.asarray(out.vert_properties)[:, :3], np.asarray(out.tri_verts), process=False), len(bodies)


def evaluate(exe, reference, prediction):
    r = subprocess.run([exe, "eval", str(reference), str(prediction), "--json", "--no-validity"],
                       capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("predictions", nargs="*")
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "voronoi-fit"))
    args = ap.parse_args()
    union, n = union_of_bodies(args.mesh)
    with tempfile.TemporaryDirectory() as tmp:
        upath = Path(tmp) / "union.obj"
        union.export(upath)
        d = evaluate(args.bin, args.mesh, upath)
        diag = d["reference_diagonal"]
        print(f"{args.mesh}: {n} bodies; their union ({len(union.faces)} triangles) is at certified Hausdorff "
              f"{100 * d['hausdorff']['hi'] / diag:.3f}% of the diagonal (the floor)")
        for p in args.predictions:
            e = evaluate(args.bin, args.mesh, p)
            to_union = evaluate(args.bin, upath, p)
            print(f"  {p}: {100 * e['hausdorff']['hi'] / diag:.3f}% against the mesh; "
                  f"{100 * to_union['hausdorff']['hi'] / diag:.3f}% from the union (the solid's true boundary)")


if __name__ == "__main__":
    main()
