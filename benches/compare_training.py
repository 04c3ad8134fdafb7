#!/usr/bin/env python3
"""Training variants of the main job, measured on the bundled bunny and sphere.

Runs `voronoi-fit MESH` once per variant (initialisation, preset, beta annealing, the
signed-distance and centroidal regularisers) and prints a markdown table of the
misclassification on 1M fresh samples (the report's figure), the crust's size and the
wall time. The README's training table comes from this script:

    python3 benches/compare_training.py [--meshes assets/bunny.obj assets/icosphere.obj]

Builds the binary in release first.
"""
import argparse
import json
import os
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

VARIANTS = [
    ("default (surface pairs)", []),
    ("--init samples", ["--init", "samples"]),
    ("--init paper", ["--init", "paper"]),
    ("--preset paper", ["--preset", "paper"]),
    ("default + β annealing from 1,000", ["--beta-start", "1000"]),
    ("default + signed distance 1e-3", ["--w-sdf", "1e-3"]),
    ("default + centroidal 1e-3", ["--w-centroidal", "1e-3"]),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", nargs="+", default=["assets/bunny.obj", "assets/icosphere.obj"])
    ap.add_argument("--only", nargs="*", help="substrings of variant names to run")
    args = ap.parse_args()
    subprocess.run(["cargo", "build", "--release", "-q"], cwd=ROOT, check=True)
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    exe = os.path.join(target, "release", "voronoi-fit")
    print("| mesh | variant | misclassified (uniform / near-surface) | crust triangles | train s | total s |")
    print("|---|---|---|---|---|---|")
    for mesh in args.meshes:
        for name, extra in VARIANTS:
            if args.only and not any(o in name for o in args.only):
                continue
            with tempfile.TemporaryDirectory() as d:
                out = os.path.join(d, "fit.glb")
                t = time.perf_counter()
                r = subprocess.run([exe, os.path.join(ROOT, mesh), "-o", out, "--quiet", "--json", *extra],
                                   capture_output=True, text=True)
                wall = time.perf_counter() - t
                if r.returncode != 0:
                    print(f"| {os.path.basename(mesh)} | {name} | failed: {r.stderr.strip()} | | | |")
                    continue
                rep = json.loads(r.stdout)
                q = rep["quality"]
                print(f"| {os.path.basename(mesh)} | {name} | {100 * q['misclassification']:.3f}% "
                      f"({100 * q['misclassification_uniform']:.3f}% / {100 * q['misclassification_near_surface']:.3f}%) "
                      f"| {rep['crust']['num_triangles']:,} | {rep['timings_seconds']['train']:.1f} | {wall:.1f} |",
                      flush=True)


if __name__ == "__main__":
    main()
