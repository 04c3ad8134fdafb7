#!/usr/bin/env python3
"""Render meshes to PNG with matplotlib (Agg, no display, no OpenGL): input and crust side
by side, from two or three views, so a reader can see the surface.

    target/bench-venv/bin/python benches/render.py INPUT.obj CRUST.glb -o OUT.png
    target/bench-venv/bin/python benches/render.py INPUT.obj A.glb B.obj C.obj -o OUT.png --labels input,ours,mc,qem
    target/bench-venv/bin/python benches/render.py --grid IN1.obj OUT1.glb IN2.obj OUT2.glb -o GRID.png

Rows are views (front, side, top by default: `--views`), columns are the meshes (the first
is the reference: every panel uses its bounding box for the framing, so panels line up
and anything far outside the input's box is cut off). `--grid` takes (input, crust) pairs
instead: one row per pair, columns input/crust for each view (`--views front,side` by
default). `--up y|z` names the mesh's up axis (default y; CAD/STL files are often z-up).

How: each view is an orthographic projection; triangles are flat-shaded (two-sided
Lambert from a light above-left of the camera, plus ambient) and drawn far-to-near
(painter's algorithm by centroid depth; triangles longer than 4% of the frame are split for
the ordering only) as one PolyCollection of 2D polygons per panel, with edges in the face
colour so no seams show (no wireframe). Faces seen from behind (back faces: open
meshes, inward-facing bodies, wrong orientation) are drawn in orange, so orientation
problems are visible. Meshes of ~200k triangles take a few seconds per panel. Meshes are
read with trimesh (GLB scenes flattened with their node transforms).
"""
import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from quality_meshes import load_mesh  # noqa: E402

# azimuth (about the up axis) and elevation, degrees
VIEWS = {"front": (-30.0, 20.0), "side": (60.0, 20.0), "top": (-30.0, 75.0), "back": (150.0, 20.0)}
FRONT_COLOR = np.array([0.70, 0.76, 0.86])
BACK_COLOR = np.array([0.95, 0.55, 0.20])
LIGHT = np.array([-0.45, 0.65, 1.0]) / np.linalg.norm([-0.45, 0.65, 1.0])  # camera space


def rotation(up, azimuth, elevation):
    """World -> camera (x right, y up, z toward the viewer)."""
    if up == "z":  # make z the up axis (+y), -y the viewing axis
        U = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])
    elif up == "x":
        U = np.array([[0, 0, 1.0], [1, 0, 0], [0, 1, 0]])
    else:
        U = np.eye(3)
    a, e = np.radians(azimuth), np.radians(elevation)
    Ry = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    Rx = np.array([[1, 0, 0], [0, np.cos(e), -np.sin(e)], [0, np.sin(e), np.cos(e)]])
    return Rx @ Ry @ U


def frame_of(V):
    lo, hi = V.min(0), V.max(0)
    return (lo + hi) / 2, max(np.linalg.norm(hi - lo) / 2, 1e-300)


