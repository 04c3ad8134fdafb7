"""voronoi-fit from Python: fit labelled Voronoi sites to a triangle mesh and read back a
watertight crust (VoronoiNet), plus the geometry the fit is built on (winding numbers,
signed distances, exact Delaunay, certified Hausdorff, the evaluation report).

Every function calls the same Rust library code as the ``voronoi-fit`` command line and
releases the GIL while it works, so threads can fit several meshes at once. Arrays go in
and come out as numpy arrays (float64 positions, uint32 indices). Wherever a mesh is
expected you may pass a ``(vertices, faces)`` pair, a ``trimesh.Trimesh``, or a path to a
mesh file (OBJ, STL, PLY, OFF, glTF, GLB).

    import voronoi_fit as vf
    result = vf.fit("bunny.obj", sites=8192, seed=0)
    result.crust_vertices, result.crust_faces    # the watertight crust, mesh frame
    result.report["metrics"]["hausdorff"]        # the same report as OUT.report.json

Errors raise :class:`InputError` (a ``ValueError``) when the input is at fault, with the
CLI's message, and :class:`Error` (a ``RuntimeError``) otherwise.
"""

from __future__ import annotations

import json
import os
import sys
from typing import Any, Callable, Optional

import numpy as np

from . import _native
from ._native import Error, InputError

__all__ = [
    "Error",
    "FitResult",
    "InputError",
    "crust",
    "delaunay",
    "evaluate",
    "fit",
    "hausdorff",
    "load_mesh",
    "save_mesh",
    "signed_distance",
    "view",
    "winding_number",
]

__version__ = "0.1.0"

# fit() keyword arguments passed through to the library's FitOptions (the CLI's flags).
_FIT_OPTIONS = {
    "steps",
    "preset",
    "init",
    "density",
    "batch",
    "lr",
    "beta_start",
    "surface_offset",
    "w_sdf",
    "w_centroidal",
    "w_normal",
    "w_reconstruction",
    "w_surface",
    "samples",
    "eval_samples",
    "solid",
    "shell_thickness",
    "flood_cells",
    "no_fill_holes",
    "train_shell",
    "skip_metrics",
    "polish_steps",
    "polish_lr",
    "polish_batch",
    "polish_align",
    "target_hausdorff",
    "keep_topology",
    "max_sites",
}


def _rows(a: Any, what: str) -> np.ndarray:
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"{what}: not an array of numbers ({e})") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"{what}: expected an (n, 3) array, got shape {arr.shape}")
    return np.ascontiguousarray(arr, dtype="<f8")


def _faces(a: Any, what: str) -> np.ndarray:
    arr = np.asarray(a)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"{what}: expected an (m, 3) array of vertex indices, got shape {arr.shape}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        if not np.all(np.equal(np.mod(arr, 1), 0)):
            raise InputError(f"{what}: vertex indices must be whole numbers")
    if arr.size and (arr.min() < 0 or arr.max() >= 2**32):
        raise InputError(f"{what}: vertex indices must be in 0 .. 2**32 - 1 (0-based)")
    return np.ascontiguousarray(arr, dtype="<u4")


def _as_mesh(mesh: Any, faces: Any = None, what: str = "mesh") -> tuple[np.ndarray, np.ndarray]:
    """A mesh-like → (vertices, faces) arrays: a (V, F) pair, separate V and F, a
    trimesh.Trimesh (anything with .vertices and .faces), a FitResult's crust, or a path."""
    if faces is not None:
        return _rows(mesh, f"{what} vertices"), _faces(faces, f"{what} faces")
    if isinstance(mesh, (str, os.PathLike)):
        return load_mesh(mesh)
    if isinstance(mesh, FitResult):
        return mesh.crust_vertices, mesh.crust_faces
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        return _rows(mesh.vertices, f"{what} vertices"), _faces(mesh.faces, f"{what} faces")
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        return _rows(mesh[0], f"{what} vertices"), _faces(mesh[1], f"{what} faces")
    raise InputError(
        f"{what}: expected (vertices, faces), a trimesh.Trimesh or a path to a mesh file, got {type(mesh).__name__}"
    )


def _from(b: bytes, dtype: str, cols: int) -> np.ndarray:
    a = np.frombuffer(b, dtype=dtype).copy()
    return a.reshape(-1, cols) if cols > 1 else a


