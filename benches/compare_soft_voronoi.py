#!/usr/bin/env python3
"""One soft-Voronoi training step, sparse (this project) against dense (numpy), same size.

The step is the reconstruction term's loss E|O - V| and its gradient with respect to the
sites: V(x) = sum_k lambda_k softmax_k(-beta |x - p_k|), beta = 10,000. The dense version
forms the N x K distance matrix (in chunks of samples, to bound memory) as a PyTorch or
numpy implementation of the paper would. Both run in this process's run, on this machine;
the ratio is what the README reports.

    python3 benches/compare_soft_voronoi.py [--k 4096] [--n 65536] [--dense-repeats 2]

Needs numpy (benches/requirements-bench.txt) and builds the Rust example in release.
"""
import argparse
import json
import os
import subprocess
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def ball(p):
    return np.linalg.norm(p - 0.5, axis=1) < 0.35


def dense_step(sites, labels, points, occ, beta, chunk=4096):
    lam = labels.astype(np.float64)
    grad = np.zeros_like(sites)
    loss = 0.0
    n = len(points)
    p2 = (sites * sites).sum(1)
    for s in range(0, n, chunk):
        x = points[s:s + chunk]
        o = occ[s:s + chunk]
        # |x - p|^2 = |x|^2 + |p|^2 - 2 x.p through BLAS, as torch.cdist does.
        d = np.sqrt(np.maximum((x * x).sum(1)[:, None] + p2[None, :] - 2.0 * (x @ sites.T), 0.0))  # (c, K)
        z = -beta * (d - d.min(axis=1, keepdims=True))
        w = np.exp(z)
        w /= w.sum(axis=1, keepdims=True)
        v = w @ lam
        loss += np.where(o, 1.0 - v, v).sum()
        sign = np.where(o, -1.0, 1.0) / n
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (sign[:, None] * w * (lam[None, :] - v[:, None]) * (-beta)) / d
        a[~np.isfinite(a)] = 0.0
        grad += a.sum(axis=0)[:, None] * sites - a.T @ x
    return loss / n, grad


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--k", type=int, default=4096)
    ap.add_argument("--n", type=int, default=65536)
    ap.add_argument("--beta", type=float, default=10000.0)
    ap.add_argument("--dense-repeats", type=int, default=2)
    ap.add_argument("--sparse-repeats", type=int, default=20)
    args = ap.parse_args()

    subprocess.run(["cargo", "build", "--release", "-q", "-p", "soft-voronoi", "--example", "kernel_step_timing"],
                   cwd=ROOT, check=True)
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    exe = os.path.join(target, "release", "examples", "kernel_step_timing")
    out = subprocess.run([exe, str(args.k), str(args.n), str(args.sparse_repeats), str(args.beta)],
                         check=True, capture_output=True, text=True).stdout
    sparse = json.loads(out)

    rng = np.random.default_rng(1)
    sites = rng.random((args.k, 3))
    points = rng.random((args.n, 3))
    labels, occ = ball(sites), ball(points)
    times = []
    for _ in range(args.dense_repeats):
        t = time.perf_counter()
        loss, _ = dense_step(sites, labels, points, occ, args.beta)
        times.append(time.perf_counter() - t)
    dense = min(times)
    ratio = dense / sparse["median_seconds"]
    print(json.dumps({
        "k": args.k, "n": args.n, "beta": args.beta,
        "sparse_seconds_per_step": sparse["median_seconds"], "sparse_threads": sparse["threads"],
        "dense_numpy_seconds_per_step": dense, "dense_loss": loss, "sparse_loss": sparse["loss"],
        "numpy": np.__version__, "ratio_dense_over_sparse": ratio,
    }, indent=2))


if __name__ == "__main__":
    main()
