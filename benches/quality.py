#!/usr/bin/env python3
"""Surface-quality benchmark: the crust of `voronoi-fit` against three other ways of
spending the same storage, on real and synthetic meshes, all measured by `voronoi-fit eval`
in the same run.

    target/bench-venv/bin/python benches/quality.py                 # all meshes, K = 2k, 8k, 32k
    target/bench-venv/bin/python benches/quality.py --quick         # 3 small meshes, K = 2048
    target/bench-venv/bin/python benches/quality.py --sites 2048,8192 --meshes spot,dragon
    target/bench-venv/bin/python benches/quality.py --ours-args "--steps 1200" --out /tmp/variant

Setup (once): python3 -m venv target/bench-venv &&
target/bench-venv/bin/pip install -r benches/requirements-bench.txt; node/npm for the npm
meshes. The script builds the CLI with `cargo build --profile ci --bin voronoi-fit` (and
goes on with the existing binary if that fails, e.g. during someone's edit; `--no-build`
skips it).

Methods, per mesh and number of sites K (floats = 3K):
  ours      `voronoi-fit MESH -o OUT.glb --sites K --quiet --json [--ours-args]`; time =
            the report's total_seconds (its fit-only part, without the report's own
            evaluation, is in `seconds_fit`). Storage 3K float32 + K bits; the fixed
            ceil(sqrt(K))-ish boundary sites are implied by K and not counted.
  ours_uniform  the same with `--density uniform` (one pair spacing everywhere: the density
            ablation's baseline, issue 53)
  voromesh  VoroMesh-style direct fit (benches/voromesh_ref.py: grid-initialised generators,
            VoroLoss, Adam, winding-number labels) with about K generators (exact count in
            `sites`), surface by `voronoi-fit crust` of its sites file. Same storage rule.
  mc        marching cubes (skimage, level 0) of the exact signed distance
            (`voronoi-fit query`, negative inside by |winding number| >= 0.5) sampled on an
            n^3 grid, n = round((3K)^(1/3)), so n^3 ~ 3K floats (stored as float32:
            4 n^3 bytes), over the bounding box plus 1.25 cells on every side.
  qem       QEM decimation (fast-simplification) of the input (after trimesh's
            merge_vertices) to the same bytes as ours: a mesh costs 12 V + 12 F bytes (float32
            positions, uint32 indices), ours 12 K + K/8. With F ~ 2V (closed meshes) that is
            V ~ K/3, F ~ 2K/3; the target face count uses the input's own V/F ratio and is
            corrected once from the bytes actually reached. An input already within the
            budget is kept as it is (noted).
Every output is measured by `voronoi-fit eval INPUT OUTPUT --json`: certified Hausdorff
interval (upper end, % of the input's bounding-box diagonal), Chamfer L1 (% of the
diagonal), F-score at 0.3% of the diagonal, normal consistency, IoU, and validity (closed,
manifold, self-intersections, components, genus). The CSV also has `boundary_hausdorff_pct`
and `interior_share` (eval's `solid_boundary`: the Hausdorff distance with the input's faces
that lie inside its own solid left out, a sampled estimate; the share of such faces), which
tell a union's buried faces apart from a method's error.

Output: DIR/quality_results.csv and DIR/quality_results.md (DIR = benches/results/ unless --out),
one row per mesh x K x method, a summary of medians per method, and PNG renders of input
and outputs (DIR/quality_renders/, by benches/render.py). The provenance of the meshes is
printed and written to benches/results/QUALITY_MESHES.md. The CSV's `output` column is
relative to the work folder (--work). Failed runs are recorded with their error
and the benchmark goes on. Runs are sequential (the machine has 2 cores; each tool uses
both). Work files: target/quality-cache/runs/MESH/K/METHOD/; `--reuse` takes a previous
result whose settings are identical instead of running it again; `--cached-only` runs
nothing and tabulates the latest result of every selected run found in the work folder
(to merge runs over different subsets; use a separate `--work` per experiment).
"""
import argparse
import csv
import hashlib
import json
import math
import os
import shlex
import shutil
import statistics
import subprocess
import sys
import time
import traceback
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import quality_meshes as qm  # noqa: E402

