"""Marching cubes of the `baselines` crate against scikit-image.

The Rust side is the crate's example binary `mc` (built by `cargo test --workspace
--profile ci` into target/ci/examples/mc; `VF_MC_BIN` overrides the path):

    mc GRID.npy OUT.npz [LEVEL] [decider|separate|join] [above|below]

Two comparisons, with vertices identified by their float32 coordinates (skimage's output
type; grids are float32-representable, as skimage converts to float32):

- Triangle sets: every non-degenerate triangle as its three vertices, rotated to start at the
  smallest (orientation kept), compared as multisets. Equal sets mean Hausdorff distance 0.
  Degenerate triangles (two corners at one point, which skimage keeps and the crate drops)
  are left out.
- Per cell (where triangle sets differ): the polygon(s) bounding the cell's triangles and the
  Euler characteristic of the cell's triangles (disc or tube), which do not depend on how a
  polygon is triangulated.

Results:
- `Ambiguity::SeparateAbove` ("separate") vs `method="lorensen"`: identical triangle sets on
  every grid: SDFs, uniform noise (all 254 cases), a ReLU decoder's values, and values
  exactly on the level.
- The default (asymptotic decider on faces, exact interior test) vs the default
  `method="lewiner"`: identical triangle sets on smooth fields (sphere, torus), and on noise
  and decoder grids in every cell without an ambiguous face or body diagonal. In ambiguous cells Lewiner's
  tables triangulate differently (some with a centre vertex), a few cells in 10,000 have
  other face polygons, and about 0.8% another interior (tube vs two discs), where the
  crate's choice is checked against the sampled trilinear interpolant
  (`test_lewiner_noise`).
- Orientation: the crate's `Inside::Below` gives skimage's default (`descent`) triangles,
  `Inside::Above` its `gradient_direction="ascent"` ones.
"""
import collections
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conftest import BIN, ROOT

from skimage.measure import marching_cubes  # noqa: E402

MC = Path(os.environ.get("VF_MC_BIN", BIN.parent / "examples" / "mc"))


@pytest.fixture(scope="module")
def mc_bin():
    assert MC.exists(), f"{MC} is missing: build with cargo test --workspace --profile ci (or set VF_MC_BIN)"
    return MC


def rust_mc(mc_bin, tmp_path, grid, level=0.0, ambiguity="decider", inside="below"):
    g = tmp_path / "grid.npy"
    out = tmp_path / "mesh.npz"
    np.save(g, np.asarray(grid, dtype=np.float64))
    r = subprocess.run([str(mc_bin), str(g), str(out), repr(float(level)), ambiguity, inside], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    z = np.load(out)
    return z["verts"], z["faces"].astype(np.int64)


def cell_signatures(meshes):
    """For each mesh, {cell: (directed boundary edges, Euler characteristic)} of the
    triangles in each grid cell (cell = floor of the triangle's centroid), with vertices
    identified across the meshes by their float32 coordinates. Degenerate triangles (two
    corners at the same point; skimage keeps them, the crate drops them) are skipped."""
    v32 = [np.asarray(v, dtype=np.float32) for v, _ in meshes]
    _, ids = np.unique(np.concatenate(v32), axis=0, return_inverse=True)
    ids = ids.ravel()
    out, off = [], 0
    for v, (_, faces) in zip(v32, meshes):
        t = ids[off:off + len(v)][faces]
        off += len(v)
        ok = (t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])
        t, f = t[ok], faces[ok]
        cell = np.floor(v[f].astype(np.float64).mean(axis=1)).astype(np.int64)
        sig = collections.defaultdict(lambda: [collections.Counter(), set(), set(), 0])
        for c, tri in zip(map(tuple, cell), t.tolist()):
            e = sig[c]
            e[3] += 1
            for q in range(3):
                a, b = tri[q], tri[(q + 1) % 3]
                e[0][(a, b)] += 1
                e[1].add((min(a, b), max(a, b)))
                e[2].add(a)
        cells = {}
        for c, (directed, undirected, verts, nf) in sig.items():
            boundary = frozenset((k, n - directed.get((k[1], k[0]), 0)) for k, n in directed.items() if n > directed.get((k[1], k[0]), 0))
            cells[c] = (boundary, len(verts) - len(undirected) + nf)
        out.append(cells)
    return out


