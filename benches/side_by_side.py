#!/usr/bin/env python3
"""The main job beside the VoroMesh-style reference: time ratio and quality of both, per
mesh, from one run of the quality benchmark that ran both methods at the same K.

    target/bench-venv/bin/python benches/quality.py --methods ours,voromesh --sites 8192 --out DIR
    python3 benches/side_by_side.py DIR/quality_results.csv [--K 8192] [--csv OUT.csv]

`seconds` are each method's own wall time in that run (ours: the whole main job, its
metrics included; the reference: its fit and the crust the project extracts from its
sites). `ratio` is reference seconds over ours: above 1, ours is faster. `ours_no_worse`
says whether ours is at least as good on all four measures (certified Hausdorff distance,
Chamfer L1, F-score, normal consistency). Only the standard library is needed.
"""
import argparse
import csv
import statistics
import sys
from pathlib import Path

MEASURES = [("hausdorff_hi_pct", -1), ("chamfer_l1_pct", -1), ("fscore", 1), ("normal_consistency", 1)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", help="quality_results.csv of a run with both methods")
    ap.add_argument("--K", default="8192")
    ap.add_argument("--csv", help="write the table here")
    a = ap.parse_args()
    by = {}
    with open(a.results, newline="") as f:
        for r in csv.DictReader(f):
            if r["K"] == a.K and r["status"] == "ok" and r["method"] in ("ours", "voromesh"):
                by.setdefault(r["mesh"], {})[r["method"]] = r
    rows = []
    for mesh, m in by.items():
        if set(m) != {"ours", "voromesh"}:
            continue
        o, v = m["ours"], m["voromesh"]
        row = {"mesh": mesh, "K": a.K, "ours_s": float(o["seconds"]), "voromesh_s": float(v["seconds"])}
        row["ratio"] = row["voromesh_s"] / row["ours_s"]
        no_worse = True
        for key, sign in MEASURES:
            ov, vv = float(o[key]), float(v[key])
            row[f"ours_{key}"], row[f"voromesh_{key}"] = ov, vv
            no_worse &= sign * (ov - vv) >= 0
        row["ours_no_worse"] = no_worse
        rows.append(row)
    if not rows:
        sys.exit(f"{a.results}: no mesh with both methods at K = {a.K}")
    for r in rows:
        print(
            f"{r['mesh']:>12}: ours {r['ours_s']:6.1f} s, reference {r['voromesh_s']:6.1f} s, ratio {r['ratio']:5.2f}; "
            f"H {r['ours_hausdorff_hi_pct']:.3f} vs {r['voromesh_hausdorff_hi_pct']:.3f} %, "
            f"NC {r['ours_normal_consistency']:.4f} vs {r['voromesh_normal_consistency']:.4f}"
            + ("" if r["ours_no_worse"] else "  (ours worse on one)")
        )
    ratios = [r["ratio"] for r in rows]
    print(
        f"median ratio {statistics.median(ratios):.2f} (min {min(ratios):.2f}, max {max(ratios):.2f}); "
        f"ours no worse on all four on {sum(r['ours_no_worse'] for r in rows)} of {len(rows)}"
    )
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()