def load_mesh(path: "str | os.PathLike[str]") -> tuple[np.ndarray, np.ndarray]:
    """Read a mesh file as the CLI does (OBJ, STL, PLY, OFF, glTF, GLB; exactly coincident
    vertices welded). Returns ``(vertices (n, 3) float64, faces (m, 3) uint32)``.

    Raises :class:`InputError` naming the file and the line, byte or element at fault."""
    v, f = _native.load_mesh(os.fspath(path))
    return _from(v, "<f8", 3), _from(f, "<u4", 3)


def save_mesh(path: "str | os.PathLike[str]", vertices: Any, faces: Any, normals: str = "flat") -> None:
    """Write a mesh atomically (temporary file beside it, then rename) as the CLI writes
    its outputs: .glb, .gltf (+ .bin), .obj or binary .ply by the extension. glTF holds
    float32, so positions are rounded there (for a crust, fit with ``float32=True``
    first: see :meth:`FitResult.save`).

    ``normals`` (glTF only, as the CLI's ``--normals``): ``"flat"`` writes none, so viewers
    shade each triangle flat and every vertex stays shared (watertight in trimesh);
    ``"smooth"`` one area-weighted normal per vertex; ``"crease"`` or ``"crease:DEG"``
    smooth except across edges sharper than DEG (40 by default), a vertex on such an edge
    written once per side (``trimesh.load`` then shows seams until
    ``merge_vertices(merge_norm=True)``)."""
    v, f = _rows(vertices, "vertices"), _faces(faces, "faces")
    _native.save_mesh(os.fspath(path), v.tobytes(), f.tobytes(), normals)


def view(
    crust: "str | os.PathLike[str]",
    input: "Optional[str | os.PathLike[str]]" = None,
    report: "Optional[str | os.PathLike[str]]" = None,
    sites: "Optional[str | os.PathLike[str]]" = None,
    out: "Optional[str | os.PathLike[str]]" = None,
    cells: "Optional[str | os.PathLike[str]]" = None,
    check_samples: int = 200_000,
) -> "Path":
    """Write the offline viewer page of a crust, as ``voronoi-fit view`` does: one
    self-contained HTML file (three.js inlined, meshes embedded) showing the input and the
    crust, the sites, misclassified sample points, the cells, the loss curve and timings.

    Files not given are looked for beside the crust (``OUT.report.json``,
    ``OUT.sites.npz``, ``OUT.cells.glb``; the input is the path the report names); a
    missing one only leaves its part out. ``out`` defaults to ``OUT.html`` beside the
    crust. ``check_samples`` fresh samples are classified by the sites to find
    misclassified points (0: none). Returns the page's path; each part left out is a
    ``UserWarning`` saying why (as the CLI's notes on stderr).

    Raises :class:`InputError` when a file given is missing or malformed."""
    import warnings
    from pathlib import Path

    opt = lambda p: None if p is None else os.fspath(p)  # noqa: E731
    path, notes = _native.view(
        os.fspath(crust), opt(input), opt(report), opt(sites), opt(cells), opt(out), check_samples
    )
    for n in notes:
        warnings.warn(f"{n}; the page leaves that part out", stacklevel=2)
    return Path(path)


def _atomic_text(path: str, text: str) -> None:
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


