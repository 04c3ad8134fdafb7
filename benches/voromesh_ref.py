#!/usr/bin/env python3
"""VoroMesh-style direct fit (Maruani, Klokov, Ovsjanikov, Alliez, Desbrun, "VoroMesh:
Learning Watertight Surface Meshes with Voronoi Diagrams", ICCV 2023), a numpy/scipy
reference for the surface-quality benchmark. Writes a sites file that `voronoi-fit crust`
reads, so the surface is extracted by the project's exact crust:

    target/bench-venv/bin/python benches/voromesh_ref.py MESH.obj --sites 8192 -o OUT.sites.npz
    target/voronoi-fit crust OUT.sites.npz -o OUT.glb

(`quality.py` runs both.) `--selftest` checks the analytic gradient against finite
differences.

What it does, following the paper's direct optimisation (section 4.1) and its public code
(read, not copied; PyTorch there, numpy here):

 1. normalise the mesh into [-0.9, 0.9]^3 (centre of the bounding box, largest half-extent
    0.9; the generators live in [-1, 1]^3);
 2. sample the surface uniformly by area (numpy, seeded): S = 100,000 points by default.
    The paper's code uses 150 n^2 for a grid of n nodes per axis (`--samples 0`), which is
    0.3-2 million at K = 8k-32k or on meshes that fill little of their box, and costs
    minutes per fit here (each step queries 20% of them); 100k is about that density at
    K ~ 2k;
 3. initial generators: the nodes of a regular grid over [-1, 1]^3 that are corners of a
    cell holding at least one sample. The grid spacing is chosen by bisection so that the
    number of generators is as close to K as a grid allows (the exact count is reported;
    typically within 1% of K);
 4. minimise the VoroLoss with Adam (lr 5e-3, betas 0.9/0.999, the paper code's step
    schedule: halved after steps 80, 150, 200 and 250), 400 steps, each on a random 20% of
    the samples, generators clamped to [-1, 1]^3 after every step. VoroLoss of a sample x
    with nearest generator p_i: the squared distance from x to the boundary of p_i's
    Voronoi cell, approximated by the smallest squared distance to the bisector planes of
    p_i and its 10 next-nearest generators p_j:
        d_j = (x - (p_i + p_j)/2) . (p_j - p_i)/|p_j - p_i|,   loss = mean_x min_j d_j^2.
    The kNN (scipy cKDTree) is recomputed every step and held fixed for the gradient (as
    the paper does); the gradient is analytic (see `voroloss`). The loss does not use
    labels: it only pulls Voronoi faces onto the samples;
 5. label every generator by the generalised winding number of the mesh at the generator
    (libigl fast winding number; inside where |w| >= 0.5, the project's inside rule).
    `--label barycenter` uses the mean of each cell's Voronoi vertices instead, as the
    paper's code does (scipy Voronoi; cells reaching infinity fall back to the generator);
 6. write the sites file: sites (K,3) float64 in the unit cube strictly inside (0,1)^3,
    labels (K,) uint8, transform (4,4) back to the mesh frame, format_version [1].
"""
import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from quality_meshes import load_mesh  # noqa: E402

KNN = 11  # the nearest generator and 10 neighbours, as the paper's code (kedge = 10)
MILESTONES = (80, 150, 200, 250)  # the paper code's MultiStepLR, gamma 0.5
SAMPLES_FAC = 150
DEFAULT_SAMPLES = 100_000


def normalise(V, extent=0.9):
    """center, scale with (V - center) / scale in [-extent, extent]^3."""
    center = (V.max(0) + V.min(0)) / 2
    scale = np.abs(V - center).max() / extent
    return center, scale