ROOT = HERE.parent
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
WORK = ROOT / "target" / "quality-cache" / "runs"
PY = sys.executable
METHODS = ["ours", "voromesh", "mc", "qem", "ours_uniform"]
RENDER_DEFAULT = ["spot", "bunny_scan", "featuretype", "dragon", "box_fin", "cad_union"]
TIMEOUT = 3600

FIELDS = [
    "mesh", "K", "method", "status", "error", "size", "bytes", "vertices", "triangles",
    "hausdorff_hi_pct", "hausdorff_lo_pct", "chamfer_l1_pct", "fscore", "normal_consistency", "iou",
    "boundary_hausdorff_pct", "interior_share", "valid_solid", "closed", "manifold", "self_intersecting", "components", "genus",
    "seconds", "seconds_fit", "notes", "output",
]


class RunError(Exception):
    pass


def run(cmd, timeout=TIMEOUT):
    """Run a command; return stdout; raise RunError with the tail of stderr on failure."""
    try:
        r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RunError(f"timed out after {timeout} s: {' '.join(map(str, cmd[:3]))} ...")
    if r.returncode != 0:
        err = " ".join((r.stderr or r.stdout).strip().split())
        raise RunError(f"exit {r.returncode}: {err[-400:]}")
    return r.stdout


# ---------------------------------------------------------------------------------------
# methods: each returns (prediction path, dict of row fields)


def storage_bytes(K):
    """Bytes of K sites: 3K float32 + one bit per label."""
    return 12 * K + math.ceil(K / 8)


def method_ours(mesh, K, d, a, extra=(), name="ours"):
    out = d / f"{name}.glb"
    rep = json.loads(run([a.ours_bin, mesh.path, "-o", out, "--sites", K, "--quiet", "--json",
                          *shlex.split(a.ours_args), *extra]))
    t = rep["timings_seconds"]
    # Every site the file holds counts: K trained, the boundary sites, those inserted where
    # the crust strayed, less those removed last because they change nothing.
    n = rep["crust"]["num_sites"]
    return out, {
        "size": f"{n} sites (K = {K})", "bytes": storage_bytes(n),
        "seconds": rep["total_seconds"],
        "seconds_fit": sum(t.get(k, 0.0) for k in ("load", "oracle", "sample", "train", "crust")),
        "notes": f"misclassified {100 * rep['quality']['misclassification']:.2f}%",
    }


def method_ours_uniform(mesh, K, d, a):
    """The main job with one pair spacing over the whole surface (`--density uniform`): the
    density ablation's baseline (issue 53), in the same run as `ours`."""
    out, row = method_ours(mesh, K, d, a, extra=["--density", "uniform"], name="ours_uniform")
    return out, row


def method_voromesh(mesh, K, d, a):
    sites = d / "voromesh.sites.npz"
    out = d / "voromesh.glb"
    t0 = time.perf_counter()
    info = json.loads(run([PY, HERE / "voromesh_ref.py", mesh.path, "--sites", K, "-o", sites, "--quiet",
                           *shlex.split(a.voromesh_args)]))
    run([a.bin, "crust", sites, "-o", out])
    wall = time.perf_counter() - t0
    Kv = info["sites"]
    return out, {
        "size": f"{Kv} sites", "bytes": storage_bytes(Kv), "seconds": wall, "seconds_fit": wall,
        "notes": f"grid n {info['grid_n']:.2f}, {info['samples']:,} samples, VoroLoss {info['loss_last']:.2e}",
    }