class FitResult:
    """What :func:`fit` returns.

    Attributes:
        sites: (K + B, 3) float64, the sites in the mesh's frame (K trainable, then B fixed
            outside sites on the faces of the normalisation cube).
        labels: (K + B,) bool, True = inside.
        sites_unit: the same sites in the unit cube, as the sites file stores them.
        transform: (4, 4) float64, unit cube → mesh frame (row-major, column vectors).
        crust_vertices: (n, 3) float64, the crust in the mesh frame.
        crust_faces: (m, 3) uint32, counter-clockwise seen from outside.
        report: dict, the same report as ``OUT.report.json``.
    """

    def __init__(self, sites_unit, labels, transform, crust_vertices, crust_faces, report):
        self.sites_unit = sites_unit
        self.labels = labels
        self.transform = transform
        self.crust_vertices = crust_vertices
        self.crust_faces = crust_faces
        self.report = report
        homogeneous = np.hstack([sites_unit, np.ones((len(sites_unit), 1))])
        self.sites = (homogeneous @ transform.T)[:, :3]

    def to_trimesh(self):
        """The crust as a ``trimesh.Trimesh`` (needs trimesh)."""
        import trimesh

        return trimesh.Trimesh(self.crust_vertices, self.crust_faces, process=False)

    def save(self, prefix: "str | os.PathLike[str]", format: str = "glb", normals: str = "flat") -> dict:
        """Write ``PREFIX.voronoi.FORMAT`` (the crust), ``PREFIX.voronoi.sites.npz`` and
        ``PREFIX.voronoi.report.json``, each atomically, as ``voronoi-fit MESH -o
        PREFIX.voronoi.FORMAT`` names them; returns the paths. A .glb/.gltf crust must
        come from ``fit(..., float32=True)``, which rounds and checks it as glTF stores it
        (a float64 crust is refused there with that advice); .obj and .ply keep float64.
        ``normals``: as for :func:`save_mesh`."""
        if format in ("glb", "gltf") and not np.array_equal(
            self.crust_vertices.astype(np.float32).astype(np.float64), self.crust_vertices
        ):
            raise InputError(
                f"the crust is float64; glTF stores float32, and rounding it now could break the checked crust. "
                f"Fit with float32=True (as the CLI does for .glb), or save as obj or ply"
            )
        base = os.fspath(prefix) + ".voronoi"
        paths = {"crust": f"{base}.{format}", "sites": f"{base}.sites.npz", "report": f"{base}.report.json"}
        _native.save_sites(
            paths["sites"],
            np.ascontiguousarray(self.sites_unit, dtype="<f8").tobytes(),
            np.ascontiguousarray(self.labels, dtype=np.uint8).tobytes(),
            np.ascontiguousarray(self.transform, dtype="<f8").tobytes(),
        )
        save_mesh(paths["crust"], self.crust_vertices, self.crust_faces, normals)
        _atomic_text(paths["report"], json.dumps(self.report, indent=2))
        return paths

    def summary(self) -> str:
        """The figures people look at first."""
        m = self.report.get("metrics") or {}
        h = m.get("hausdorff") or {}
        s = m.get("surface") or {}
        c = self.report["crust"]
        text = f"{len(self.labels)} sites -> crust of {c['num_triangles']} triangles, genus {c['genus']}"
        if h:
            text += (
                f"; Hausdorff {100 * h['hi'] / h['diagonal']:.3f}% of the diagonal, "
                f"normal consistency {s.get('normal_consistency', float('nan')):.4f}"
            )
        return text

    def __repr__(self) -> str:
        return f"<voronoi_fit.FitResult: {self.summary()}>"