def sample_surface(V, F, n, seed):
    """n points uniform by area on the triangles (degenerate triangles get none)."""
    rng = np.random.default_rng(seed)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    tri = rng.choice(len(F), size=n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    u, v, w = 1 - s, s * (1 - r2), s * r2
    return u[:, None] * a[tri] + v[:, None] * b[tri] + w[:, None] * c[tri]


def grid_generators(X, n):
    """Nodes of the grid with spacing 2/(n-1) over [-1, 1]^3 (n real >= 2) that are corners of
    cells holding a sample of X."""
    h = 2.0 / (n - 1)
    m = int(np.floor(2.0 / h + 1e-9))  # cells per axis
    c = np.clip(np.floor((X + 1) / h).astype(np.int64), 0, m - 1)
    M = m + 1  # nodes per axis; a node (i, j, k) has the key (i M + j) M + k
    cell = np.unique((c[:, 0] * M + c[:, 1]) * M + c[:, 2])
    offsets = np.array([(i * M + j) * M + k for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    key = np.unique((cell[:, None] + offsets[None, :]).ravel())
    ijk = np.column_stack([key // (M * M), (key // M) % M, key % M])
    return -1.0 + ijk * h


def choose_grid(X, K, iters=30):
    """The real n whose generator count is closest to K (bisection on the monotone count)."""
    lo, hi = 2.0, 4.0
    while len(grid_generators(X, hi)) < K and hi < 4096:
        lo, hi = hi, hi * 2
    best = None
    for _ in range(iters):
        mid = (lo + hi) / 2
        c = len(grid_generators(X, mid))
        if best is None or abs(c - K) < abs(best[1] - K):
            best = (mid, c)
        if c == K:
            break
        if c < K:
            lo = mid
        else:
            hi = mid
    for n in (lo, hi):
        c = len(grid_generators(X, n))
        if abs(c - K) < abs(best[1] - K):
            best = (n, c)
    return best[0]


def voroloss(P, X, knn=KNN):
    """VoroLoss of samples X against generators P and its analytic gradient dL/dP.

    For sample x, nearest generator p_i and neighbour p_j: e = p_j - p_i, L = |e|, u = e/L,
    r = x - (p_i + p_j)/2, d = r . u. With t = (r - d u)/L (the change of u):
        dd/dp_j = -u/2 + t,   dd/dp_i = -u/2 - t,
    and the loss min_j d_j^2, averaged over the samples, takes 2 d dd/dp at the argmin j.
    """
    _, idx = cKDTree(P).query(X, k=knn, workers=-1)
    pi = P[idx[:, 0]]
    pj = P[idx[:, 1:]]
    e = pj - pi[:, None, :]
    L = np.maximum(np.linalg.norm(e, axis=2), 1e-12)
    u = e / L[..., None]
    r = X[:, None, :] - 0.5 * (pi[:, None, :] + pj)
    d = np.einsum("nkc,nkc->nk", r, u)
    j = np.argmin(d * d, axis=1)
    rows = np.arange(len(X))
    dj, uj, Lj, rj = d[rows, j], u[rows, j], L[rows, j], r[rows, j]
    n = len(X)
    loss = float(np.mean(dj * dj))
    t = (rj - dj[:, None] * uj) / Lj[:, None]
    coef = (2.0 / n) * dj[:, None]
    gj = coef * (-0.5 * uj + t)
    gi = coef * (-0.5 * uj - t)
    G = np.zeros_like(P)
    ii, jj = idx[:, 0], idx[rows, 1 + j]
    for c in range(3):
        G[:, c] = np.bincount(ii, gi[:, c], minlength=len(P)) + np.bincount(jj, gj[:, c], minlength=len(P))
    return loss, G


def labels_at(V, F, Q):
    import igl

    w = igl.fast_winding_number(np.ascontiguousarray(V), np.ascontiguousarray(F), np.ascontiguousarray(Q))
    return (np.abs(w) >= 0.5).astype(np.uint8)


def barycenters(P):
    """Mean of each generator's Voronoi vertices (the paper code's labelling points); the
    generator itself where its cell reaches infinity. Eight corner points at (+-1)^3 bound
    most cells, as in the paper's code."""
    from scipy.spatial import Voronoi

    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
    vor = Voronoi(np.vstack([P, signs]))
    out = P.copy()
    for g in range(len(P)):
        reg = vor.regions[vor.point_region[g]]
        if reg and -1 not in reg:
            out[g] = vor.vertices[reg].mean(0)
    return out


def fit(V, F, K, steps=400, lr=5e-3, batch_fraction=0.2, samples=None, seed=0, label="generator", log=None):
    """Fit; return (sites in [-1,1]^3, labels, center, scale, info dict)."""
    t0 = time.perf_counter()
    center, scale = normalise(V)
    Vn = (V - center) / scale
    if samples is None:
        S = DEFAULT_SAMPLES
    elif samples == 0:  # the paper code's rule: samples_fac n^2 for a grid of n nodes per axis
        n0 = choose_grid(sample_surface(Vn, F, DEFAULT_SAMPLES, seed), K)
        S = max(DEFAULT_SAMPLES, int(SAMPLES_FAC * round(n0) ** 2))
    else:
        S = samples
    X = sample_surface(Vn, F, S, seed + 1)
    n = choose_grid(X, K)
    P = grid_generators(X, n)
    rng = np.random.default_rng(seed + 2)
    m, v = np.zeros_like(P), np.zeros_like(P)
    b1, b2, eps = 0.9, 0.999, 1e-8
    first = last = None
    for step in range(1, steps + 1):
        lr_t = lr * 0.5 ** sum(step > s for s in MILESTONES)
        batch = X[rng.random(len(X)) < batch_fraction]
        loss, G = voroloss(P, batch)
        m = b1 * m + (1 - b1) * G
        v = b2 * v + (1 - b2) * G * G
        P = P - lr_t * (m / (1 - b1**step)) / (np.sqrt(v / (1 - b2**step)) + eps)
        np.clip(P, -1.0, 1.0, out=P)
        first = loss if first is None else first
        last = loss
        if log and (step == 1 or step % 50 == 0 or step == steps):
            log(f"  step {step:4d}  VoroLoss {loss:.3e}  lr {lr_t:.1e}")
    t_opt = time.perf_counter() - t0
    Q = P if label == "generator" else barycenters(P)
    lab = labels_at(Vn, F, Q)
    info = {
        "sites": int(len(P)), "inside": int(lab.sum()), "grid_n": float(n), "grid_spacing_normalised": 2 / (n - 1),
        "samples": int(S), "steps": steps, "lr": lr, "batch_fraction": batch_fraction, "label": label,
        "loss_first": first, "loss_last": last, "seconds_optimise": t_opt, "seconds": time.perf_counter() - t0,
    }
    return P, lab, center, scale, info


def write_sites(path, P, labels, center, scale):
    """Sites file in the project's format (README, "The sites file")."""
    eps = 1e-7
    U = np.clip((P + 1) / 2, eps, 1 - eps)
    T = np.eye(4)
    T[:3, :3] *= 2 * scale
    T[:3, 3] = center - scale
    with open(path, "wb") as f:
        np.savez(f, sites=U.astype(np.float64), labels=labels.astype(np.uint8), transform=T,
                 format_version=np.array([1], dtype=np.int64))


def selftest():
    rng = np.random.default_rng(0)
    P = rng.uniform(-1, 1, (60, 3))
    X = rng.uniform(-1, 1, (200, 3))
    loss, G = voroloss(P, X)
    _, idx = cKDTree(P).query(X, k=KNN)
    worst = 0.0
    for g in range(len(P)):
        for c in range(3):
            # finite differences with the kNN held fixed (as the gradient is), so the
            # assignment of samples to cells does not jump
            def f(delta):
                Q = P.copy()
                Q[g, c] += delta
                pi, pj = Q[idx[:, 0]], Q[idx[:, 1:]]
                e = pj - pi[:, None]
                u = e / np.linalg.norm(e, axis=2)[..., None]
                d = np.einsum("nkc,nkc->nk", X[:, None] - 0.5 * (pi[:, None] + pj), u)
                return np.mean(np.min(d * d, axis=1))
            fd = (f(1e-6) - f(-1e-6)) / 2e-6
            worst = max(worst, abs(fd - G[g, c]))
    print(f"selftest: loss {loss:.4e}, max |analytic - finite difference| = {worst:.2e}")
    return 0 if worst < 1e-6 else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs="?")
    ap.add_argument("-o", "--output", help="sites file (.npz)")
    ap.add_argument("--sites", type=int, default=8192, help="target number of generators K")
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--lr", type=float, default=5e-3)
    ap.add_argument("--batch-fraction", type=float, default=0.2)
    ap.add_argument("--samples", type=int, default=None,
                    help="surface samples (default 100,000; 0: the paper code's max(1e5, 150 n^2), slow for large K)")
    ap.add_argument("--label", choices=["generator", "barycenter"], default="generator")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--selftest", action="store_true")
    a = ap.parse_args()
    if a.selftest:
        return selftest()
    if not a.mesh or not a.output:
        ap.error("MESH and -o are required")
    V, F = load_mesh(a.mesh)
    log = None if a.quiet else (lambda s: print(s, file=sys.stderr))
    P, lab, center, scale, info = fit(V, F, a.sites, a.steps, a.lr, a.batch_fraction, a.samples, a.seed, a.label, log)
    write_sites(a.output, P, lab, center, scale)
    print(json.dumps(info))
    return 0


if __name__ == "__main__":
    sys.exit(main())