def method_mc(mesh, K, d, a):
    from skimage.measure import marching_cubes

    t0 = time.perf_counter()
    n = max(4, round((3 * K) ** (1 / 3)))
    V, _ = qm.load_mesh(mesh.path)
    lo, hi = V.min(0), V.max(0)
    ext = np.maximum(hi - lo, 1e-9 * np.linalg.norm(hi - lo))
    # n nodes per axis with 1.25 cells of margin beyond the bounding box on each side: the
    # outermost nodes are outside, and no node lies on the box's planes (an exact zero at a
    # node gives skimage degenerate triangles, and CAD faces often lie on those planes)
    margin = 1.25
    h = ext / (n - 1 - 2 * margin)
    axes = [lo[i] - margin * h[i] + h[i] * np.arange(n) for i in range(3)]
    G = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    pts, res = d / "mc_points.npy", d / "mc_query.npz"
    np.save(pts, G)
    run([a.bin, "query", mesh.path, pts, "-o", res])
    sdf = np.load(res)["sdf"].reshape(n, n, n).astype(np.float32)  # stored as float32
    if not (sdf.min() < 0 < sdf.max()):
        raise RunError(f"no zero crossing on the {n}^3 grid (signed distance in [{sdf.min():.3g}, {sdf.max():.3g}]): "
                       "nothing is inside by the winding-number rule")
    verts, faces, _, _ = marching_cubes(sdf, level=0.0, spacing=tuple(h))
    verts = verts + (lo - margin * h)
    faces = faces.astype(np.int64)
    a_, b_, c_ = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    if np.einsum("ij,ij->i", a_, np.cross(b_, c_)).sum() < 0:  # orient outwards
        faces = faces[:, ::-1]
    out = d / "mc.obj"
    qm.write_obj(out, verts, faces)
    wall = time.perf_counter() - t0
    return out, {"size": f"{n}^3 grid", "bytes": 4 * n**3, "seconds": wall, "seconds_fit": wall, "notes": ""}


def method_qem(mesh, K, d, a):
    import fast_simplification
    import trimesh

    t0 = time.perf_counter()
    V, F = qm.load_mesh(mesh.path)
    m = trimesh.Trimesh(V, F, process=False)
    m.merge_vertices()
    V, F = np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)
    budget = storage_bytes(K)
    note = ""
    if 12 * len(V) + 12 * len(F) <= budget:
        Vs, Fs = V, F
        note = "input within the budget: not decimated"
    else:
        ratio = len(V) / len(F)
        target = int(budget / (12 * (1 + ratio)))
        for _ in range(2):
            Vs, Fs = fast_simplification.simplify(V, F, target_count=max(target, 4))
            got = 12 * len(Vs) + 12 * len(Fs)
            if abs(got - budget) <= 0.03 * budget:
                break
            target = int(target * budget / got)
        note = f"target {target:,} faces"
    out = d / "qem.obj"
    qm.write_obj(out, Vs, Fs)
    wall = time.perf_counter() - t0
    return out, {"size": f"{len(Fs):,} faces", "bytes": 12 * len(Vs) + 12 * len(Fs), "seconds": wall,
                 "seconds_fit": wall, "notes": note}


METHOD_FN = {"ours": method_ours, "voromesh": method_voromesh, "mc": method_mc, "qem": method_qem,
             "ours_uniform": method_ours_uniform}


def evaluate(a, mesh, pred):
    ev = json.loads(run([a.bin, "eval", mesh.path, pred, "--json"]))
    diag = ev["reference_diagonal"]
    s, hd, v = ev["surface"], ev["hausdorff"], ev.get("prediction_validity") or {}
    return {
        "hausdorff_hi_pct": 100 * hd["hi"] / diag, "hausdorff_lo_pct": 100 * hd["lo"] / diag,
        "chamfer_l1_pct": 100 * s["chamfer_l1"] / diag, "fscore": s["fscore"],
        "normal_consistency": s["normal_consistency"], "iou": (ev.get("iou") or {}).get("iou"),
        # The Hausdorff distance to the solid's boundary only (faces inside the input's own
        # solid left out; a sampled estimate): what any closed surface can reach on unions.
        "boundary_hausdorff_pct": 100 * (ev.get("solid_boundary") or {}).get("hausdorff_estimate", float("nan")) / diag,
        "interior_share": (ev.get("solid_boundary") or {}).get("interior_share"),
        "valid_solid": v.get("is_valid_solid"), "closed": v.get("is_closed"), "manifold": v.get("is_manifold"),
        "self_intersecting": v.get("self_intersecting"), "components": v.get("num_components"), "genus": v.get("genus"),
    }


