"""The Python package (`import voronoi_fit`, built by tests/run.sh with maturin into the
test venv) against the CLI's own outputs and against libigl / scipy:

- `fit` gives bit for bit the sites and crust that `voronoi-fit MESH -o OUT.obj` writes
  with the same options, and the same report figures; trimesh objects, (V, F) pairs and
  paths give the same result;
- `crust` of the fit's sites is the fit's crust; of the sites in the mesh frame, a closed
  mesh of the same volume;
- `winding_number` (exact: 1e-9; fast: 1e-3 and no flips) and `signed_distance` against
  `igl.winding_number` / `igl.point_mesh_squared_distance`; `delaunay` against
  scipy.spatial.Delaunay; `hausdorff` and `evaluate` against `voronoi-fit eval` and
  `igl.hausdorff`;
- errors are `InputError` (a ValueError) with the CLI's message; an exception in the
  progress callback stops the fit and is raised; the GIL is released during a fit.
"""
import json
import threading
from pathlib import Path
import time

import igl
import numpy as np
import pytest
import trimesh
from scipy.spatial import Delaunay, cKDTree

import voronoi_fit as vf

from conftest import ROOT, SHARED, assert_gltf_valid, run

BUNNY = ROOT / "assets" / "bunny.obj"
SMALL = dict(sites=512, steps=30, samples=20000, eval_samples=2000, polish_steps=100)
SMALL_CLI = ["--sites", "512", "--steps", "30", "--samples", "20000", "--eval-samples", "2000", "--polish-steps", "100"]


@pytest.fixture(scope="module")
def bunny():
    return vf.load_mesh(BUNNY)


@pytest.fixture(scope="module")
def fitted(bunny):
    # float64, to compare with the CLI's lossless .obj output.
    return vf.fit(bunny, name=str(BUNNY), progress=False, float32=False, **SMALL)


def test_fit_equals_the_cli(fitted, tmp_path):
    out = tmp_path / "b.obj"
    run(BUNNY, "-o", out, "--quiet", *SMALL_CLI)
    sites = np.load(tmp_path / "b.sites.npz")
    assert np.array_equal(sites["sites"], fitted.sites_unit)
    assert np.array_equal(sites["labels"].astype(bool), fitted.labels)
    V, F = vf.load_mesh(out)
    assert V.shape == fitted.crust_vertices.shape and np.array_equal(F, fitted.crust_faces)
    assert np.array_equal(V, fitted.crust_vertices), "the CLI's OBJ holds the same float64 crust"
    report = json.loads((tmp_path / "b.report.json").read_text())
    for path in (["metrics", "hausdorff", "hi"], ["metrics", "surface", "chamfer_l1"], ["quality", "misclassification"]):
        a, b = report, fitted.report
        for k in path:
            a, b = a[k], b[k]
        assert a == b, path
    assert fitted.report["settings"]["train"]["num_sites"] == 512
    assert "Hausdorff" in fitted.summary()


def test_inputs_as_trimesh_path_and_arrays_agree(bunny, fitted):
    tm = trimesh.Trimesh(bunny[0], bunny[1], process=False)
    by_trimesh = vf.fit(tm, progress=False, float32=False, **SMALL)
    by_path = vf.fit(BUNNY, progress=False, float32=False, **SMALL)
    by_arrays = vf.fit(bunny[0], bunny[1], progress=False, float32=False, **SMALL)
    for r in (by_trimesh, by_path, by_arrays):
        assert np.array_equal(r.crust_vertices, fitted.crust_vertices)
        assert np.array_equal(r.sites, fitted.sites)
    assert by_path.report["input"]["path"] == str(BUNNY)
    assert isinstance(by_trimesh.to_trimesh(), trimesh.Trimesh)


def test_crust_of_the_fit_sites(fitted):
    V, F = vf.crust(fitted.sites_unit, fitted.labels, fitted.transform)
    # The fit maps its crust by the sites file's own matrix: the same crust to the bit
    # (mapped by centre and scale instead, a merge of vertices a few float steps apart
    # once went the other way: 4,032 triangles against the fit's 4,030).
    assert np.array_equal(F, fitted.crust_faces)
    assert np.array_equal(V, fitted.crust_vertices)
    # In the mesh frame, without a transform: the same diagram up to rounding, closed.
    V2, F2 = vf.crust(fitted.sites, fitted.labels)
    m, m2 = trimesh.Trimesh(V, F, process=False), trimesh.Trimesh(V2, F2, process=False)
    assert m2.is_watertight and m2.is_winding_consistent
    assert abs(m2.volume - m.volume) <= 1e-6 * abs(m.volume)