def canonical_triangles(verts, faces):
    """(m, 9) float32 rows: the non-degenerate triangles' vertices, each triangle rotated to
    start at its lexicographically smallest vertex (orientation kept)."""
    p = np.asarray(verts, dtype=np.float32)[np.asarray(faces, dtype=np.int64)]  # (m, 3, 3)
    same = lambda i, j: (p[:, i] == p[:, j]).all(axis=1)
    p = p[~(same(0, 1) | same(1, 2) | same(0, 2))]

    def less(i, j):  # vertex i < vertex j lexicographically
        a, b = p[:, i], p[:, j]
        return (a[:, 0] < b[:, 0]) | ((a[:, 0] == b[:, 0]) & ((a[:, 1] < b[:, 1]) | ((a[:, 1] == b[:, 1]) & (a[:, 2] < b[:, 2]))))

    first = np.where(less(0, 1) & less(0, 2), 0, np.where(less(1, 2), 1, 2))
    order = (first[:, None] + np.arange(3)[None, :]) % 3
    return p[np.arange(len(p))[:, None], order].reshape(-1, 9)


def row_keys(rows):
    """Hashable keys of the rows of a 2-D array."""
    rows = np.ascontiguousarray(rows)
    return rows.view(np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))).ravel().tolist()


def triangle_set(verts, faces):
    """Multiset of canonical triangles (see `canonical_triangles`)."""
    return collections.Counter(row_keys(canonical_triangles(verts, faces)))


def cell_triangle_sets(verts, faces, shape):
    """{cell: triangle multiset} with cell = floor of the triangle's centroid (clipped to the
    grid's cells)."""
    t = canonical_triangles(verts, faces)
    cells = np.floor(t.reshape(-1, 3, 3).astype(np.float64).mean(axis=1)).astype(np.int64)
    cells = np.clip(cells, 0, np.array(shape) - 2)
    out = collections.defaultdict(collections.Counter)
    for c, k in zip(map(tuple, cells.tolist()), row_keys(t)):
        out[c][k] += 1
    return out


def triangle_difference(a, b):
    """Triangles in one multiset and not the other (counted with multiplicity), and the
    number in the first."""
    a, b = triangle_set(*a), triangle_set(*b)
    return (a - b) + (b - a), sum(a.values())


def cell_masks(grid):
    """Corner-above mask (corner c at offset (c & 1, c >> 1 & 1, c >> 2)) of every cell."""
    g = np.asarray(grid) > 0
    n0, n1, n2 = g.shape
    m = np.zeros((n0 - 1, n1 - 1, n2 - 1), dtype=np.int64)
    for c in range(8):
        i, j, k = c & 1, (c >> 1) & 1, c >> 2
        m |= g[i:n0 - 1 + i, j:n1 - 1 + j, k:n2 - 1 + k].astype(np.int64) << c
    return m


# Cube faces as corner cycles (corner bits as in `cell_masks`).
FACES = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]]


def ambiguous(mask):
    """A face with diagonal above and below corners, or two corners of one sign at the ends
    of a body diagonal and the other six of the other (case 4's interior ambiguity)."""
    for f in FACES:
        s = [(mask >> c) & 1 for c in f]
        if s[0] == s[2] and s[1] == s[3] and s[0] != s[1]:
            return True
    return mask in (0b10000001, 0b01000010, 0b00100100, 0b00011000) or 255 - mask in (
        0b10000001, 0b01000010, 0b00100100, 0b00011000)


def edge_vertices(verts):
    """Vertices on grid edges (two integer coordinates), as float32 tuples."""
    v32 = np.asarray(verts, dtype=np.float32)
    on_edge = (v32 == np.round(v32)).sum(axis=1) >= 2
    return set(map(tuple, v32[on_edge].tolist()))