def mesh_counts(path):
    V, F = qm.load_mesh(path)
    return len(np.unique(F)), len(F)


# ---------------------------------------------------------------------------------------


def file_hash(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def settings_key(a, mesh, K, method):
    """Identity of a run for --reuse: the input, the method's settings and the binaries'
    contents (an edited voronoi-fit runs everything again)."""
    h = hashlib.sha256()
    h.update(Path(mesh.path).read_bytes())
    extra = {
        "ours": a.ours_args + a.ours_bin_hash,
        "ours_uniform": a.ours_args + a.ours_bin_hash,
        "voromesh": a.voromesh_args + file_hash(HERE / "voromesh_ref.py"),
    }.get(method, file_hash(__file__))  # mc, qem: this script's code
    h.update(f"{method}|{K}|{extra}|{a.bin_hash}".encode())
    return h.hexdigest()[:16]


def one_run(a, mesh, K, method):
    d = Path(a.work) / mesh.name / f"K{K}" / method
    d.mkdir(parents=True, exist_ok=True)
    key = settings_key(a, mesh, K, method)
    cache = d / "result.json"
    if a.cached_only:  # the latest result in the work folder, whatever its settings
        if not cache.exists():
            return None
        row = json.loads(cache.read_text())
        row.pop("_key", None)
        return row
    if a.reuse and cache.exists():
        row = json.loads(cache.read_text())
        if row.get("_key") == key and row.get("status") == "ok":
            row.pop("_key")
            return row
    row = {"mesh": mesh.name, "K": K, "method": method, "status": "ok", "error": ""}
    try:
        pred, info = METHOD_FN[method](mesh, K, d, a)
        row.update(info)
        row["vertices"], row["triangles"] = mesh_counts(pred)
        row.update(evaluate(a, mesh, pred))
        row["output"] = str(pred)
    except Exception as e:  # record and go on
        row["status"] = "failed"
        row["error"] = str(e) if isinstance(e, RunError) else f"{type(e).__name__}: {e}"
        if not isinstance(e, RunError):
            traceback.print_exc()
    cache.write_text(json.dumps({**row, "_key": key}))
    return row


# ---------------------------------------------------------------------------------------
# reporting


def fmt(x, spec):
    if x is None or x == "":
        return ""
    if isinstance(x, float) and math.isnan(x):
        return "NaN"
    return format(x, spec)


def yesno(b):
    return "" if b is None else ("yes" if b else "no")


def validity(r):
    if r.get("status") != "ok" or r.get("closed") is None:
        return ""
    flags = []
    if not r["closed"]:
        flags.append("open")
    if not r["manifold"]:
        flags.append("non-manifold")
    if r["self_intersecting"]:
        flags.append("self-intersecting")
    return "valid" if not flags else ", ".join(flags)


def seconds(r):
    """Wall seconds; for ours also the fit alone (without its report's own evaluation)."""
    if r["method"] == "ours" and r.get("seconds_fit") is not None:
        return f"{r['seconds']:.1f} ({r['seconds_fit']:.1f})"
    return fmt(r.get("seconds"), ".1f")


def table_rows(rows):
    out = [
        "| mesh | K | method | size | bytes | Hausdorff hi % | boundary H % | Chamfer L1 % | F-score | normal cons. | IoU | validity | components | s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r["status"] != "ok":
            err = r["error"].replace("|", "/")
            out.append(f"| {r['mesh']} | {r['K']} | {r['method']} | failed: {err[:160]} | | | | | | | | | | |")
            continue
        size = r["size"] + (" (the input: within the budget)" if "not decimated" in (r.get("notes") or "") else "")
        out.append(
            f"| {r['mesh']} | {r['K']} | {r['method']} | {size} | {r['bytes']:,} | {fmt(r['hausdorff_hi_pct'], '.3f')} | "
            f"{fmt(r.get('boundary_hausdorff_pct'), '.3f')} | {fmt(r['chamfer_l1_pct'], '.4f')} | {fmt(r['fscore'], '.3f')} | {fmt(r['normal_consistency'], '.3f')} | "
            f"{fmt(r['iou'], '.3f')} | {validity(r)} | {r.get('components', '')} | {seconds(r)} |"
        )
    return "\n".join(out)


def median(xs):
    xs = [x for x in xs if x is not None and not (isinstance(x, float) and math.isnan(x))]
    return statistics.median(xs) if xs else None


def summary(rows, methods, decimated_only=False):
    """Medians per method (and per K and method) over the (mesh, K) pairs where every method
    succeeded, so each median is over the same inputs; plus success counts over all runs.
    decimated_only: only the pairs whose input is larger than the budget (where QEM had to
    decimate; elsewhere it returns the input itself, with zero error)."""
    by = {}
    for r in rows:
        by.setdefault((r["mesh"], r["K"]), {})[r["method"]] = r
    common = [k for k, v in by.items() if all(v.get(m, {}).get("status") == "ok" for m in methods)]
    if decimated_only:
        common = [k for k in common if "not decimated" not in (by[k].get("qem", {}).get("notes") or "")]
    rows = [r for r in rows if not decimated_only or (r["mesh"], r["K"]) in common]
    Ks = sorted({r["K"] for r in rows})
    what = "decimated by QEM (input larger than the budget) and where " if decimated_only else "where "
    lines = [
        f"Medians over the {len(common)} (mesh, K) pairs {what}all of {', '.join(methods)} succeeded; "
        "`ok` counts successful runs; `valid` counts closed, manifold, self-intersection-free outputs among them.",
        "",
        "| K | method | ok | valid | Hausdorff hi % | Chamfer L1 % | F-score | normal cons. | IoU | s |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for K in [None] + Ks:
        for m in methods:
            allr = [r for r in rows if r["method"] == m and (K is None or r["K"] == K)]
            ok = [r for r in allr if r["status"] == "ok"]
            valid = sum(1 for r in ok if validity(r) == "valid")
            sel = [by[k][m] for k in common if K is None or k[1] == K]
            med = {f: median([r.get(f) for r in sel]) for f in
                   ("hausdorff_hi_pct", "chamfer_l1_pct", "fscore", "normal_consistency", "iou", "seconds")}
            lines.append(
                f"| {'all' if K is None else K} | {m} | {len(ok)}/{len(allr)} | {valid}/{len(ok)} | {fmt(med['hausdorff_hi_pct'], '.3f')} | "
                f"{fmt(med['chamfer_l1_pct'], '.4f')} | {fmt(med['fscore'], '.3f')} | {fmt(med['normal_consistency'], '.3f')} | "
                f"{fmt(med['iou'], '.3f')} | {fmt(med['seconds'], '.1f')} |"
            )
    return "\n".join(lines)


def write_outputs(a, rows, methods, renders, header):
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "quality_results.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            rel = dict(r)
            if rel.get("output"):
                try:
                    rel["output"] = os.path.relpath(rel["output"], a.work)
                except ValueError:
                    pass
            w.writerow(rel)
    md = [
        "# Surface-quality benchmark results",
        "",
        header,
        "",
        "## Summary",
        "",
        summary(rows, methods),
        "",
        "Only the inputs that do not fit the budget as they are:",
        "",
        summary(rows, methods, decimated_only=True) if "qem" in methods else "(QEM not run)",
        "",
        "## All runs",
        "",
        "Hausdorff: upper end of the certified interval; Hausdorff and Chamfer L1 in % of the input's "
        "bounding-box diagonal; F-score at 0.3% of the diagonal; bytes: storage of the representation "
        "(sites: 12 K + K/8; marching cubes: float32 grid; QEM: 12 V + 12 F); s: wall seconds of the method "
        "without the `eval` run (ours: the report's total_seconds, which include its own 1M-sample evaluation; "
        "in parentheses load + sampling + training + crust). The machine is shared with other builds: times vary 2x.",
        "",
        table_rows(rows),
    ]
    if renders:
        md += ["", "## Renders", ""]
        for title, p in renders:
            md.append(f"{title}:\n\n![{title}]({os.path.relpath(p, out)})\n")
    (out / "quality_results.md").write_text("\n".join(md) + "\n")


def do_renders(a, specs, rows, methods):
    import render

    out = Path(a.out) / "quality_renders"
    out.mkdir(parents=True, exist_ok=True)
    Ks = sorted({r["K"] for r in rows})
    K = a.render_k or (max(Ks) if Ks else None)
    names = [n for n in (a.render.split(",") if a.render else RENDER_DEFAULT) if n in {s.name for s in specs}]
    ok = {(r["mesh"], r["K"], r["method"]): r for r in rows if r["status"] == "ok"}
    done, pairs = [], []
    for s in specs:
        if s.name not in names:
            continue
        paths, labels = [s.path], ["input"]
        for m in methods:
            r = ok.get((s.name, K, m))
            if r:
                paths.append(r["output"])
                labels.append(f"{m} ({fmt(r['hausdorff_hi_pct'], '.2f')}% H)")
        if len(paths) < 2:
            continue
        p = out / f"{s.name}_K{K}.png"
        t = time.perf_counter()
        render.render_columns(paths, labels, p, up=s.up, title=f"{s.name}, K = {K}")
        print(f"  rendered {p} ({time.perf_counter() - t:.1f} s)")
        done.append((f"{s.name}, K = {K}: input and every method (front, side, top)", p))
        if ok.get((s.name, K, "ours")):
            pairs.append((s.path, ok[(s.name, K, "ours")]["output"], s.name, s.up))
    if pairs:
        p = out / f"grid_ours_K{K}.png"
        render.render_grid(pairs, p, views=("front", "side"))
        print(f"  rendered {p}")
        done.insert(0, (f"Input against ours (K = {K}), front and side", p))
    return done


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", help=f"comma-separated names (default all: {','.join(qm.BY_NAME)})")
    ap.add_argument("--sites", default="2048,8192,32768", help="comma-separated K values")
    ap.add_argument("--methods", default=",".join(METHODS), help="subset of " + ",".join(METHODS))
    ap.add_argument("--quick", action="store_true", help=f"meshes {','.join(qm.QUICK)} and K = 2048 only")
    ap.add_argument("--bin", default=str(TARGET / "ci" / "voronoi-fit"), help="voronoi-fit for eval, crust, query, convert")
    ap.add_argument("--ours-bin", help="voronoi-fit for the ours runs (default --bin)")
    ap.add_argument("--ours-args", default="", help='extra flags for the ours runs, e.g. "--steps 1200"')
    ap.add_argument("--voromesh-args", default="", help="extra flags for benches/voromesh_ref.py")
    ap.add_argument("--out", default=str(HERE / "results"), help="folder of quality_results.{md,csv} and quality_renders/")
    ap.add_argument("--work", default=str(WORK), help="work files (outputs of every run)")
    ap.add_argument("--reuse", action="store_true", help="reuse earlier results with identical settings")
    ap.add_argument("--cached-only", action="store_true",
                    help="run nothing: tabulate the latest result of every run in the work folder (to merge runs)")
    ap.add_argument("--note", default="", help="a line of text for the header of quality_results.md (left out of the command line shown there)")
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--render", help=f"meshes to render (default {','.join(RENDER_DEFAULT)} where run)")
    ap.add_argument("--render-k", type=int, help="K of the renders (default the largest run)")
    ap.add_argument("--no-render", action="store_true")
    a = ap.parse_args()
    a.ours_bin = a.ours_bin or a.bin
    methods = [m.strip() for m in a.methods.split(",") if m.strip()]
    for m in methods:
        if m not in METHODS:
            ap.error(f"unknown method {m!r}")
    Ks = [2048] if a.quick else [int(k) for k in a.sites.split(",")]
    names = qm.QUICK if a.quick else (a.meshes.split(",") if a.meshes else list(qm.BY_NAME))

    if not a.no_build:
        r = subprocess.run(["cargo", "build", "--profile", "ci", "--bin", "voronoi-fit"], cwd=ROOT)
        if r.returncode != 0:
            print("warning: the build failed; going on with the existing binary", file=sys.stderr)
    for b in {a.bin, a.ours_bin}:
        if not Path(b).exists():
            sys.exit(f"{b} not found: build it with `cargo build --profile ci --bin voronoi-fit`")
    # other people rebuild target/ci while this runs: work on private copies of the binaries
    snap = ROOT / "target" / "quality-cache" / "bin"
    snap.mkdir(parents=True, exist_ok=True)
    copies = {}
    for b in dict.fromkeys([a.bin, a.ours_bin]):
        dst = snap / f"voronoi-fit.{os.getpid()}.{len(copies)}"
        shutil.copy2(b, dst)
        copies[b] = str(dst)
    a.bin, a.ours_bin = copies[a.bin], copies[a.ours_bin]
    a.bin_hash, a.ours_bin_hash = file_hash(a.bin), file_hash(a.ours_bin)
    git = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"], capture_output=True, text=True).stdout.strip()

    # every mesh is prepared (cheap, cached) so that the provenance table is complete
    specs_all = qm.prepare(list(qm.BY_NAME), a.bin)
    infos = {s.name: qm.mesh_info(a.bin, s.path) for s in specs_all}
    print("Meshes:\n" + qm.provenance_markdown(specs_all, infos) + "\n")
    qm.write_provenance(specs_all, infos, HERE / "results" / "QUALITY_MESHES.md")
    specs = [qm.BY_NAME[n] for n in names if n in qm.BY_NAME]
    unknown = [n for n in names if n not in qm.BY_NAME]
    if unknown:
        sys.exit(f"unknown meshes: {', '.join(unknown)}")

    header = (
        f"Command: `python benches/quality.py {' '.join('TEXT' if a.note and x == a.note else shlex.quote(x) for x in sys.argv[1:])}`".rstrip()
        + f"  \nMeshes: {', '.join(names)}; K: {', '.join(map(str, Ks))}; methods: {', '.join(methods)}"
        + (f"; ours-args: `{a.ours_args}`" if a.ours_args else "")
        + (f"  \nTabulated from the work folder at source `{git}`: the results come from earlier runs (see the note)"
           if a.cached_only else f"  \nSource: `{git}` (binary copied at the start of the run)")
        + f"  \nDate: {time.strftime('%Y-%m-%d %H:%M')}; machine: {os.cpu_count()} cores (shared with other builds). "
        "Mesh provenance: [QUALITY_MESHES.md](QUALITY_MESHES.md)."
        + (f"  \n{a.note}" if a.note else "")
    )
    rows = []
    total = len(specs) * len(Ks) * len(methods)
    t_start = time.perf_counter()
    i = 0
    for s in specs:
        for K in Ks:
            for m in methods:
                i += 1
                t = time.perf_counter()
                print(f"[{i}/{total}] {s.name} K={K} {m} ...", end=" ", flush=True)
                r = one_run(a, s, K, m)
                if r is None:
                    print("not run (--cached-only)")
                    continue
                rows.append(r)
                if r["status"] == "ok":
                    print(f"ok {time.perf_counter() - t:.1f} s: Hausdorff {r['hausdorff_hi_pct']:.3f}%, "
                          f"Chamfer {r['chamfer_l1_pct']:.4f}%, F {r['fscore']:.3f}, NC {r['normal_consistency']:.3f}, "
                          f"{validity(r)}", flush=True)
                else:
                    print(f"FAILED {time.perf_counter() - t:.1f} s: {r['error'][:300]}", flush=True)
                write_outputs(a, rows, methods, [], header)  # partial results survive an interruption
    renders = []
    if not a.no_render:
        print("Rendering ...")
        try:
            renders = do_renders(a, specs, rows, methods)
        except Exception:
            traceback.print_exc()
    write_outputs(a, rows, methods, renders, header)
    print()
    print(summary(rows, methods))
    print(f"\nwrote {Path(a.out) / 'quality_results.md'} and .csv in {time.perf_counter() - t_start:.0f} s")
    for c in set(copies.values()):
        os.remove(c)


if __name__ == "__main__":
    main()
