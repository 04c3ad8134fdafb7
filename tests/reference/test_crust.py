"""The crust checked by trimesh and the Khronos validator, from sites files made with numpy."""
import numpy as np
import pytest
import trimesh

from conftest import assert_gltf_valid, run


def write_sites(path, sites, labels, transform=None):
    if transform is None:
        transform = np.diag([2.0, 2.0, 2.0, 1.0])
        transform[:3, 3] = [-1.0, 5.0, 0.25]
    np.savez(path, sites=np.asarray(sites, np.float64), labels=np.asarray(labels, np.uint8),
             transform=np.asarray(transform, np.float64), format_version=np.array([1], np.int64))


def lattice(n):
    g = (np.arange(n) + 0.5) / n
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)


rng = np.random.default_rng(20261122)
U = rng.uniform(0.0, 1.0, (3000, 3))
L = lattice(6)
CASES = {
    "uniform_ball": (U, np.linalg.norm(U - 0.5, axis=1) < 0.35),
    "uniform_random": (U[:1500], rng.uniform(size=1500) < 0.5),
    "lattice_checkerboard": (L, (np.floor(L * 6).astype(int).sum(1) % 2) == 0),
    "lattice_random": (L, rng.uniform(size=len(L)) < 0.5),
    "single_inside": (np.array([[0.3, 0.6, 0.5]]), np.array([1])),
}


@pytest.mark.parametrize("name", CASES)
def test_crust_is_watertight_in_trimesh_and_cells_sum_to_its_volume(bin_path, tmp_path, name):
    sites, labels = CASES[name]
    f = tmp_path / "s.npz"
    write_sites(f, sites, labels)
    run("crust", f, "-o", tmp_path / "crust.glb", "--cells", tmp_path / "cells.glb")
    run("crust", f, "-o", tmp_path / "crust.ply")
    assert_gltf_valid(tmp_path / "crust.glb")
    assert_gltf_valid(tmp_path / "cells.glb")
    crust = trimesh.load(str(tmp_path / "crust.ply"), process=False)
    assert crust.is_watertight and crust.is_winding_consistent
    assert crust.volume > 0
    # The transform scales by 2: volumes by 8.
    cells = trimesh.load(str(tmp_path / "cells.glb"), process=False)
    geoms = list(cells.geometry.values())
    assert len(geoms) == int(np.sum(np.asarray(labels) > 0)) or name.startswith("lattice")
    for g in geoms:
        assert g.is_watertight and g.is_winding_consistent and g.volume > 0
        # Convex: the hull adds no volume (f32 positions: trimesh's angle test is too strict).
        assert abs(g.convex_hull.volume - g.volume) <= 1e-5 * g.volume
    total = sum(g.volume for g in geoms)
    # Cells come through GLB (f32 positions): 1e-6 relative. The 1e-9 check on f64 is a
    # Rust test (crates/crust/tests/guarantees.rs).
    assert abs(total - crust.volume) <= 1e-6 * crust.volume, (total, crust.volume)
    glb = trimesh.load(str(tmp_path / "crust.glb"), process=False, force="mesh")
    assert len(glb.faces) == len(crust.faces)


def test_checkerboard_volume_is_half_the_box(bin_path, tmp_path):
    sites, labels = CASES["lattice_checkerboard"]
    write_sites(tmp_path / "s.npz", sites, labels, np.eye(4))
    run("crust", tmp_path / "s.npz", "-o", tmp_path / "c.ply")
    assert abs(trimesh.load(str(tmp_path / "c.ply"), process=False).volume - 0.5) < 1e-12


@pytest.mark.parametrize("broken", ["no_labels", "bad_shape", "label_2", "outside_box", "nan"])
def test_bad_sites_files_exit_2_without_output(bin_path, tmp_path, broken):
    s = rng.uniform(0.1, 0.9, (50, 3))
    lab = np.zeros(50, np.uint8)
    arrays = dict(sites=s, labels=lab, transform=np.eye(4), format_version=np.array([1], np.int64))
    if broken == "no_labels":
        del arrays["labels"]
    elif broken == "bad_shape":
        arrays["sites"] = s[:, :2].copy()
    elif broken == "label_2":
        lab[3] = 2
    elif broken == "outside_box":
        s[7] = [1.5, 0.5, 0.5]
    elif broken == "nan":
        s[9, 1] = np.nan
    f = tmp_path / "bad.npz"
    np.savez(f, **arrays)
    out = tmp_path / "out.glb"
    r = run("crust", f, "-o", out, check=False)
    assert r.returncode == 2, r.stderr
    assert str(f) in r.stderr
    assert not out.exists()


def test_a_mirroring_transform_keeps_the_crust_outward(bin_path, tmp_path):
    sites, labels = CASES["uniform_ball"]
    write_sites(tmp_path / "s.npz", sites, labels, np.diag([-1.0, 1.0, 1.0, 1.0]))
    run("crust", tmp_path / "s.npz", "-o", tmp_path / "c.ply")
    m = trimesh.load(str(tmp_path / "c.ply"), process=False)
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