def compare(mc_bin, tmp_path, grid, level, method, ambiguity):
    g32 = np.asarray(grid, dtype=np.float32)
    sv, sf, _, _ = marching_cubes(g32, level, method=method)
    rv, rf = rust_mc(mc_bin, tmp_path, g32.astype(np.float64), level, ambiguity, "below")
    cs, cr = cell_signatures([(sv, sf), (rv, rf)])
    differing = sorted(c for c in set(cs) | set(cr) if cs.get(c) != cr.get(c))
    return dict(cells=len(cs), differing=differing, vertex_mismatch=len(edge_vertices(sv) ^ edge_vertices(rv)),
                skimage=(sv, sf), rust=(rv, rf))


def grid_points(n):
    x = np.linspace(0.0, 1.0, n)
    return np.meshgrid(x, x, x, indexing="ij")


def sphere(n):
    X, Y, Z = grid_points(n)
    return np.sqrt((X - 0.5) ** 2 + (Y - 0.47) ** 2 + (Z - 0.52) ** 2) - 0.31


def torus(n):
    X, Y, Z = grid_points(n)
    q = np.sqrt((X - 0.5) ** 2 + (Y - 0.5) ** 2) - 0.28
    return np.sqrt(q**2 + (Z - 0.5) ** 2) - 0.11


def noise(n, seed, pad=False):
    g = np.random.default_rng(seed).uniform(-1.0, 1.0, (n, n, n))
    if pad:
        g[0], g[-1], g[:, 0], g[:, -1], g[:, :, 0], g[:, :, -1] = (1.0,) * 6
    return g


def integer_noise(n, seed):
    """Values in {-2, ..., 2}: levels -1, 0, 1 hit grid values exactly."""
    return np.random.default_rng(seed).integers(-2, 3, (n, n, n)).astype(np.float64)


SMOOTH = [(f"{name}{n}", f, n) for n in (16, 33, 64) for name, f in (("sphere", sphere), ("torus", torus))]


@pytest.mark.parametrize("name,f,n", SMOOTH, ids=[s[0] for s in SMOOTH])
@pytest.mark.parametrize("method,ambiguity", [("lewiner", "decider"), ("lorensen", "separate")])
def test_smooth_fields_identical(mc_bin, tmp_path, name, f, n, method, ambiguity):
    r = compare(mc_bin, tmp_path, f(n), 0.0, method, ambiguity)
    assert r["cells"] > 0
    assert r["vertex_mismatch"] == 0
    assert r["differing"] == [], f"{name} {method}: {len(r['differing'])} of {r['cells']} cells differ"
    diff, total = triangle_difference(r["skimage"], r["rust"])
    assert total > 0
    assert sum(diff.values()) == 0, f"{name} {method}: {sum(diff.values())} of {total} triangles differ"


NOISE = [(16, 1), (33, 2), (48, 3)]


@pytest.mark.parametrize("n,seed", NOISE)
def test_lorensen_noise_identical(mc_bin, tmp_path, n, seed):
    """Every case of the classic table at once: the same triangles as `method="lorensen"`."""
    for pad in (False, True):
        g = noise(n, seed, pad)
        if n >= 33:
            assert len(set(cell_masks(g.astype(np.float32)).ravel().tolist()) - {0, 255}) == 254
        r = compare(mc_bin, tmp_path, g, 0.0, "lorensen", "separate")
        assert r["vertex_mismatch"] == 0
        assert r["differing"] == [], f"{len(r['differing'])} of {r['cells']} cells differ: {r['differing'][:5]}"
        diff, total = triangle_difference(r["skimage"], r["rust"])
        assert sum(diff.values()) == 0, f"{sum(diff.values())} of {total} triangles differ"