def test_pruning_changes_neither_the_crust_nor_the_occupancy(bunny, fitted):
    # The same fit keeping every site: the sites removed last had only neighbours of their
    # own label, so the crust (as a surface: volume, area) and the nearest-site labels
    # (scipy's k-d tree) are the same.
    full = vf.fit(bunny, progress=False, float32=False, prune=False, **SMALL)
    assert full.report["pruning"] is None
    pruning = fitted.report["pruning"]
    assert len(fitted.sites) == pruning["sites_after"] < pruning["sites_before"] == len(full.sites)
    m = trimesh.Trimesh(fitted.crust_vertices, fitted.crust_faces, process=False)
    m_full = trimesh.Trimesh(full.crust_vertices, full.crust_faces, process=False)
    assert abs(m.volume - m_full.volume) <= 1e-9 * abs(m_full.volume)
    assert abs(m.area - m_full.area) <= 1e-9 * m_full.area
    rng = np.random.default_rng(3)
    points = rng.random((200_000, 3))
    near = np.repeat(full.sites_unit, 4, axis=0) + rng.normal(scale=0.01, size=(4 * len(full.sites_unit), 3))
    points = np.vstack([points, near])
    label = lambda r: r.labels[cKDTree(r.sites_unit).query(points)[1]]
    assert np.array_equal(label(fitted), label(full))


def test_winding_numbers_and_distances_equal_libigl(bunny):
    V, F = bunny
    rng = np.random.default_rng(3)
    lo, hi = V.min(0), V.max(0)
    Q = lo + (hi - lo) * rng.uniform(-0.1, 1.1, size=(20000, 3))
    w_igl = igl.winding_number(V, F, Q)
    exact = vf.winding_number(V, F, Q, exact=True)
    assert np.max(np.abs(exact - w_igl)) < 1e-9
    fast = vf.winding_number((V, F), Q)
    assert np.max(np.abs(fast - w_igl)) < 1e-3
    assert np.array_equal(np.abs(fast) >= 0.5, np.abs(w_igl) >= 0.5), "the fast winding number flipped a side"
    d, C, T = vf.signed_distance(V, F, Q, return_closest=True)
    sqrd, I, C_igl = igl.point_mesh_squared_distance(Q, V, F)
    assert np.allclose(np.abs(d), np.sqrt(sqrd), rtol=0, atol=1e-12 * np.ptp(V))
    assert np.array_equal(d < 0, np.abs(w_igl) >= 0.5)
    assert np.allclose(np.sum((C - Q) ** 2, axis=1), sqrd, rtol=1e-9, atol=1e-15)
    assert T.shape == (len(Q),) and T.max() < len(F)


def test_delaunay_equals_scipy():
    rng = np.random.default_rng(5)
    P = rng.uniform(size=(2000, 3))
    ours = np.sort(vf.delaunay(P).astype(np.int64), axis=1)
    ref = np.sort(Delaunay(P).simplices.astype(np.int64), axis=1)
    assert set(map(tuple, ours)) == set(map(tuple, ref))
    a, b, c, d = (P[ours[:, i]] for i in range(4))
    # Positively oriented, as documented.
    t = vf.delaunay(P)
    a, b, c, d = (P[t[:, i]] for i in range(4))
    assert np.all(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) > 0)


def test_hausdorff_and_evaluate_equal_the_cli(bunny, fitted, tmp_path):
    pred = tmp_path / "pred.obj"
    trimesh.Trimesh(fitted.crust_vertices, fitted.crust_faces, process=False).export(pred)
    cli = json.loads(run("eval", BUNNY, pred, "--json").stdout)
    ours = vf.evaluate(BUNNY, pred)
    for k in ("lo", "hi"):
        assert ours["hausdorff"][k] == cli["hausdorff"][k]
    for k in ("chamfer_l1", "fscore", "normal_consistency"):
        assert ours["surface"][k] == cli["surface"][k]
    assert ours["hausdorff_libigl"] == cli["hausdorff_libigl"]
    lo, hi = vf.hausdorff(bunny, fitted)
    assert lo <= hi
    V, F = bunny
    h_igl = igl.hausdorff(V, F, fitted.crust_vertices, fitted.crust_faces.astype(np.int64))
    assert lo >= h_igl * (1 - 1e-12), "the certified interval starts at or above libigl's vertex value"


