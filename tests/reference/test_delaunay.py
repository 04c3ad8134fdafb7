"""Reference check of `voronoi-fit delaunay` against scipy.spatial.Delaunay (Qhull).

For points in general position the Delaunay tetrahedralization is unique, so the tet
sets must be identical (after sorting each tet's indices), not only the counts. Also
checks the CLI contract: input indices, positive orientation, duplicates mapped to
their first input index, and exit code 2 with no output file on bad input.
"""
import numpy as np
import pytest
from scipy.spatial import Delaunay

from conftest import run


def tets_of(points, tmp_path, *extra):
    src = tmp_path / "points.npy"
    out = tmp_path / "tets.npy"
    np.save(src, points)
    run("delaunay", src, "-o", out, "--validate", *extra)
    tets = np.load(out)
    assert tets.dtype == np.uint32 and tets.ndim == 2 and tets.shape[1] == 4
    return tets.astype(np.int64)


def signed_volumes6(points, tets):
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))


def canonical(tets):
    t = np.sort(np.asarray(tets, dtype=np.int64), axis=1)
    return t[np.lexsort(t.T[::-1])]


@pytest.mark.parametrize("n,seed", [(10, 0), (1_000, 1), (20_000, 2), (200_000, 3)])
def test_uniform_matches_scipy(n, seed, tmp_path):
    points = np.random.default_rng(seed).random((n, 3))
    ours = tets_of(points, tmp_path)
    ref = Delaunay(points).simplices
    assert len(ours) == len(ref)
    np.testing.assert_array_equal(canonical(ours), canonical(ref))
    assert (signed_volumes6(points, ours) > 0).all()
    # The tets tile the convex hull: volumes sum to the hull volume.
    hull_volume = np.abs(signed_volumes6(points, ref)).sum()
    assert np.isclose(signed_volumes6(points, ours).sum(), hull_volume, rtol=1e-12)


def test_gaussian_and_float32_input(tmp_path):
    points = np.random.default_rng(7).standard_normal((5_000, 3)).astype(np.float32)
    ours = tets_of(points, tmp_path)
    ref = Delaunay(points.astype(np.float64)).simplices
    np.testing.assert_array_equal(canonical(ours), canonical(ref))


def test_lattice_volume_and_orientation(tmp_path):
    # Degenerate: the triangulation is not unique, so compare what is invariant.
    g = np.arange(12, dtype=np.float64)
    points = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    ours = tets_of(points, tmp_path)
    vol = signed_volumes6(points, ours)
    assert (vol > 0).all()
    assert vol.sum() == 6 * 11**3


def test_duplicates_map_to_first_input_index(tmp_path):
    rng = np.random.default_rng(5)
    base = rng.random((500, 3))
    points = np.concatenate([base, base[::-1], base[:10]])
    ours = tets_of(points, tmp_path)
    assert ours.max() < 500  # representatives are the first occurrences
    np.testing.assert_array_equal(canonical(ours), canonical(Delaunay(base).simplices))


def test_extreme_scales(tmp_path):
    points = np.random.default_rng(9).random((2_000, 3))
    ref = canonical(Delaunay(points).simplices)
    for s in (2.0**-500, 2.0**500):  # exact power-of-two scalings keep the same set
        np.testing.assert_array_equal(canonical(tets_of(points * s, tmp_path)), ref)


@pytest.mark.parametrize(
    "content,needle",
    [
        (b"not an npy file", "npy"),
        (None, "shape"),  # wrong shape
        ("nan", "not finite"),
        ("coplanar", "affinely independent"),
    ],
)
def test_bad_input_exit_2_no_output(content, needle, tmp_path):
    src = tmp_path / "bad.npy"
    if content is None:
        np.save(src, np.zeros((10, 2)))
    elif content == "nan":
        p = np.random.default_rng(1).random((10, 3))
        p[4, 1] = np.nan
        np.save(src, p)
    elif content == "coplanar":
        p = np.random.default_rng(1).random((10, 3))
        p[:, 2] = 1.0
        np.save(src, p)
    else:
        src.write_bytes(content)
    out = tmp_path / "out.npy"
    r = run("delaunay", src, "-o", out, check=False)
    assert r.returncode == 2, r.stderr
    assert str(src) in r.stderr and needle in r.stderr, r.stderr
    assert r.stderr.strip().count("\n") == 0  # one paragraph
    assert not out.exists()
