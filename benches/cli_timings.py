#!/usr/bin/env python3
"""Quick timings of three building blocks through their own commands, into one JSON file:

    python3 benches/cli_timings.py [--bin target/ci/voronoi-fit] [--examples target/ci/examples]
                                   [--out benches/results/cli_timings.json]

- Delaunay: `voronoi-fit delaunay POINTS.npy --timings` on 1,000,000 seeded uniform points
  in the unit cube (the triangulation's seconds, excluding file I/O);
- occupancy: `voronoi-fit query assets/bunny.obj POINTS.npy --timings` on 1,000,000 seeded
  uniform points in the bunny's bounding box grown by about 5% (winding numbers and
  closest points, wall and CPU seconds);
- crust: `crust_timing 100000` (the `crust` crate's example: 100,000 uniform sites
  labelled inside a ball of radius 0.35, Delaunay alone against the crust including its
  Delaunay, best of 5 each).

Under a minute of CPU on 2 cores. Only the standard library is needed; the points are
written as .npy by hand. Build first: `cargo build --profile ci --bin voronoi-fit` and
`cargo build --profile ci -p crust --example crust_timing` (or pass release paths).
"""
import argparse
import datetime
import json
import os
import random
import re
import struct
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def write_npy(path, rows):
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 3), }" % len(rows)
    header += " " * (64 - (10 + len(header) + 1) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode())
        f.write(b"".join(struct.pack("<3d", *r) for r in rows))


def timings_line(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads([l for l in r.stderr.splitlines() if l.startswith("{")][-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(ROOT / "target" / "ci" / "voronoi-fit"))
    ap.add_argument("--examples", default=str(ROOT / "target" / "ci" / "examples"))
    ap.add_argument("--out", default=str(ROOT / "benches" / "results" / "cli_timings.json"))
    a = ap.parse_args()
    rng = random.Random(0)
    out = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%MZ"), "bin": os.path.relpath(a.bin, ROOT)}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        pts = tmp / "uniform.npy"
        write_npy(pts, [(rng.random(), rng.random(), rng.random()) for _ in range(1_000_000)])
        out["delaunay_1m_uniform"] = timings_line([a.bin, "delaunay", str(pts), "-o", str(tmp / "t.npy"), "--timings"])
        vs = [list(map(float, l.split()[1:4])) for l in (ROOT / "assets" / "bunny.obj").read_text().splitlines()
              if l.startswith("v ")]
        lo = [min(v[i] for v in vs) for i in range(3)]
        hi = [max(v[i] for v in vs) for i in range(3)]
        pad = [0.05 * (h - l) for l, h in zip(lo, hi)]
        q = tmp / "q.npy"
        write_npy(q, [tuple(l - p + (h - l + 2 * p) * rng.random() for l, h, p in zip(lo, hi, pad))
                      for _ in range(1_000_000)])
        out["query_bunny_1m"] = timings_line([a.bin, "query", str(ROOT / "assets" / "bunny.obj"), str(q),
                                              "-o", str(tmp / "q.npz"), "--timings"])
    line = subprocess.run([str(Path(a.examples) / "crust_timing"), "100000"], capture_output=True, text=True,
                          check=True).stdout.strip()
    m = re.search(r"delaunay ([\d.]+) s, crust \(including its delaunay\) ([\d.]+) s, ratio ([\d.]+), (\d+) triangles", line)
    out["crust_100k_ball"] = {"stdout": line, "delaunay_seconds": float(m.group(1)),
                              "crust_seconds": float(m.group(2)), "ratio": float(m.group(3)),
                              "triangles": int(m.group(4))}
    Path(a.out).write_text(json.dumps(out, indent=2) + "\n")
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
