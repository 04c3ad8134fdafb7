#!/usr/bin/env python3
"""Real-world benchmark (issue 51, item 7): messy public meshes (dataset-style soups,
open boxes, sheets, scans with holes, prints) through voronoi-fit's default fit and two
watertight-conversion baselines, all measured by `voronoi-fit eval` against the input.

    python3 -m venv target/bench-venv && target/bench-venv/bin/pip install -r benches/requirements-bench.txt
    target/bench-venv/bin/python benches/real_world.py                      # every mesh, every method
    target/bench-venv/bin/python benches/real_world.py --quick              # 3 small meshes
    target/bench-venv/bin/python benches/real_world.py --meshes truck,offset1 --methods mesh2sdf,pcu

The meshes and their provenance are in benches/real_world/meshes.json (MESHES.md says the
same for people); the open box is generated here (`open_box.obj`: a unit cube without its
bottom face, written when missing). Methods:

- `ours`: `voronoi-fit MESH -o OUT.glb --quiet --json` at the default settings (`--sites`,
  `--fit-args` add arguments), with a timeout (`--timeout`, 600 s);
- `mesh2sdf`: `mesh2sdf.compute(V', F, 128, fix=True, level=2/128, return_mesh=True)` on the
  input mapped into [-0.8, 0.8]^3 as mesh2sdf's README does (centre of the bounding box,
  mesh_scale 0.8), the marching-cubes mesh mapped back to the input's frame;
- `pcu`: point-cloud-utils' `make_mesh_watertight(V, F, resolution)` (Huang et al. 2018,
  "robust watertight manifold") at the resolution that gives about as many triangles as
  ours on that mesh (from this run, or from an earlier run's CSV in --out; 20,000 where
  ours has no output): a first run at half that count, then one more rescaled when it is
  off by more than 25 % (resolution clamped to [1,000, 100,000]; the time is the last
  run's). The resolution used is in the `param` column. The count moves in steps (the
  octree's depth), so it can still land 2-4x from the target: see the `triangles` column.

Each output is measured by `voronoi-fit eval INPUT OUTPUT --json` (certified Hausdorff
`hi`, Chamfer L1 and the F-score at τ = 0.3 % of the input's diagonal, normal
consistency, IoU against the input's winding-number solid, validity of the output). A
method that fails, times out or writes nothing is a row with `status` and `error`; the run
never stops on one mesh. Writes --out/real_world.csv (+ .provenance.json), real_world.md
and real_world_renders/NAME.png (input and each method's output, front and side views,
framed by the input's bounding box; back faces orange). Rows of meshes or methods not run
this time are kept from the CSV already in --out (so runs can be split).
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time
import traceback
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from quality_meshes import load_mesh  # noqa: E402

MESH_DIR = HERE / "real_world" / "meshes"
MESHES_JSON = HERE / "real_world" / "meshes.json"
QUICK = ["open_box", "house_shapenet", "halftunnel"]
METHODS = ["ours", "mesh2sdf", "pcu"]
FIELDS = ["mesh", "kind", "method", "status", "error", "param", "wall_s", "eval_s", "triangles",
          "hausdorff_hi_pct", "chamfer_l1_pct", "fscore", "normal_consistency", "iou",
          "valid_solid", "closed", "manifold", "self_intersecting", "components", "output"]


def write_open_box(path):
    """A unit cube without its bottom face (z = 0): 10 triangles, outward facing."""
    V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    F = [(4, 5, 6), (4, 6, 7),  # top
         (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]
    with open(path, "w") as f:
        f.write("# unit cube without its bottom face (benches/real_world.py)\n")
        f.writelines(f"v {x} {y} {z}\n" for x, y, z in V)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)


def run(cmd, timeout):
    t = time.time()
    try:
        p = subprocess.run(["nice", "-n", "19", *cmd], capture_output=True, text=True, timeout=timeout)
        return p.returncode, p.stdout, p.stderr, time.time() - t
    except subprocess.TimeoutExpired as e:
        return "timeout", e.stdout or "", e.stderr or "", time.time() - t


def write_obj(path, V, F):
    with open(path, "w") as f:
        np.savetxt(f, V, fmt="v %.9g %.9g %.9g")
        np.savetxt(f, np.asarray(F, dtype=np.int64) + 1, fmt="f %d %d %d")


def method_ours(binary, mesh, out, args):
    o = out / "ours" / f"{mesh['name']}.glb"
    o.parent.mkdir(parents=True, exist_ok=True)
    if o.exists():
        o.unlink()
    cmd = [binary, str(MESH_DIR / mesh["file"]), "-o", str(o), "--quiet", "--json"]
    if args.sites:
        cmd += ["--sites", str(args.sites)]
    cmd += args.fit_args.split() if args.fit_args else []
    rc, so, se, wall = run(cmd, args.timeout)
    param = f"sites={args.sites}" if args.sites else "default"
    if rc == "timeout":
        return dict(status="timeout", error=f"no output after {args.timeout} s", wall_s=wall, param=param)
    if rc != 0 or not o.exists():
        msg = (se.strip().splitlines() or ["(no message)"])[-1]
        return dict(status="failed", error=f"exit {rc}: {msg}"[:300], wall_s=wall, param=param)
    try:
        rep = json.loads(so)
        k = rep["settings"]["train"]["num_sites"]
        param = f"sites={int(k)}"
        rule = (rep.get("solid") or {}).get("rule")
        if rule:
            param += f" solid={rule}"
    except Exception:
        pass
    return dict(status="ok", wall_s=wall, output=o, param=param)


def method_mesh2sdf(mesh, out, args):
    import mesh2sdf

    V, F = load_mesh(MESH_DIR / mesh["file"])
    size, mesh_scale = 128, 0.8
    lo, hi = V.min(0), V.max(0)
    c = (lo + hi) / 2
    s = 2.0 * mesh_scale / (hi - lo).max()
    t = time.time()
    _, m = mesh2sdf.compute((V - c) * s, F, size, fix=True, level=2.0 / size, return_mesh=True)
    wall = time.time() - t
    o = out / "mesh2sdf" / f"{mesh['name']}.obj"
    o.parent.mkdir(parents=True, exist_ok=True)
    write_obj(o, np.asarray(m.vertices) / s + c, np.asarray(m.faces))
    return dict(status="ok", wall_s=wall, output=o, param="size=128,fix=True")


def method_pcu(mesh, out, args, target):
    """make_mesh_watertight at the resolution that gives about `target` triangles: a first
    run at resolution target / 2, then, when its count is off by more than 25 %, one more
    at the resolution scaled by target / count (the count grows about linearly with it)."""
    import point_cloud_utils as pcu

    V, F = load_mesh(MESH_DIR / mesh["file"])
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int32)
    res = int(min(100_000, max(1_000, target // 2)))
    t = time.time()
    vw, fw = pcu.make_mesh_watertight(V, F, res)
    wall = time.time() - t
    if len(fw) and not (0.75 < len(fw) / target < 1.25):
        res2 = int(min(100_000, max(1_000, res * target / len(fw))))
        if res2 != res:
            res = res2
            t = time.time()
            vw, fw = pcu.make_mesh_watertight(V, F, res)
            wall = time.time() - t
    o = out / "pcu" / f"{mesh['name']}.obj"
    o.parent.mkdir(parents=True, exist_ok=True)
    write_obj(o, vw, fw)
    return dict(status="ok", wall_s=wall, output=o, param=f"resolution={res}")


def evaluate(binary, mesh, row, timeout):
    rc, so, se, wall = run([binary, "eval", str(MESH_DIR / mesh["file"]), str(row["output"]), "--json"], timeout)
    row["eval_s"] = wall
    if rc != 0:
        row["status"] = "eval_failed" if rc != "timeout" else "eval_timeout"
        row["error"] = (f"eval exit {rc}: " + ((se.strip().splitlines() or [""])[-1]))[:300]
        return
    r = json.loads(so)
    d = r["reference_diagonal"]
    row["hausdorff_hi_pct"] = 100 * r["hausdorff"]["hi"] / d
    row["chamfer_l1_pct"] = 100 * r["surface"]["chamfer_l1"] / d
    row["fscore"] = r["surface"]["fscore"]
    row["normal_consistency"] = r["surface"]["normal_consistency"]
    row["iou"] = (r.get("iou") or {}).get("iou")
    v = r.get("prediction_validity") or {}
    row["valid_solid"] = v.get("is_valid_solid")
    row["closed"] = v.get("is_closed")
    row["manifold"] = v.get("is_manifold")
    row["self_intersecting"] = v.get("self_intersecting")
    row["components"] = v.get("num_components")


def triangles_of(path):
    try:
        return len(load_mesh(path)[1])
    except Exception:
        return None


def read_csv(path):
    if not path.exists():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def fmt(x, nd):
    if x in (None, ""):
        return "–"
    try:
        return f"{float(x):.{nd}f}"
    except ValueError:
        return str(x)


def write_md(rows, meshes, path, command):
    order = {m["name"]: i for i, m in enumerate(meshes)}
    rows = sorted(rows, key=lambda r: (order.get(r["mesh"], 999), METHODS.index(r["method"])
                                       if r["method"] in METHODS else 9))
    L = ["# Real-world meshes: ours (default) against mesh2sdf and make_mesh_watertight", "",
         f"`{command}`. Provenance of the meshes: `benches/real_world/MESHES.md`. Distances in % of the",
         "input's bounding-box diagonal (certified Hausdorff upper bound, Chamfer L1); F-score at τ = 0.3 %;",
         "NC = normal consistency; IoU against the input's winding-number solid (|w| ≥ 0.5, meaningless for",
         "sheets); valid = closed, manifold, no self-intersection (`voronoi-fit eval`). Time: wall seconds of",
         "the method alone (not its evaluation), on a 2-core machine shared with other builds.", "",
         "| mesh | kind | method | status | param | triangles | Hausdorff % | Chamfer % | F-score | NC | IoU | valid | s |",
         "|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---|---:|"]
    for r in rows:
        st = r["status"] if r["status"] == "ok" else f"**{r['status']}**"
        valid = {"True": "yes", "False": "no", True: "yes", False: "no"}.get(r.get("valid_solid"), "–")
        L.append(f"| {r['mesh']} | {r['kind']} | {r['method']} | {st} | {r.get('param', '')} | "
                 f"{r.get('triangles') or '–'} | {fmt(r.get('hausdorff_hi_pct'), 2)} | {fmt(r.get('chamfer_l1_pct'), 3)} | "
                 f"{fmt(r.get('fscore'), 3)} | {fmt(r.get('normal_consistency'), 3)} | {fmt(r.get('iou'), 3)} | "
                 f"{valid} | {fmt(r.get('wall_s'), 1)} |")
    by = {(r["mesh"], r["method"]): r for r in rows}
    names = [m["name"] for m in meshes if (m["name"], "ours") in by]
    if names:
        def ahead(k, lower):
            n = 0
            for name in names:
                try:
                    o = float(by[(name, "ours")][k])
                    t = [float(by[(name, b)][k]) for b in ("mesh2sdf", "pcu")]
                except (KeyError, TypeError, ValueError):
                    continue
                n += all(o < x if lower else o > x for x in t)
            return n
        L += ["", f"Ours ahead of both baselines, of {len(names)} meshes: Hausdorff on {ahead('hausdorff_hi_pct', True)}, "
              f"Chamfer on {ahead('chamfer_l1_pct', True)}, normal consistency on {ahead('normal_consistency', False)}, "
              f"F-score on {ahead('fscore', False)} (a failed or timed-out fit counts as behind)."]
    errs = [r for r in rows if r.get("error")]
    if errs:
        L += ["", "Failures:", ""] + [f"- {r['mesh']} / {r['method']}: {r['error']}" for r in errs]
    renders = Path(path).parent / "real_world_renders"
    pics = [m["name"] for m in meshes if (renders / f"{m['name']}.png").exists()]
    if pics:
        L += ["", "## Renders", "", "Input, then each method's output (front and side views, framed by the input's bounding "
              "box; faces seen from behind in orange). What ours gets wrong, mesh by mesh: "
              "`benches/real_world/MESHES.md`.", ""]
        for n in pics:
            L += [f"### {n}", "", f"![{n}](real_world_renders/{n}.png)", ""]
    Path(path).write_text("\n".join(L) + "\n")


def render(mesh, rows, out):
    from render import render_columns

    paths, labels = [MESH_DIR / mesh["file"]], ["input"]
    for m in METHODS:
        r = rows.get(m)
        if r and r.get("output") and Path(r["output"]).exists():
            paths.append(Path(r["output"]))
            h = fmt(r.get("hausdorff_hi_pct"), 1)
            labels.append(f"{m} (H {h} %)")
    d = out / "real_world_renders"
    d.mkdir(parents=True, exist_ok=True)
    render_columns([str(p) for p in paths], labels, d / f"{mesh['name']}.png", up=mesh.get("up", "y"),
                   views=("front", "side"), title=f"{mesh['name']} ({mesh['kind']})", panel=3.0, dpi=80)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", help="comma-separated names (default: all in meshes.json)")
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--out", default=str(HERE / "results"), help="folder of the CSV, table and renders")
    ap.add_argument("--work", default=str(ROOT / "target" / "real-world-runs"), help="folder of the outputs")
    ap.add_argument("--quick", action="store_true", help="only " + ", ".join(QUICK))
    ap.add_argument("--no-build", action="store_true", help="use the binary as it is (this script never builds; "
                    "without --no-build it only checks that the binary exists)")
    ap.add_argument("--bin", default=str(ROOT / "target" / "ci" / "voronoi-fit"))
    ap.add_argument("--sites", type=int, help="--sites of ours (default: the fit's default)")
    ap.add_argument("--fit-args", default="", help="more arguments of ours, one string")
    ap.add_argument("--timeout", type=float, default=600, help="seconds per fit (ours) and per evaluation")
    ap.add_argument("--no-render", action="store_true")
    ap.add_argument("--table-only", action="store_true", help="only rewrite real_world.md from the CSV in --out")
    args = ap.parse_args()
    if args.table_only:
        meshes = json.loads(MESHES_JSON.read_text())["meshes"]
        out = Path(args.out)
        write_md(read_csv(out / "real_world.csv"), meshes, out / "real_world.md",
                 "target/bench-venv/bin/python benches/real_world.py")
        return

    if not Path(args.bin).exists():
        sys.exit(f"{args.bin} is missing: build it (cargo build --profile ci) or pass --bin")
    meshes = json.loads(MESHES_JSON.read_text())["meshes"]
    if not (MESH_DIR / "open_box.obj").exists():
        write_open_box(MESH_DIR / "open_box.obj")
    names = QUICK if args.quick else (args.meshes.split(",") if args.meshes else [m["name"] for m in meshes])
    unknown = set(names) - {m["name"] for m in meshes}
    if unknown:
        sys.exit(f"unknown meshes: {sorted(unknown)}")
    methods = args.methods.split(",")
    out, work = Path(args.out), Path(args.work)
    out.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)
    csv_path = out / "real_world.csv"
    old = read_csv(csv_path)
    done = {(r["mesh"], r["method"]): r for r in old}
    for m in meshes:
        if m["name"] not in names:
            continue
        mesh_rows = {}
        for meth in METHODS:
            if meth not in methods:
                if (m["name"], meth) in done:
                    mesh_rows[meth] = done[(m["name"], meth)]
                continue
            row = dict(mesh=m["name"], kind=m["kind"], method=meth, status="", error="")
            print(f"{m['name']} / {meth} ...", flush=True)
            try:
                if meth == "ours":
                    row.update(method_ours(args.bin, m, work, args))
                elif meth == "mesh2sdf":
                    row.update(method_mesh2sdf(m, work, args))
                elif meth == "pcu":
                    ref = mesh_rows.get("ours") or done.get((m["name"], "ours"))
                    t = ref and ref.get("triangles")
                    row.update(method_pcu(m, work, args, int(t) if t else 20_000))
                else:
                    raise ValueError(f"unknown method {meth}")
            except Exception as e:  # a failure is a row
                row.update(status="failed", error=f"{type(e).__name__}: {e}"[:300])
                traceback.print_exc()
            if row.get("status") == "ok":
                row["triangles"] = triangles_of(row["output"])
                try:
                    evaluate(args.bin, m, row, args.timeout)
                except Exception as e:
                    row.update(status="eval_failed", error=f"{type(e).__name__}: {e}"[:300])
            if row.get("output"):
                row["output"] = os.path.relpath(row["output"], ROOT)
            for k in ("wall_s", "eval_s", "hausdorff_hi_pct", "chamfer_l1_pct", "fscore", "normal_consistency", "iou"):
                if isinstance(row.get(k), float):
                    row[k] = round(row[k], 6 if k not in ("wall_s", "eval_s") else 1)
            print("   ", {k: row.get(k) for k in ("status", "error", "wall_s", "triangles", "hausdorff_hi_pct",
                                                    "chamfer_l1_pct", "fscore", "normal_consistency")}, flush=True)
            mesh_rows[meth] = row
            done[(m["name"], meth)] = row
            rows = list(done.values())
            with open(csv_path, "w", newline="") as f:  # after every row: a killed run keeps its rows
                w = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
                w.writeheader()
                w.writerows(rows)
        if not args.no_render:
            try:
                # Every method's row of this mesh whose output is still there (kept rows of
                # an earlier run too), so a partial rerun keeps all columns of the render.
                kept = {meth: v for (name, meth), v in done.items() if name == m["name"]}
                rr = {k: dict(v, output=(ROOT / v["output"]) if v.get("output") else None) for k, v in kept.items()}
                render(m, rr, out)
            except Exception as e:
                print(f"    render failed: {e}", flush=True)
    rows = list(done.values())
    command = "target/bench-venv/bin/python benches/real_world.py " + " ".join(sys.argv[1:])
    write_md(rows, meshes, out / "real_world.md", command.strip())
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT).stdout.strip()
    prov = {"command": command.strip(), "commit": commit,
            "date": datetime.now(timezone.utc).strftime("%Y-%m-%d"),
            "notes": "Rows of this run and of earlier runs kept in the CSV (see the script's docstring). The "
                     "prebuilt ci-profile binary target/ci/voronoi-fit (release + debug assertions) on the 2-core "
                     "machine shared with other agents' builds: wall seconds are inflated. mesh2sdf 1.1.0, "
                     "point-cloud-utils 0.34.0 (benches/requirements-bench.txt)."}
    for p in (csv_path, out / "real_world.md"):
        Path(str(p) + ".provenance.json").write_text(json.dumps(prov, indent=2) + "\n")
    print(out / "real_world.md")


if __name__ == "__main__":
    main()
