"""The topology report against trimesh, and every GLB/glTF the CLI writes against the
Khronos validator, for every mesh of the corpus."""
import os
from pathlib import Path

import numpy as np
import pytest
import trimesh

from conftest import assert_gltf_valid, corpus, info, run


def trimesh_exact(path):
    """Load with trimesh without its processing, weld exactly coincident positions (as
    voronoi-fit does) and drop unreferenced vertices."""
    m = trimesh.load(str(path), process=False, force="mesh")
    v = np.asarray(m.vertices, dtype=np.float64)
    v = np.where(v == 0.0, 0.0, v)  # -0.0 and 0.0 weld
    uniq, inverse = np.unique(v, axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[np.asarray(m.faces)]
    t = trimesh.Trimesh(uniq, faces, process=False)
    t.remove_unreferenced_vertices()
    return t


@pytest.mark.parametrize("path", corpus(), ids=lambda p: p.name)
def test_report_agrees_with_trimesh(bin_path, path):
    r = info(path)
    t = trimesh_exact(path)
    assert r["num_faces"] == len(t.faces)
    assert r["num_referenced_vertices"] == len(t.vertices)
    assert r["is_closed"] == t.is_watertight
    assert r["is_orientation_consistent"] == t.is_winding_consistent
    assert r["euler_characteristic"] == t.euler_number
    assert r["num_components"] == t.body_count
    # Volume: trimesh's value where it is defined (closed, consistently oriented); for open
    # or inconsistently wound meshes trimesh integrates x·n_x only, which depends on the
    # axis, so there the check is against the origin-referenced determinant sum in numpy.
    tri = np.asarray(t.triangles, dtype=np.float64)
    det_sum = float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)
    scale = float(np.ptp(t.vertices, axis=0).max()) ** 3
    tol = lambda ref: 1e-9 * max(abs(ref), 1e-6 * scale)
    assert abs(r["signed_volume"] - det_sum) <= tol(det_sum), (r["signed_volume"], det_sum)
    if t.is_watertight and t.is_winding_consistent:
        vol = t.volume
        assert abs(r["signed_volume"] - vol) <= tol(vol), (r["signed_volume"], vol)
    assert np.allclose(r["bbox_min"], t.bounds[0], rtol=0, atol=0)
    assert np.allclose(r["bbox_max"], t.bounds[1], rtol=0, atol=0)


@pytest.mark.parametrize("path", corpus(), ids=lambda p: p.name)
@pytest.mark.parametrize("ext", [".glb", ".gltf"])
def test_written_gltf_is_valid_and_reads_back(bin_path, tmp_path, path, ext):
    out = tmp_path / f"out{ext}"
    run("convert", path, "-o", out)
    assert_gltf_valid(out)
    # The source as voronoi-fit triangulates it (quads and polygons as fans), through the
    # lossless binary PLY writer, read by trimesh.
    src_ply = tmp_path / "src.ply"
    run("convert", path, "-o", src_ply)
    src = trimesh.load(str(src_ply), process=False)
    assert len(src.faces) == len(trimesh_exact(path).faces)
    back = trimesh.load(str(out), process=False, force="mesh")
    assert len(back.faces) == len(src.faces)
    # Same triangles, as sets of f32-rounded corner positions.
    def tri_set(m):
        tris = np.asarray(m.vertices, dtype=np.float32)[np.asarray(m.faces)]
        return sorted(map(lambda t: tuple(t.ravel().tolist()), tris))
    assert tri_set(back) == tri_set(src)


@pytest.mark.parametrize("path", corpus()[:3], ids=lambda p: p.name)
def test_normalized_output_fits_the_unit_cube(bin_path, tmp_path, path):
    out = tmp_path / "n.ply"
    run("convert", path, "-o", out, "--normalize", "--margin", "0.1")
    m = trimesh.load(str(out), process=False)
    lo, hi = m.bounds
    assert lo.min() >= 0.1 - 1e-12 and hi.max() <= 0.9 + 1e-12
    assert abs(np.ptp(m.vertices, axis=0).max() - 0.8) < 1e-12


def glbs_written_by_rust_tests():
    d = os.environ.get("VF_GLB_OUT")
    return sorted(p for p in Path(d).rglob("*") if p.suffix in (".glb", ".gltf")) if d else []


def test_rust_tests_left_gltf_files_to_validate():
    if "VF_GLB_OUT" not in os.environ:
        pytest.skip("run through tests/run.sh, which sets VF_GLB_OUT for cargo test")
    assert len(glbs_written_by_rust_tests()) >= 3


@pytest.mark.parametrize("path", glbs_written_by_rust_tests(), ids=lambda p: p.name)
def test_gltf_written_by_rust_tests_is_valid(path):
    assert_gltf_valid(path)