class _Tqdm:
    """The fit's progress on a tqdm bar (stages as the description, steps as the bar)."""

    def __init__(self, tqdm):
        self.tqdm = tqdm
        self.bar = None
        self.stage = None

    def __call__(self, stage, step, steps, loss):
        if stage in ("train", "polish") and steps:
            if self.bar is None:
                self.bar = self.tqdm(total=steps, desc=stage, unit="step", leave=False)
                self.stage = stage
            if self.stage != stage or self.bar.total != steps:
                self.bar.reset(total=steps)
                self.bar.set_description_str(stage, refresh=False)
                self.stage = stage
            self.bar.n = step
            if loss == loss:
                self.bar.set_postfix(loss=f"{loss:.5f}", refresh=False)
            self.bar.refresh()
        elif self.bar is not None:
            self.bar.set_description(stage)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def fit(
    mesh: Any,
    faces: Any = None,
    *,
    sites: int = 8192,
    seed: int = 0,
    relabel: bool = True,
    carve: "float | bool" = True,
    prune: bool = True,
    progress: "Callable[[str, int, int, float], Any] | bool | None" = None,
    name: Optional[str] = None,
    float32: bool = True,
    **options: Any,
) -> FitResult:
    """Fit ``sites`` labelled Voronoi sites to a mesh and extract the watertight crust:
    the main job, exactly as ``voronoi-fit MESH --sites K --seed N`` runs it (the crust is
    rounded to float32 and checked again as rounded, as for the CLI's default GLB output,
    unless ``float32=False``).

    Args:
        mesh: (vertices, faces), a trimesh.Trimesh, a path, or vertices with ``faces``.
        faces: the faces, when ``mesh`` is the vertices.
        sites: trainable sites K.
        seed: seed of the samples, the initialisation and the batches (same seed, same
            result, on any thread count).
        relabel: give each trained site the solid's label where it stands (False needs
            polish_steps=0: the polish ignores labels).
        carve: True (default tolerance, 0.3% of the diagonal), a share of the diagonal, or
            False for no site insertion.
        prune: last, remove the sites whose Delaunay neighbours all carry their label
            (they change neither the crust nor the occupancy); False keeps every site.
        progress: a callable ``progress(stage, step, steps, loss)``; None shows a tqdm bar
            when tqdm is installed and stderr is a terminal; False shows nothing. An
            exception raised by the callable, or Ctrl-C, stops the fit and is raised.
        name: the mesh's name in messages and the report (default: the path, or "mesh").
        float32: round the crust to float32 and check it again as rounded, as the CLI does
            for its default GLB output (so ``result.save(prefix)`` writes exactly the file
            ``voronoi-fit MESH`` writes); False keeps float64, as the CLI does for .obj and
            .ply outputs.
        **options: the CLI's other fit options by their long names: steps, preset
            ("default" | "fast" | "paper"), init, density ("adaptive" | "uniform"), batch, lr,
            beta_start, surface_offset, w_sdf,
            w_centroidal, w_normal, w_reconstruction, w_surface, samples, eval_samples,
            solid ("auto" | "winding" | "shell" | "flood"), shell_thickness, flood_cells,
            no_fill_holes (keep planar holes open), train_shell (train a thin shell's sites
            instead of keeping them as constructed), skip_metrics,
            polish_steps (0: no polish), polish_lr, polish_batch, polish_align (None: on a closed mesh both
            polishes, the aligned crust kept where it is at least as good on all four metrics,
            Hausdorff distances both within the F-score's tau or with overlapping certified
            intervals counting as equal;
            0: VoroLoss alone; W > 0: always weight W), target_hausdorff (a certified
            Hausdorff distance as a share of the diagonal: K doubles from ``sites`` until
            met), keep_topology (K doubles until the crust has the input's genus and
            components), max_sites (their budget, default 131,072); the report's
            ``accuracy_target`` has the trace.

    Returns:
        :class:`FitResult`.
    """
    unknown = sorted(set(options) - _FIT_OPTIONS)
    if unknown:
        raise InputError(f"unknown fit option(s) {', '.join(unknown)}; known: {', '.join(sorted(_FIT_OPTIONS))}")
    if name is None:
        name = os.fspath(mesh) if isinstance(mesh, (str, os.PathLike)) else "mesh"
    v, f = _as_mesh(mesh, faces)
    opts = {k: val for k, val in options.items() if val is not None}
    opts["sites"] = int(sites)
    opts["seed"] = int(seed)
    opts["no_relabel"] = not relabel
    opts["no_prune"] = not prune
    if carve is False:
        opts["no_carve"] = True
    elif carve is not True:
        opts["carve"] = float(carve)
    bar = None
    callback = progress if callable(progress) else None
    if progress is None and sys.stderr is not None and sys.stderr.isatty():
        try:
            from tqdm.auto import tqdm

            bar = _Tqdm(tqdm)
            callback = bar
        except ImportError:
            pass
    try:
        s, l, t, cv, cf, report = _native.fit(v.tobytes(), f.tobytes(), name, json.dumps(opts), callback, bool(float32))
    finally:
        if bar is not None:
            bar.close()
    return FitResult(
        _from(s, "<f8", 3),
        np.frombuffer(l, dtype=np.uint8).astype(bool),
        _from(t, "<f8", 4),
        _from(cv, "<f8", 3),
        _from(cf, "<u4", 3),
        json.loads(report),
    )


def crust(sites: Any, labels: Any, transform: Any = None) -> tuple[np.ndarray, np.ndarray]:
    """The watertight crust of labelled sites: the Voronoi faces between inside and
    outside sites, from an exact Delaunay tetrahedralization, checked exactly (closed,
    manifold, no self-intersections).

    Args:
        sites: (n, 3). With ``transform``, unit-cube coordinates as a sites file stores
            them (``FitResult.sites_unit``) and ``transform`` the 4×4 map to the mesh frame;
            without, any frame (``FitResult.sites``): they are mapped into the unit cube
            (bounding box, 5% margin) and the crust is mapped back.
        labels: (n,) bool or 0/1, True = inside.

    Returns:
        (vertices (n, 3) float64, faces (m, 3) uint32), counter-clockwise seen from outside.
    """
    p = _rows(sites, "sites")
    lab = np.asarray(labels).reshape(-1)
    if lab.shape[0] != p.shape[0]:
        raise InputError(f"{lab.shape[0]} labels for {p.shape[0]} sites: give one per site")
    lab = np.ascontiguousarray(lab.astype(bool), dtype=np.uint8)
    if transform is None:
        if len(p) == 0:
            raise InputError("sites: no sites")
        lo, hi = p.min(axis=0), p.max(axis=0)
        extent = float((hi - lo).max())
        if not extent > 0:
            raise InputError("sites: all sites coincide; there is no cell to bound")
        scale = 0.9 / extent
        center = 0.5 * (lo + hi)
        unit = np.clip((p - center) * scale + 0.5, 0.0, 1.0)
        m = np.eye(4)
        m[:3, :3] /= scale
        m[:3, 3] = center - 0.5 / scale
    else:
        unit = p
        m = np.asarray(transform, dtype=np.float64)
        if m.shape != (4, 4):
            raise InputError(f"transform: expected a 4×4 matrix, got shape {m.shape}")
    v, f = _native.crust(np.ascontiguousarray(unit, dtype="<f8").tobytes(), lab.tobytes(), np.ascontiguousarray(m, dtype="<f8").tobytes())
    return _from(v, "<f8", 3), _from(f, "<u4", 3)