def test_errors_are_input_errors_with_the_cli_message(bunny, tmp_path):
    V, F = bunny
    bad = V.copy()
    bad[7, 1] = np.nan
    with pytest.raises(vf.InputError, match="row 7 is not finite"):
        vf.winding_number(bad, F, V[:3])
    with pytest.raises(ValueError, match="refers to a vertex beyond"):
        vf.fit(V, F + len(V), progress=False, **SMALL)
    with pytest.raises(vf.InputError, match=r"\(n, 3\)"):
        vf.delaunay(np.zeros((4, 2)))
    with pytest.raises(vf.InputError, match="unknown fit option"):
        vf.fit(bunny, progress=False, stepz=3)
    with pytest.raises(vf.InputError, match="at least twice"):
        vf.fit(bunny, progress=False, sites=512, samples=1000)
    # Every documented option is passed through (an unknown one would fail first).
    with pytest.raises(vf.InputError, match="at least twice"):
        vf.fit(bunny, progress=False, sites=512, samples=1000, density="uniform", flood_cells=64)
    malformed = ROOT / "tests" / "malformed" / "nan_vertex.obj"
    cli = run("info", malformed, check=False)
    with pytest.raises(vf.InputError) as e:
        vf.load_mesh(malformed)
    assert str(e.value) in cli.stderr and "nan_vertex.obj" in str(e.value)
    with pytest.raises(vf.InputError):
        vf.fit(np.zeros((3, 3)), np.array([[0, 1, 2]]), progress=False, **SMALL)


def test_the_accuracy_target_is_the_clis(bunny, tmp_path):
    """`keep_topology`, `target_hausdorff` and `max_sites` reach the same accuracy target as
    the CLI's flags: the same trace, K doubling from `sites`."""
    r = vf.fit(bunny, name=str(BUNNY), progress=False, float32=False, keep_topology=True, target_hausdorff=0.004,
               max_sites=1024, **SMALL)
    a = r.report["accuracy_target"]
    assert a["keep_topology"] and a["goal_hausdorff_of_diagonal"] == 0.004 and a["max_sites"] == 1024
    sites = [row["sites"] for row in a["trace"]]
    assert sites[0] == 512 and all(b == 2 * x for x, b in zip(sites, sites[1:])) and sites[-1] <= 1024
    assert r.report["input"]["genus"] == 0 and "genus" in a["trace"][0]
    out = tmp_path / "b.obj"
    run(BUNNY, "-o", out, *SMALL_CLI, "--keep-topology", "--target-hausdorff", "0.4%", "--max-sites", "1024")
    cli = json.loads(out.with_suffix(".report.json").read_text())["accuracy_target"]
    assert [(t["sites"], t["genus"], t["hausdorff_hi_of_diagonal"]) for t in cli["trace"]] == [
        (t["sites"], t["genus"], t["hausdorff_hi_of_diagonal"]) for t in a["trace"]
    ]
    with pytest.raises(vf.InputError, match="target-hausdorff"):
        vf.fit(bunny, progress=False, target_hausdorff=2.0, **SMALL)


def test_progress_callback_sees_every_step_and_can_stop(bunny):
    seen = []
    vf.fit(bunny, progress=lambda stage, step, steps, loss: seen.append((stage, step, steps)), **SMALL)
    train = [s for s in seen if s[0] == "train" and s[1] > 0]
    assert [s[1] for s in train] == list(range(1, 31)) and all(s[2] == 30 for s in train)
    assert {"sample", "crust", "metrics"} <= {s[0] for s in seen}

    class Stop(Exception):
        pass

    def stop_at_5(stage, step, steps, loss):
        if stage == "train" and step == 5:
            raise Stop()

    with pytest.raises(Stop):
        vf.fit(bunny, progress=stop_at_5, **SMALL)


def test_the_gil_is_released_during_a_fit(bunny):
    """A Python thread keeps running while a fit works (with the GIL held it would stall
    for the whole native call)."""
    ticks = []
    done = threading.Event()

    def ticker():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    t = threading.Thread(target=ticker)
    t.start()
    t0 = time.perf_counter()
    vf.fit(bunny, progress=False, **{**SMALL, "steps": 60})
    t1 = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if t0 < x < t1]
    assert t1 - t0 > 0.3
    assert len(during) >= 10, f"{len(during)} ticks in a {t1 - t0:.2f} s fit"


def test_soup_and_open_meshes_fit(tmp_path):
    for name in ["mikedh__soup.stl", "mikedh__teapot.stl"]:
        r = vf.fit(SHARED / name, progress=False, **SMALL)
        m = r.to_trimesh()
        assert m.is_watertight and len(r.crust_faces) > 0, name


