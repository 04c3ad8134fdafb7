#!/usr/bin/env python3
"""Compare the delaunay3 crate with CGAL and scipy on the same point sets.

    python benches/compare_delaunay.py [--only uniform1M,lattice,cospherical]
                                       [--libs delaunay3,cgal,scipy] [--repeats 3]

Setup: `pip install -r benches/requirements-bench.txt` (numpy, scipy, the PyPI `cgal`
bindings 6.0.1), and `cargo build --release -p delaunay3 --example time_raw` (done
automatically unless --no-build; the binary path can be given with --bin).

What is timed, fairly on all sides: only the triangulation. File reading and building
the input (numpy array, CGAL's Python list of Point_3) happen before the clock starts.
  - delaunay3: `Delaunay3::new(&points)` inside examples/time_raw.rs (spatial sort,
    insertion, compaction into the final arrays);
  - CGAL: `Delaunay_triangulation_3().insert(list_of_Point_3)` (its range insertion,
    which spatially sorts too), Epick kernel as shipped by the bindings;
  - scipy: `scipy.spatial.Delaunay(points)` (Qhull).
CPU seconds are the process's user+system time over that call (all single-threaded);
memory is the peak-RSS growth over that call divided by the number of points. Each
measurement runs in a fresh subprocess; with --repeats > 1 the minimum CPU time is kept
(repeats are skipped for scipy on sets over 100k points and after any run over 20 CPU s). Prints a table with ratios to
CGAL.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def status_kib(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key):
                return int(line.split()[1])
    return 0


# ---------------------------------------------------------------- point sets
def uniform(n, seed=12345):
    return np.random.default_rng(seed).random((n, 3))


def lattice(k=30):
    g = np.arange(k, dtype=np.float64)
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)


def cospherical(r2=11_895_939, count=20_000, seed=42):
    """`count` integer points exactly on x²+y²+z² = r2 (enumerated exactly)."""
    r = int(np.sqrt(r2)) + 1
    sols = []
    ys = np.arange(-r, r + 1, dtype=np.int64)
    for x in range(-r, r + 1):
        rz = r2 - x * x - ys * ys
        ok = rz >= 0
        y, rz = ys[ok], rz[ok]
        z = np.round(np.sqrt(rz)).astype(np.int64)
        hit = z * z == rz
        for yy, zz in zip(y[hit], z[hit]):
            sols.append((x, yy, zz))
            if zz != 0:
                sols.append((x, yy, -zz))
    sols = np.array(sorted(sols), dtype=np.int64)
    assert (sols**2).sum(1).tolist() == [r2] * len(sols)
    pick = np.random.default_rng(seed).choice(len(sols), size=count, replace=False)
    return sols[np.sort(pick)].astype(np.float64)


DATASETS = {
    "uniform1M": lambda: uniform(1_000_000),
    "lattice": lambda: lattice(30),
    "cospherical": lambda: cospherical(),
}


# ---------------------------------------------------------------- workers
def worker(lib, path):
    points = np.load(path)
    if lib == "cgal":
        from CGAL.CGAL_Kernel import Point_3
        from CGAL.CGAL_Triangulation_3 import Delaunay_triangulation_3

        pts = [Point_3(float(x), float(y), float(z)) for x, y, z in points]
        t = Delaunay_triangulation_3()
        rss0 = status_kib("VmRSS:")
        c0, w0 = time.process_time(), time.perf_counter()
        t.insert(pts)
        c1, w1 = time.process_time(), time.perf_counter()
        cells = t.number_of_finite_cells()
    elif lib == "scipy":
        from scipy.spatial import Delaunay

        rss0 = status_kib("VmRSS:")
        c0, w0 = time.process_time(), time.perf_counter()
        d = Delaunay(points)
        c1, w1 = time.process_time(), time.perf_counter()
        cells = len(d.simplices)
    else:
        raise SystemExit(f"unknown library {lib}")
    hwm = status_kib("VmHWM:")
    print(json.dumps({"cpu_seconds": c1 - c0, "wall_seconds": w1 - w0, "num_finite_tets": int(cells),
                      "peak_rss_growth_bytes": max(0, hwm - rss0) * 1024}))


def measure(lib, npy, raw, binary):
    if lib == "delaunay3":
        out = subprocess.run([str(binary), str(raw)], capture_output=True, text=True, check=True).stdout
    else:
        out = subprocess.run([sys.executable, __file__, "--worker", lib, str(npy)],
                             capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--worker", nargs=2, metavar=("LIB", "NPY"), help=argparse.SUPPRESS)
    ap.add_argument("--only", default=",".join(DATASETS))
    ap.add_argument("--libs", default="delaunay3,cgal,scipy")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--bin", type=Path, default=None, help="path of the time_raw example binary")
    ap.add_argument("--no-build", action="store_true")
    a = ap.parse_args()
    if a.worker:
        return worker(*a.worker)

    libs = a.libs.split(",")
    binary = a.bin
    if "delaunay3" in libs and binary is None:
        target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
        binary = target / "release" / "examples" / "time_raw"
        if not a.no_build:
            subprocess.run(["cargo", "build", "--release", "-q", "-p", "delaunay3", "--example", "time_raw"],
                           cwd=ROOT, check=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.only.split(","):
            pts = np.ascontiguousarray(DATASETS[name](), dtype="<f8")
            npy, raw = Path(tmp) / f"{name}.npy", Path(tmp) / f"{name}.f64"
            np.save(npy, pts)
            pts.tofile(raw)
            res = {}
            for lib in libs:
                reps = 1 if (lib == "scipy" and len(pts) > 100_000) else a.repeats
                runs = []
                for _ in range(reps):
                    runs.append(measure(lib, npy, raw, binary))
                    if runs[-1]["cpu_seconds"] > 20:  # slow enough that one run is telling
                        break
                res[lib] = min(runs, key=lambda r: r["cpu_seconds"])
                print(f"  {name:12s} {lib:10s} {res[lib]}", file=sys.stderr, flush=True)
            rows.append((name, len(pts), res))

    print(f"\n{'set':12s} {'points':>9s} {'library':10s} {'CPU s':>8s} {'wall s':>8s} "
          f"{'vs CGAL':>8s} {'B/point':>8s} {'finite tets':>12s}")
    for name, n, res in rows:
        base = res.get("cgal", {}).get("cpu_seconds")
        for lib, r in res.items():
            ratio = f"{r['cpu_seconds'] / base:7.2f}x" if base else "     n/a"
            print(f"{name:12s} {n:9d} {lib:10s} {r['cpu_seconds']:8.3f} {r['wall_seconds']:8.3f} {ratio:>8s} "
                  f"{r['peak_rss_growth_bytes'] / n:8.0f} {r['num_finite_tets']:12d}")
    print(f"\nmachine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