def _mesh_and_queries(v, f, q):
    if q is None:  # winding_number(mesh, queries)
        mv, mf = _as_mesh(v)
        return mv, mf, _rows(f, "queries")
    return _rows(v, "vertices"), _faces(f, "faces"), _rows(q, "queries")


def winding_number(V: Any, F: Any, Q: Any = None, exact: bool = False) -> np.ndarray:
    """Generalized winding numbers of the query points Q with respect to the mesh (V, F)
    (or ``winding_number(mesh, Q)``). Fast by default: Barill et al.'s order-2 expansion
    with the exact sum wherever the answer is within reach of ±0.5, so inside/outside
    never flips; ``exact=True`` sums every triangle's solid angle hierarchically."""
    v, f, q = _mesh_and_queries(V, F, Q)
    return _from(_native.winding_number(v.tobytes(), f.tobytes(), q.tobytes(), bool(exact)), "<f8", 1)


def signed_distance(V: Any, F: Any, Q: Any = None, return_closest: bool = False):
    """Signed distance from the query points to the mesh, negative inside (|winding
    number| ≥ 0.5, the rule the fit uses). With ``return_closest`` also the closest points
    (n, 3) and their triangles (n,)."""
    v, f, q = _mesh_and_queries(V, F, Q)
    d, c, t = _native.signed_distance(v.tobytes(), f.tobytes(), q.tobytes())
    d = _from(d, "<f8", 1)
    if return_closest:
        return d, _from(c, "<f8", 3), _from(t, "<u4", 1)
    return d


def delaunay(points: Any) -> np.ndarray:
    """Exact 3D Delaunay tetrahedralization (Shewchuk's predicates, symbolic perturbation
    for degenerate input): (m, 4) uint32 positively oriented tetrahedra, indices into
    ``points``."""
    p = _rows(points, "points")
    return _from(_native.delaunay(p.tobytes()), "<u4", 4)


def hausdorff(VA: Any, FA: Any, VB: Any = None, FB: Any = None, rel_tolerance: float = 1e-6) -> tuple[float, float]:
    """Certified two-sided Hausdorff distance between two surfaces: ``(lo, hi)`` with the
    true distance in between and ``hi - lo`` at most ``rel_tolerance`` × the diagonal of
    both meshes' bounding box. Call as ``hausdorff(VA, FA, VB, FB)`` or
    ``hausdorff(mesh_a, mesh_b)``."""
    if VB is None and FB is None:
        (va, fa), (vb, fb) = _as_mesh(VA, what="first mesh"), _as_mesh(FA, what="second mesh")
    else:
        (va, fa), (vb, fb) = _as_mesh(VA, FA, "first mesh"), _as_mesh(VB, FB, "second mesh")
    return _native.hausdorff(va.tobytes(), fa.tobytes(), vb.tobytes(), fb.tobytes(), float(rel_tolerance))


def evaluate(reference: Any, prediction: Any) -> dict:
    """The ``voronoi-fit eval`` report of ``prediction`` against ``reference`` (each a
    mesh-like): certified and libigl-compatible Hausdorff, Chamfer L1/L2, F-score at 0.3%
    of the diagonal, normal consistency, volumetric IoU and the prediction's validity."""
    vr, fr = _as_mesh(reference, what="reference")
    vp, fp = _as_mesh(prediction, what="prediction")
    return json.loads(_native.evaluate(vr.tobytes(), fr.tobytes(), vp.tobytes(), fp.tobytes()))