def test_glb_normals_flat_by_default_creased_on_request(bunny, tmp_path):
    """The default GLB carries no normals (viewers shade flat) and every vertex shared:
    watertight in trimesh as loaded. With ``crease`` the CLI and Python write the same file,
    valid for the Khronos validator, whose vertices on sharp edges come once per side:
    trimesh sees seams until it welds, and then the same watertight crust."""
    import json as _json
    import struct

    def attrs(path):
        data = Path(path).read_bytes()
        (length,) = struct.unpack_from("<I", data, 12)  # the JSON chunk after the 12-byte header
        return _json.loads(data[20 : 20 + length])["meshes"][0]["primitives"][0]["attributes"]

    r = vf.fit(BUNNY, progress=False, **SMALL)
    flat = r.save(tmp_path / "flat")["crust"]
    creased = r.save(tmp_path / "creased", normals="crease")["crust"]
    run(BUNNY, "-o", tmp_path / "cli.voronoi.glb", "--quiet", "--normals", "crease", *SMALL_CLI)
    assert (tmp_path / "cli.voronoi.glb").read_bytes() == Path(creased).read_bytes()
    report = _json.loads((tmp_path / "cli.voronoi.report.json").read_text())
    assert report["outputs"]["crust_normals"] == "crease:40"
    for path in (flat, creased):
        assert_gltf_valid(path)
    assert "NORMAL" not in attrs(flat) and "NORMAL" in attrs(creased)
    a = trimesh.load(flat, force="mesh")
    assert a.is_watertight and len(a.vertices) == len(r.crust_vertices)
    b = trimesh.load(creased, force="mesh", process=False)
    assert len(b.vertices) > len(r.crust_vertices)
    b.merge_vertices(merge_norm=True)
    assert b.is_watertight and len(b.vertices) == len(r.crust_vertices)
    assert abs(b.volume - a.volume) < 1e-9 * abs(a.volume)
    with pytest.raises(vf.InputError, match="crease:DEGREES"):
        r.save(tmp_path / "bad", normals="round")


def test_stub_lists_every_public_name():
    stub = (ROOT / "crates" / "python" / "python" / "voronoi_fit" / "__init__.pyi").read_text()
    for name in vf.__all__:
        assert name in stub, name
    assert all(vf.__dict__[n].__doc__ for n in vf.__all__), "every public name has a docstring"


def test_saved_files_are_the_cli_files_and_the_glb_is_valid(bunny, tmp_path):
    r = vf.fit(BUNNY, progress=False, **SMALL)  # float32 by default, as the CLI's GLB
    paths = r.save(tmp_path / "py")
    assert_gltf_valid(paths["crust"])
    run(BUNNY, "-o", tmp_path / "cli.voronoi.glb", "--quiet", *SMALL_CLI)
    assert (tmp_path / "cli.voronoi.glb").read_bytes() == Path(paths["crust"]).read_bytes()
    cli_sites, py_sites = np.load(tmp_path / "cli.voronoi.sites.npz"), np.load(paths["sites"])
    for k in ("sites", "labels", "transform"):
        assert np.array_equal(cli_sites[k], py_sites[k]), k
    with pytest.raises(vf.InputError, match="float32=True"):
        vf.fit(BUNNY, progress=False, float32=False, **SMALL).save(tmp_path / "f64")
    assert not list(tmp_path.glob("f64*")), "nothing written when refused"


