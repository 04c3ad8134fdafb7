#!/usr/bin/env python3
"""Time and peak memory of the main job against the number of sites K, on one mesh.

    python3 benches/k_scaling.py [--bin target/ci/voronoi-fit] [--mesh assets/bunny.obj]
                                 [--sites 2048,8192,32768,131072] [--args "--preset fast"]
                                 [--json benches/results/k_scaling.json]

Each K runs `voronoi-fit MESH --sites K -o OUT --quiet` once; the stage seconds are the
report's `timings_seconds`, the peak memory is the child's maximum resident set size as
the kernel counts it (`os.wait4`), and the quality is the report's metrics against the
input. Per K it also gives seconds per thousand sites, so near-linear scaling shows as a
flat column. Only the standard library is needed.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STAGES = ["sample", "train", "polish", "crust", "evaluate", "metrics"]


def run(binary, mesh, k, extra, out_dir):
    out = out_dir / f"{mesh.stem}.k{k}.glb"
    cmd = [str(binary), str(mesh), "--sites", str(k), "-o", str(out), "--quiet", *extra]
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    err = p.stderr.read().decode(errors="replace")
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed: {err.strip()}")
    report = json.loads(out.with_suffix(".report.json").read_text())
    t = report["timings_seconds"]
    m = report.get("metrics") or {}
    d = m.get("reference_diagonal")
    surface = m.get("surface") or {}
    row = {
        "K": k,
        "total_s": report["total_seconds"],
        "wall_s": wall,
        "peak_rss_mb": usage.ru_maxrss / 1024.0,
        "s_per_1k_sites": report["total_seconds"] / (k / 1000.0),
        "sites_in_file": report.get("crust", {}).get("num_sites"),
        "crust_triangles": report.get("crust", {}).get("num_triangles"),
    }
    row.update({f"{s}_s": t.get(s, 0.0) for s in STAGES})
    if d:
        row["hausdorff_hi_pct"] = 100.0 * m["hausdorff"]["hi"] / d
        row["chamfer_l1_pct"] = 100.0 * surface["chamfer_l1"] / d
        row["fscore"] = surface["fscore"]
        row["normal_consistency"] = surface["normal_consistency"]
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(ROOT / "target" / "ci" / "voronoi-fit"))
    ap.add_argument("--mesh", default=str(ROOT / "assets" / "bunny.obj"))
    ap.add_argument("--sites", default="2048,8192,32768,131072")
    ap.add_argument("--args", default="", help="extra flags for every run")
    ap.add_argument("--json", help="write the rows here")
    a = ap.parse_args()
    mesh = Path(a.mesh)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in [int(s) for s in a.sites.split(",")]:
            row = run(a.bin, mesh, k, a.args.split(), Path(tmp))
            rows.append(row)
            print(
                f"K={k:>7}: {row['total_s']:7.1f} s ({row['s_per_1k_sites']:.2f} s per 1k sites), "
                f"peak {row['peak_rss_mb']:.0f} MB; "
                + ", ".join(f"{s} {row[s + '_s']:.1f}" for s in STAGES),
                flush=True,
            )
    if a.json:
        Path(a.json).write_text(json.dumps({"mesh": mesh.name, "args": a.args, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
