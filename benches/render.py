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
Lambert from a light above-left of the camera, plus ambient) and rasterized with a depth
buffer at 3x3 samples per pixel, averaged (no wireframe). A triangle covers the pixels
whose sample points it contains, so a sliver much thinner than a pixel shows as much as
its area: the painter's algorithm drawn before (a PolyCollection with edges in the face
colour) gave every sliver and step face of a crust a line at least a pixel wide, and
smooth crusts looked speckled. Faces seen from behind (back faces: open
meshes, inward-facing bodies, wrong orientation) are drawn in orange, so orientation
problems are visible. `--smooth file` instead shades a GLB by the NORMAL attribute it
carries, as a glTF viewer does (`voronoi-fit --normals`). Meshes of ~200k triangles take a few seconds per panel. Meshes are
read with trimesh (GLB scenes flattened with their node transforms).
"""
import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from quality_meshes import load_mesh  # noqa: E402

# azimuth (about the up axis) and elevation, degrees
VIEWS = {"front": (-30.0, 20.0), "side": (60.0, 20.0), "top": (-30.0, 75.0), "back": (150.0, 20.0), "bottom": (-30.0, -60.0)}
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


SS = 3  # samples per pixel along each axis


def glb_with_normals(path):
    """(V, F, per-corner normals) of a GLB as a viewer shades it: the file's own vertices
    (not welded) and its NORMAL attribute, or None when the file has no normals (flat).
    Read from the binary chunk directly: trimesh recomputes normals on load. For the GLBs
    voronoi-fit writes (triangle primitives, u32 indices, nodes without transforms)."""
    import json
    import struct

    data = Path(path).read_bytes()
    if data[:4] != b"glTF":
        return None
    (length,) = struct.unpack_from("<I", data, 12)
    j = json.loads(data[20:20 + length])
    binary = 20 + length + 8

    def accessor(i, dtype, width):
        a = j["accessors"][i]
        v = j["bufferViews"][a["bufferView"]]
        offset = binary + v.get("byteOffset", 0) + a.get("byteOffset", 0)
        return np.frombuffer(data, dtype=dtype, count=a["count"] * width, offset=offset).reshape(-1, width)

    prims = [p for m in j.get("meshes", []) for p in m["primitives"]]
    if not prims or not all("NORMAL" in p["attributes"] for p in prims):
        return None
    Vs, Fs, Ns, base = [], [], [], 0
    for p in prims:
        V = accessor(p["attributes"]["POSITION"], "<f4", 3).astype(float)
        Vs.append(V)
        Ns.append(accessor(p["attributes"]["NORMAL"], "<f4", 3).astype(float))
        Fs.append(accessor(p["indices"], "<u4", 1).reshape(-1, 3).astype(np.int64) + base)
        base += len(V)
    V, F, N = np.vstack(Vs), np.vstack(Fs), np.vstack(Ns)
    return V, F, N[F]


def draw(ax, V, F, R, center, scale, pixels=380, smooth=None):
    """One panel: orthographic, two-sided Lambert, depth buffer, SSxSS samples a pixel.
    Flat-shaded, or with `smooth` (per-corner normals, (len(F), 3, 3)) each pixel shaded by
    the corner normals interpolated, as a glTF viewer shades a mesh with normals."""
    ax.set_xlim(-1.02, 1.02)
    ax.set_ylim(-1.02, 1.02)
    ax.set_aspect("equal")
    ax.axis("off")
    n_px = pixels * SS
    img = np.ones((n_px, n_px, 3))
    if len(F):
        P = (V - center) @ R.T / scale  # the frame is [-1.02, 1.02]^2
        XY = (P[:, :2] + 1.02) / 2.04 * n_px
        Z = P[:, 2]
        tri = P[F]
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        ln = np.linalg.norm(n, axis=1)
        n = n / np.where(ln > 0, ln, 1)[:, None]
        back = n[:, 2] < 0  # facing away from the viewer
        shade = (0.28 + 0.72 * np.abs(n @ LIGHT))[:, None]
        colors = np.clip(np.where(back[:, None], BACK_COLOR, FRONT_COLOR) * shade, 0, 1)
        depth = np.full((n_px, n_px), -np.inf)
        corner = None
        if smooth is not None:
            corner = smooth @ R.T
        for fi, (f, col) in enumerate(zip(F, colors)):
            (ax_, ay), (bx, by), (cx, cy) = XY[f]
            x0, x1 = int(max(0, np.floor(min(ax_, bx, cx)))), int(min(n_px - 1, np.ceil(max(ax_, bx, cx))))
            y0, y1 = int(max(0, np.floor(min(ay, by, cy)))), int(min(n_px - 1, np.ceil(max(ay, by, cy))))
            if x1 < x0 or y1 < y0:
                continue
            d = (bx - ax_) * (cy - ay) - (cx - ax_) * (by - ay)
            if d == 0:
                continue
            xs, ys = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
            w1 = ((xs - ax_) * (cy - ay) - (cx - ax_) * (ys - ay)) / d
            w2 = ((bx - ax_) * (ys - ay) - (xs - ax_) * (by - ay)) / d
            w0 = 1 - w1 - w2
            inside = (w0 >= 0) & (w1 >= 0) & (w2 >= 0)
            if not inside.any():
                continue
            z = w0 * Z[f[0]] + w1 * Z[f[1]] + w2 * Z[f[2]]
            sub = depth[y0:y1 + 1, x0:x1 + 1]
            upd = inside & (z > sub)
            sub[upd] = z[upd]
            if corner is None:
                img[y0:y1 + 1, x0:x1 + 1][upd] = col
            else:
                cn = corner[fi]
                nn = w0[upd][:, None] * cn[0] + w1[upd][:, None] * cn[1] + w2[upd][:, None] * cn[2]
                nn /= np.maximum(np.linalg.norm(nn, axis=1), 1e-300)[:, None]
                base = BACK_COLOR if back[fi] else FRONT_COLOR
                img[y0:y1 + 1, x0:x1 + 1][upd] = np.clip(base * (0.28 + 0.72 * np.abs(nn @ LIGHT))[:, None], 0, 1)
    img = img.reshape(pixels, SS, pixels, SS, 3).mean(axis=(1, 3))
    ax.imshow(img, origin="lower", extent=(-1.02, 1.02, -1.02, 1.02), interpolation="nearest")


def render_columns(paths, labels, out, up="y", views=("front", "side", "top"), title=None, panel=3.4, dpi=110,
                   smooth=None):
    """Rows: views; columns: meshes (the first frames every panel)."""
    meshes = [load_mesh(p) for p in paths]
    smooth = list(smooth) if isinstance(smooth, list) else [smooth] * len(paths)
    for j, p in enumerate(paths):
        if smooth[j] == "file":  # as a glTF viewer shades the file: its normals, or flat
            got = glb_with_normals(p)
            smooth[j] = None if got is None else got[2]
            if got is not None:
                meshes[j] = (got[0], got[1])
    center, scale = frame_of(meshes[0][0])
    fig, axes = plt.subplots(len(views), len(meshes), figsize=(panel * len(meshes), panel * len(views)), squeeze=False)
    for i, v in enumerate(views):
        R = rotation(up, *VIEWS[v])
        for j, (V, F) in enumerate(meshes):
            ax = axes[i, j]
            draw(ax, V, F, R, center, scale, smooth=smooth[j])
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
    ap.add_argument("--smooth", help="per column, comma-separated: 'file' shades a GLB with its own NORMAL "
                    "attribute interpolated (flat when it has none), as a glTF viewer does; 'flat' (the default) "
                    "shades every triangle flat")
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
        smooth = None
        if a.smooth:
            smooth = [None if x == "flat" else x for x in a.smooth.split(",")]
            if any(x not in (None, "file") for x in smooth):
                ap.error("--smooth takes flat or file per column")
            smooth = smooth * len(a.meshes) if len(smooth) == 1 else smooth
        render_columns(a.meshes, labels, a.output, up=a.up,
                       views=tuple(a.views.split(",")) if a.views else ("front", "side", "top"), title=a.title,
                       smooth=smooth)
    print(a.output)


if __name__ == "__main__":
    main()
