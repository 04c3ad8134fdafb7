#!/usr/bin/env python3
"""Stage times of the main job (`voronoi-fit MESH -o OUT`, default settings) on every mesh
in ../shared/meshes and assets/bunny.obj, optionally beside a baseline binary run on the
same meshes in the same session, with the ratio per stage.

    python3 benches/main_job_times.py [--bin target/release/voronoi-fit]
                                      [--baseline OLD_BINARY] [--meshes a.obj,b.glb]
                                      [--json OUT.json]

Build the binary first (`cargo build --release --bin voronoi-fit`); a baseline is any
other build of it (for instance an older commit built in a git worktree). Stage times are
the report's `timings_seconds` (wall seconds on every core); the misclassification is the
report's, on its fresh evaluation samples, so a speed-up that changes the fit shows there.
Only the standard library is needed.
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "meshes"
STAGES = ["sample", "train", "polish", "crust", "evaluate", "metrics"]


def run(binary, mesh, out_dir):
    out = out_dir / (mesh.stem + ".glb")
    r = subprocess.run([str(binary), str(mesh), "-o", str(out), "--quiet"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{binary} failed on {mesh}: {r.stderr.strip()}")
    report = json.loads(out.with_suffix(".report.json").read_text())
    t = report["timings_seconds"]
    return {
        "total": report["total_seconds"],
        "stages": {s: t.get(s, 0.0) for s in STAGES},
        "misclassification": report["quality"]["misclassification"],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "voronoi-fit"))
    ap.add_argument("--baseline", help="another voronoi-fit binary to time on the same meshes")
    ap.add_argument("--meshes", help="comma-separated mesh paths (default: ../shared/meshes/* and assets/bunny.obj)")
    ap.add_argument("--json", help="write the measurements here")
    ap.add_argument("--resummarize", metavar="JSON", help="only rewrite the summary of a file this script wrote")
    a = ap.parse_args()
    if a.resummarize:
        data = json.loads(Path(a.resummarize).read_text())
        data["summary"] = summary(data["rows"])
        Path(a.resummarize).write_text(json.dumps(data, indent=1))
        return
    if a.meshes:
        meshes = [Path(m) for m in a.meshes.split(",")]
    else:
        meshes = sorted(p for p in SHARED.iterdir() if p.suffix.lower() != ".md") + [ROOT / "assets" / "bunny.obj"]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for mesh in meshes:
            row = {"mesh": mesh.name, "new": run(a.bin, mesh, tmp)}
            if a.baseline:
                row["baseline"] = run(a.baseline, mesh, tmp)
            rows.append(row)
            print(f"{mesh.name}: {row['new']['total']:.1f} s", file=sys.stderr)
    head = "| mesh | total s | " + " | ".join(f"{s} s" for s in STAGES) + " | misclassified |"
    print(head)
    print("|" + "---|" * (len(STAGES) + 3))
    for r in rows:
        n = r["new"]
        b = r.get("baseline")

        def cell(new, old):
            return f"{new:.1f}" if old is None else f"{new:.1f} ({old / max(new, 1e-9):.1f}×)"

        cells = [cell(n["total"], b and b["total"])]
        cells += [cell(n["stages"][s], b and b["stages"][s]) for s in STAGES]
        mis = f"{100 * n['misclassification']:.3f}%"
        if b:
            mis += f" (was {100 * b['misclassification']:.3f}%)"
        print(f"| {r['mesh']} | " + " | ".join(cells) + f" | {mis} |")
    if a.baseline:
        print("\nIn parentheses: baseline time / new time (> 1: faster now).")
    if a.json:
        Path(a.json).write_text(json.dumps(flat(rows), indent=1))


def flat(rows):
    """The JSON file: `rows` with one flat row per mesh (`total_s`, `STAGE_s` and, beside a
    baseline, `baseline_total_s`, `baseline_STAGE_s` and the ratios `speedup_total`,
    `speedup_STAGE` = baseline / new), for the docs' figure tables; `runs` as measured."""
    out = []
    for r in rows:
        f = {"mesh": r["mesh"], "total_s": r["new"]["total"], "misclassification": r["new"]["misclassification"]}
        f.update({f"{s}_s": r["new"]["stages"][s] for s in STAGES})
        b = r.get("baseline")
        if b:
            f["baseline_total_s"] = b["total"]
            f["speedup_total"] = b["total"] / max(r["new"]["total"], 1e-9)
            for s in STAGES:
                f[f"baseline_{s}_s"] = b["stages"][s]
                f[f"speedup_{s}"] = b["stages"][s] / max(r["new"]["stages"][s], 1e-9)
            f["baseline_misclassification"] = b["misclassification"]
        out.append(f)
    return {"rows": out, "summary": summary(out), "runs": rows}


def summary(flat_rows):
    """Median and largest total seconds over the meshes, of the new build and the baseline."""
    def of(field):
        v = sorted(r[field] for r in flat_rows if field in r)
        if not v:
            return None
        n = len(v)
        return {"median": (v[(n - 1) // 2] + v[n // 2]) / 2, "max": v[-1]}

    out = {"meshes": len(flat_rows)}
    for prefix, field in [("", "total_s"), ("baseline_", "baseline_total_s")]:
        s = of(field)
        if s:
            out[f"{prefix}median_total_s"] = s["median"]
            out[f"{prefix}max_total_s"] = s["max"]
    return out


if __name__ == "__main__":
    main()