def relu_decoder_field(n, seed, width=64, depth=3):
    """An OccNet-shaped decoder's values on the n³ grid of [-1, 1]³ (float32): a ReLU MLP
    3→width×depth→1 with PyTorch's default uniform initialisation, shifted so that half the
    grid is above 0. Piecewise linear, like every ReLU decoder's logit field."""
    rng = np.random.default_rng(seed)
    x = np.linspace(-1.0, 1.0, n)
    h = np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1).reshape(-1, 3)
    dims = [3] + [width] * depth
    for i, o in zip(dims[:-1], dims[1:]):
        b = 1 / np.sqrt(i)
        h = np.maximum(h @ rng.uniform(-b, b, (i, o)) + rng.uniform(-b, b, o), 0.0)
    b = 1 / np.sqrt(width)
    f = (h @ rng.uniform(-b, b, (width, 1)) + rng.uniform(-b, b, 1)).reshape(n, n, n).astype(np.float32)
    return f - np.median(f)


@pytest.mark.parametrize("seed", [7, 8])
def test_decoder_grid(mc_bin, tmp_path, seed):
    """The issue's case, a grid of decoder values (64³): `lorensen` triangle for triangle;
    `lewiner` the same except in a few ambiguous cells."""
    g = relu_decoder_field(64, seed)
    r = compare(mc_bin, tmp_path, g, 0.0, "lorensen", "separate")
    diff, total = triangle_difference(r["skimage"], r["rust"])
    assert total > 10_000 and sum(diff.values()) == 0, f"{sum(diff.values())} of {total} triangles differ"
    r = compare(mc_bin, tmp_path, g, 0.0, "lewiner", "decider")
    masks = cell_masks(g)
    ts, tr = (cell_triangle_sets(*m, g.shape) for m in (r["skimage"], r["rust"]))
    tri_differ = [c for c in set(ts) | set(tr) if ts.get(c) != tr.get(c)]
    assert all(ambiguous(int(masks[c])) for c in tri_differ), tri_differ[:5]
    assert len(tri_differ) < 1e-3 * len(ts)


def trilinear_components(vals, s=48):
    """(components of {f > 0}, components of {f <= 0}) of the trilinear interpolant of one
    cell's corner values (corner c at (c & 1, c >> 1 & 1, c >> 2)), sampled on s³ points."""
    from scipy import ndimage

    t = np.linspace(0.0, 1.0, s)
    X, Y, Z = np.meshgrid(t, t, t, indexing="ij")
    f = 0.0
    for c in range(8):
        bx, by, bz = c & 1, (c >> 1) & 1, c >> 2
        f = f + vals[c] * (X if bx else 1 - X) * (Y if by else 1 - Y) * (Z if bz else 1 - Z)
    return ndimage.label(f > 0)[1], ndimage.label(f <= 0)[1]