def test_cluster_tasks_follow_the_batch_protocol(tmp_path):
    """The Ray runner's task (`voronoi_fit.cluster.fit_one`, here without Ray) runs the
    Rust batch protocol: `voronoi-fit batch`'s folder names (shared stems get the path
    hash), files, `batch.json` fields and summary columns, the same crust bytes; a second
    attempt finds the result and publishes nothing; bad input is a row, not an exception."""
    import csv
    import shutil

    from voronoi_fit import cluster

    meshes = tmp_path / "meshes"
    (meshes / "a").mkdir(parents=True)
    (meshes / "b").mkdir()
    shutil.copy(ROOT / "assets" / "torus.obj", meshes / "a" / "torus.obj")
    shutil.copy(ROOT / "assets" / "torus.obj", meshes / "b" / "torus.obj")
    shutil.copy(ROOT / "tests" / "malformed" / "nan_vertex.obj", meshes / "nan_vertex.obj")
    manifest = tmp_path / "manifest.txt"
    manifest.write_text("# two meshes with one stem, and a broken one\nmeshes/a/torus.obj\nmeshes/b/torus.obj\n"
                        "meshes/a/torus.obj\nmeshes/nan_vertex.obj\n")
    jobs = cluster.plan(manifest)
    names = [n for _, n in jobs]
    assert len(names) == 3 and names[0].startswith("torus-") and names[1].startswith("torus-")
    assert names[0] != names[1] and names[2] == "nan_vertex"

    opts = ["--sites", "256", "--steps", "20", "--samples", "20000", "--eval-samples", "2000", "--polish-steps", "50"]
    options = dict(sites=256, steps=20, samples=20000, eval_samples=2000, polish_steps=50, seed=0)
    out = tmp_path / "out"
    (out / ".work").mkdir(parents=True)
    batch = cluster.batch_options(out, options)
    rows = [cluster.fit_one(str(Path(p).resolve()), n, str(out), batch) for p, n in jobs]
    assert [r["status"] for r in rows] == ["fitted", "fitted", "bad input"], rows
    assert "nan_vertex.obj" in rows[2]["error"]
    again = cluster.fit_one(str(Path(jobs[0][0]).resolve()), names[0], str(out), batch)
    assert again["status"] == "done earlier"
    assert list((out / ".work").iterdir()) == [], "nothing half made is left"
    cluster.write_summary(out, rows, jobs)

    # The CLI's batch on the same meshes: the same names, files, fields and crust.
    bout = tmp_path / "batch"
    run("batch", f"@{manifest}", "--out", bout, "--quiet", "--", *opts, check=False)
    for n in names[:2]:
        ours, theirs = out / n, bout / n
        assert sorted(p.name for p in ours.iterdir()) == sorted(p.name for p in theirs.iterdir())
        assert (ours / f"{n}.voronoi.glb").read_bytes() == (theirs / f"{n}.voronoi.glb").read_bytes()
        assert json.loads((ours / "batch.json").read_text()).keys() == json.loads((theirs / "batch.json").read_text()).keys()
    with open(out / "summary.csv") as f:
        ours = list(csv.DictReader(f))
    with open(bout / "summary.csv") as f:
        theirs = list(csv.DictReader(f))
    assert list(ours[0]) == list(theirs[0]) + ["attempt_pid", "node"]
    assert [r["name"] for r in ours] == [r["name"] for r in theirs] == names
    assert [r["status"] for r in ours] == [r["status"] for r in theirs] == ["fitted", "fitted", "bad input"]
    assert ours[0]["triangles"] == theirs[0]["triangles"] and ours[0]["attempt_pid"]


def test_cluster_occupancy_samples_are_the_clis(tmp_path):
    """The Ray runner's `occupancy` option (`voronoi_fit.cluster`, here without Ray) writes
    the same NAME.voronoi.points.npz, byte for byte, as `voronoi-fit batch -- --occupancy N`
    with the same options, and both summaries name it in their `occupancy` column."""
    import csv

    from voronoi_fit import cluster

    meshes = tmp_path / "meshes"
    meshes.mkdir()
    (meshes / "torus.obj").write_bytes((ROOT / "assets" / "torus.obj").read_bytes())
    manifest = tmp_path / "manifest.txt"
    manifest.write_text("meshes/torus.obj\n")
    jobs = cluster.plan(manifest)
    options = dict(sites=256, steps=20, samples=20000, eval_samples=2000, polish_steps=50, seed=0, occupancy=4000)
    out = tmp_path / "out"
    (out / ".work").mkdir(parents=True)
    batch = cluster.batch_options(out, options)
    rows = [cluster.fit_one(str(Path(p).resolve()), n, str(out), batch) for p, n in jobs]
    assert [r["status"] for r in rows] == ["fitted"], rows
    cluster.write_summary(out, rows, jobs)
    bout = tmp_path / "batch"
    run("batch", f"@{manifest}", "--out", bout, "--quiet", "--", "--sites", "256", "--steps", "20", "--samples", "20000",
        "--eval-samples", "2000", "--polish-steps", "50", "--occupancy", "4000")
    name = "torus.voronoi.points.npz"
    assert (out / "torus" / name).read_bytes() == (bout / "torus" / name).read_bytes()
    assert np.load(out / "torus" / name)["points"].shape == (4000, 3)
    for d in (out, bout):
        with open(d / "summary.csv") as f:
            assert next(csv.DictReader(f))["occupancy"] == str(d / "torus" / name)