def split_large(tri, max_edge, rounds=6):
    """Split triangles (k,3,3) with an edge longer than max_edge into four (midpoints), up to
    `rounds` times: the painter's algorithm orders by centroid depth, which misorders long
    triangles next to small ones (CAD inputs, big flat faces). Rendering only."""
    for _ in range(rounds):
        e = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(1)
        big = e > max_edge
        if not big.any():
            break
        t = tri[big]
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        sub = np.concatenate([np.stack(x, 1) for x in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
        tri = np.concatenate([tri[~big], sub])
    return tri


def draw(ax, V, F, R, center, scale):
    """One panel: orthographic, flat two-sided Lambert, painter's order."""
    ax.set_xlim(-1.02, 1.02)
    ax.set_ylim(-1.02, 1.02)
    ax.set_aspect("equal")
    ax.axis("off")
    if len(F) == 0:
        return
    P = (V - center) @ R.T / scale
    tri = split_large(P[F], 0.08)  # the frame is [-1, 1]^2
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    ln = np.linalg.norm(n, axis=1)
    n = n / np.where(ln > 0, ln, 1)[:, None]
    back = n[:, 2] < 0  # facing away from the viewer
    lam = np.abs(n @ LIGHT)  # two-sided
    shade = (0.28 + 0.72 * lam)[:, None]
    colors = np.where(back[:, None], BACK_COLOR, FRONT_COLOR) * shade
    colors = np.clip(colors, 0, 1)
    order = np.argsort(tri[:, :, 2].mean(1), kind="stable")  # far first
    pc = PolyCollection(tri[order][:, :, :2], facecolors=colors[order], edgecolors=colors[order],
                        linewidths=0.25, antialiaseds=False)
    ax.add_collection(pc)


def render_columns(paths, labels, out, up="y", views=("front", "side", "top"), title=None, panel=3.4, dpi=110):
    """Rows: views; columns: meshes (the first frames every panel)."""
    meshes = [load_mesh(p) for p in paths]
    center, scale = frame_of(meshes[0][0])
    fig, axes = plt.subplots(len(views), len(meshes), figsize=(panel * len(meshes), panel * len(views)), squeeze=False)
    for i, v in enumerate(views):
        R = rotation(up, *VIEWS[v])
        for j, (V, F) in enumerate(meshes):
            ax = axes[i, j]
            draw(ax, V, F, R, center, scale)
            if i == 0:
                ax.set_title(f"{labels[j]}\n{len(F):,} triangles", fontsize=10)
            if j == 0:
                ax.text(-1.0, -1.0, v, fontsize=9, color="0.4")
    if title:
        fig.suptitle(title, fontsize=12)
    fig.tight_layout()
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def render_grid(pairs, out, views=("front", "side"), panel=3.0, dpi=100):
    """pairs: [(input, crust, name, up)]; rows: pairs; columns: (input, crust) per view."""
    fig, axes = plt.subplots(len(pairs), 2 * len(views), figsize=(panel * 2 * len(views), panel * len(pairs)), squeeze=False)
    for i, (inp, crust, name, up) in enumerate(pairs):
        A, B = load_mesh(inp), load_mesh(crust)
        center, scale = frame_of(A[0])
        for k, v in enumerate(views):
            R = rotation(up, *VIEWS[v])
            for j, (M, lab) in enumerate(((A, "input"), (B, "crust"))):
                ax = axes[i, 2 * k + j]
                draw(ax, *M, R, center, scale)
                ax.set_title(f"{name}: {lab}, {v} ({len(M[1]):,} tri.)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes", nargs="+", help="INPUT CRUST [MORE...], or with --grid: IN1 OUT1 IN2 OUT2 ...")
    ap.add_argument("-o", "--output", required=True, help="PNG file")
    ap.add_argument("--labels", help="comma-separated column titles (default: file names)")
    ap.add_argument("--up", default="y", help="up axis: y or z (with --grid: one, or one per pair, comma-separated)")
    ap.add_argument("--views", help="comma-separated of " + ", ".join(VIEWS))
    ap.add_argument("--title")
    ap.add_argument("--grid", action="store_true", help="(input, crust) pairs, one row each")
    a = ap.parse_args()
    if a.grid:
        if len(a.meshes) % 2:
            ap.error("--grid takes pairs of meshes")
        ps = list(zip(a.meshes[::2], a.meshes[1::2]))
        ups = a.up.split(",")
        ups = ups * len(ps) if len(ups) == 1 else ups
        pairs = [(i, c, Path(i).stem, u) for (i, c), u in zip(ps, ups)]
        render_grid(pairs, a.output, views=tuple(a.views.split(",")) if a.views else ("front", "side"))
    else:
        if len(a.meshes) < 1:
            ap.error("give at least one mesh")
        labels = a.labels.split(",") if a.labels else [Path(p).name for p in a.meshes]
        render_columns(a.meshes, labels, a.output, up=a.up,
                       views=tuple(a.views.split(",")) if a.views else ("front", "side", "top"), title=a.title)
    print(a.output)


if __name__ == "__main__":
    main()