@pytest.mark.parametrize("n,seed", NOISE)
def test_lewiner_noise(mc_bin, tmp_path, n, seed):
    """Asymptotic decider + interior test vs Lewiner on noise: the same vertices; the same
    face polygons in all but a few cells in 10,000 (faces where skimage's Lewiner tables do
    not follow the asymptotic decider; 26 of 102,192 cells at 48³); and in about 0.8% of
    cells one of the two makes a tube (Euler characteristic 0) where the other makes two
    discs (2). In every such cell checked, the crate's choice is the topology of the
    trilinear interpolant (sampled on 48³ points per cell: a tube iff both signs form one
    component; the crate's sweep is exact, so a tube neck thinner than the sampling could
    fail this check — one such cell exists among the 848 at 48³, not among those checked).
    Triangles: identical in every cell that has no ambiguous face or body diagonal; in
    ambiguous cells Lewiner's tiling tables split some polygons differently or around a
    centre vertex. Both meshes closed."""
    import trimesh

    g = noise(n, seed, pad=True)
    r = compare(mc_bin, tmp_path, g, 0.0, "lewiner", "decider")
    assert r["vertex_mismatch"] == 0
    masks = cell_masks(g.astype(np.float32))
    ts, tr = (cell_triangle_sets(*m, g.shape) for m in (r["skimage"], r["rust"]))
    tri_differ = [c for c in set(ts) | set(tr) if ts.get(c) != tr.get(c)]
    unambiguous = [c for c in tri_differ if not ambiguous(int(masks[c]))]
    print(f"noise {n}³: triangles differ in {len(tri_differ)} of {len(set(ts) | set(tr))} cells, "
          f"{len(unambiguous)} of them unambiguous")
    assert tri_differ, "noise has ambiguous cells that Lewiner tiles its own way"
    assert unambiguous == [], unambiguous[:5]
    cs, cr = cell_signatures([r["skimage"], r["rust"]])
    faces_differ = [c for c in r["differing"] if cs.get(c, (None, 0))[0] != cr.get(c, (None, 0))[0]]
    interior = [c for c in r["differing"] if c not in faces_differ]
    print(f"noise {n}³: {r['cells']} cells, {len(faces_differ)} with other face polygons, {len(interior)} other interiors")
    assert len(faces_differ) < 1e-3 * r["cells"]
    assert len(interior) < 2e-2 * r["cells"]
    g32 = g.astype(np.float32).astype(np.float64)
    for c in interior[:150]:
        assert {cs[c][1], cr[c][1]} == {0, 2}
        vals = [g32[c[0] + (k & 1), c[1] + ((k >> 1) & 1), c[2] + (k >> 2)] for k in range(8)]
        npos, nneg = trilinear_components(vals)
        assert (cr[c][1] == 0) == (npos == 1 and nneg == 1), (c, vals, npos, nneg, cr[c][1])
    for v, f in (r["rust"], r["skimage"]):
        assert trimesh.Trimesh(v, f, process=True).is_watertight


@pytest.mark.parametrize("level", [-1.0, 0.0, 1.0])
def test_exact_level_values(mc_bin, tmp_path, level):
    """Grid values equal to the level count as below (skimage's `> level`). skimage puts the
    vertices of the crossed edges at such a point within float32 rounding of it (and keeps
    the degenerate triangles), the crate exactly on it (one shared vertex, degenerate
    triangles dropped): the same crossing vertices; the crate's mesh stays closed (every
    directed edge paired). Against `lorensen` the non-degenerate triangles are identical.
    Cell by cell comparison is not meaningful here: triangles that collapse into a cell face
    have no well-defined cell."""
    g = integer_noise(20, 5)
    g[0], g[-1], g[:, 0], g[:, -1], g[:, :, 0], g[:, :, -1] = (-3.0,) * 6
    for method, ambiguity in (("lorensen", "separate"), ("lewiner", "decider")):
        sv, sf, _, _ = marching_cubes(g.astype(np.float32), level, method=method)
        rv, rf = rust_mc(mc_bin, tmp_path, g, level, ambiguity, "below")

        def on_edges(v):
            v = np.round(np.asarray(v, dtype=np.float64), 5)
            return set(map(tuple, v[(v == np.round(v)).sum(axis=1) >= 2].tolist()))

        if method == "lorensen":
            assert on_edges(sv) == on_edges(rv)
            diff, total = triangle_difference((sv, sf), (rv, rf))
            assert total > 0 and sum(diff.values()) == 0, f"{sum(diff.values())} of {total} triangles differ"
        else:
            # Lewiner's cell-centre vertices collapse onto grid points and edges next to
            # on-level values, so skimage has more.
            assert on_edges(rv) <= on_edges(sv)
        directed = collections.Counter((a, b) for t in rf.tolist() for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])))
        assert all(directed[(b, a)] == n for (a, b), n in directed.items())


def test_orientation_convention(mc_bin, tmp_path):
    """`below` = skimage's default; `above` = skimage's gradient_direction="ascent"."""
    g = sphere(24).astype(np.float32)
    sv, sf, _, _ = marching_cubes(g, 0.0, method="lorensen", gradient_direction="ascent")
    rv, rf = rust_mc(mc_bin, tmp_path, g, 0.0, "separate", "above")
    cs, cr = cell_signatures([(sv, sf), (rv, rf)])
    assert cs == cr
