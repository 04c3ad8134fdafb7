#!/usr/bin/env python3
"""No fit fails after its work (issue 51, item 4): the main job over the shared meshes,
and the bundled assets (or, `--real-world`, the real-world benchmark's meshes) × K × seeds, every exit code
recorded. A run that exits 2 (the input's fault, said before any work) is not a failure of
the fit; exit 1, a crash, a timeout or a missing output is.

    python3 benches/sweep.py                         # 12 meshes × 6 K × 5 seeds = 360 fits
    python3 benches/sweep.py --real-world --sites 1024 --seeds 0   # benches/real_world's meshes
    python3 benches/sweep.py --sites 256,512 --seeds 0 --meshes bunny,teapot   # a part

Only the standard library: it calls the prebuilt binary (`target/ci/voronoi-fit`, or
`--bin`) at the defaults except `--sites` and `--seed`, and reads each
report's `solid.rule` and certified Hausdorff distance. Writes `benches/results/sweep.csv`
(one row per fit with the commit it ran at, rewritten after every fit so a killed run keeps
its rows; rows of earlier runs with other keys are kept, `--skip-done` skips the keys
already there), `sweep.md` (the tally) and their provenance sidecars. Seeds are the
outermost loop, so a run stopped early has every mesh at every K for the seeds it finished.
"""
import argparse
import csv
import json
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benches" / "results"
FIELDS = ["mesh", "sites", "seed", "commit", "exit", "status", "seconds", "solid", "hausdorff_pct", "error"]


def meshes():
    """Every mesh of the sweep: name → path."""
    found = {}
    shared = ROOT.parent / "shared" / "meshes"
    for p in sorted(shared.glob("*")):
        if p.suffix.lower() in (".obj", ".stl", ".ply", ".off", ".glb", ".gltf"):
            found[p.stem.split("__")[-1]] = p
    for p in sorted((ROOT / "assets").glob("*.obj")):
        # assets/bunny.obj beside the shared bunny scan: both are fitted, under two names.
        found[p.stem if p.stem not in found else f"assets_{p.stem}"] = p
    return found


def real_world():
    """The real-world benchmark's meshes (`--real-world`): name → path."""
    return {p.stem: p for p in sorted((ROOT / "benches" / "real_world" / "meshes").glob("*"))}


def run_one(binary, path, k, seed, timeout):
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "out.glb"
        t = time.monotonic()
        try:
            p = subprocess.run([binary, str(path), "-o", str(out), "--sites", str(k), "--seed", str(seed), "--quiet"],
                               capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return dict(exit="", status="timeout", seconds=round(time.monotonic() - t, 1), error=f"> {timeout} s")
        row = dict(exit=p.returncode, seconds=round(time.monotonic() - t, 1))
        rep = out.with_suffix(".report.json")
        if p.returncode == 0 and out.exists() and rep.exists():
            r = json.loads(rep.read_text())
            m = r.get("metrics", {})
            h = m.get("hausdorff", {}).get("hi") if isinstance(m, dict) else None
            diag = m.get("reference_diagonal") if isinstance(m, dict) else None
            row.update(status="ok", solid=r["solid"]["rule"],
                       hausdorff_pct=round(100 * h / diag, 4) if h is not None and diag else "")
        elif p.returncode == 2:
            row.update(status="input fault", error=p.stderr.strip().splitlines()[-1][:200] if p.stderr.strip() else "")
        else:
            row.update(status="failed", error=(p.stderr.strip().splitlines() or [""])[-1][:300])
        return row


def write(out, csv_path, done, command, commit):
    """The CSV, the tally (sweep.md) and their provenance sidecars, from every row so far."""
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        w.writerows(done.values())
    rows = list(done.values())
    tally = {}
    for r in rows:
        tally[r["status"]] = tally.get(r["status"], 0) + 1
    bad = [r for r in rows if r["status"] not in ("ok", "input fault")]
    lines = ["# The main job over shared meshes, assets and real-world meshes × K × seeds", "",
             f"`{command.strip()}`. One row per fit in [sweep.csv](sweep.csv).", "",
             "| status | fits |", "|---|---:|"]
    lines += [f"| {s} | {n} |" for s, n in sorted(tally.items())]
    lines += ["", f"Meshes: {len({r['mesh'] for r in rows})}; K: "
              f"{', '.join(str(k) for k in sorted({int(r['sites']) for r in rows}))}; "
              f"fits: {len(rows)}; failed after their work or timed out: {len(bad)}.", ""]
    for r in bad:
        lines.append(f"- {r['mesh']} K={r['sites']} seed={r['seed']}: {r['status']} {r.get('error', '')}")
    (out / "sweep.md").write_text("\n".join(lines) + "\n")
    prov = {"command": command.strip(), "commit": commit, "date": datetime.now(timezone.utc).strftime("%Y-%m-%d"),
            "notes": "prebuilt ci-profile binary (release + debug assertions) on a shared 2-core machine"}
    for p in (csv_path, out / "sweep.md"):
        Path(str(p) + ".provenance.json").write_text(json.dumps(prov, indent=2) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(ROOT / "target" / "ci" / "voronoi-fit"))
    ap.add_argument("--sites", default="256,512,1024,2048,4096,8192")
    ap.add_argument("--seeds", default="0,1,2,3,4")
    ap.add_argument("--real-world", action="store_true", help="the meshes of benches/real_world instead")
    ap.add_argument("--meshes", help="comma-separated names (default: all)")
    ap.add_argument("--timeout", type=float, default=900)
    ap.add_argument("--out", default=str(RESULTS))
    ap.add_argument("--skip-done", action="store_true",
                    help="skip the fits already in the CSV (a run split over several sessions)")
    args = ap.parse_args()
    all_meshes = real_world() if args.real_world else meshes()
    names = args.meshes.split(",") if args.meshes else list(all_meshes)
    unknown = [n for n in names if n not in all_meshes]
    if unknown:
        sys.exit(f"unknown meshes {unknown}; known: {sorted(all_meshes)}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "sweep.csv"
    done = {}
    if csv_path.exists():
        with open(csv_path) as f:
            for r in csv.DictReader(f):
                done[(r["mesh"], int(r["sites"]), int(r["seed"]))] = r
    command = "python3 benches/sweep.py " + " ".join(sys.argv[1:])
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=ROOT).stdout.strip()
    # Seeds outermost, so that a run stopped early has every mesh at every K for the seeds
    # it finished; the CSV, tally and provenance are rewritten after every fit.
    for seed in [int(x) for x in args.seeds.split(",")]:
        for k in [int(x) for x in args.sites.split(",")]:
            for name in names:
                if args.skip_done and (name, k, seed) in done:
                    continue
                row = dict(mesh=name, sites=k, seed=seed, commit=commit)
                row.update(run_one(args.bin, all_meshes[name], k, seed, args.timeout))
                print(row, flush=True)
                done[(name, k, seed)] = row
                write(out, csv_path, done, command, commit)
    write(out, csv_path, done, command, commit)
    rows = list(done.values())
    tally = {}
    for r in rows:
        tally[r["status"]] = tally.get(r["status"], 0) + 1
    bad = [r for r in rows if r["status"] not in ("ok", "input fault")]
    print(f"{len(rows)} fits: {tally}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
