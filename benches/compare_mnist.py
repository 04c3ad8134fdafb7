"""Training throughput of the MNIST autoencoders (crates/mnist): images per second of a
training step (forward + loss + backward + Adam, lr 1e-3, float32 networks), our Rust
implementation (`voronoi-fit mnist bench`) against the same models in PyTorch on the CPU,
in one run; the ratio ours / PyTorch (> 1: ours is faster).

    python benches/compare_mnist.py [--methods voronoi,occnet128,occnet512,occnet16k]
                                    [--batch 32] [--points 256] [--steps 20] [--repeats 3]
                                    [--threads 2] [--bin target/release/voronoi-fit]
                                    [--data ../shared/mnist] [--json FILE] [--no-torch]
    python benches/compare_mnist.py --self-check      # the PyTorch losses' checks only

The models, the same on both sides:
- encoder (every method): 784 → 1024 → 1024 → 1024 → 1024 → 16, ReLU between; input the
  28 × 28 image / 255, flattened;
- Voronoi: decoder 16 → 1024 → 1024 → 1024 → 256, sites = 0.5 + output as 128 points of the
  unit square, the first 64 labelled inside; loss per image (averaged over the batch) the
  sum of reconstruction mean_x |O(x) − softmax(−β‖x − p‖)·labels| over the P training
  points (β = 100, distances by torch.cdist: B × P × 128), bounds Σ relu(−p) + relu(p − 1),
  10 × signed distance (mean over the sites of the distance of a site on the wrong side of
  the digit to the closest boundary point: torch.cdist to the image's boundary points, then
  min) and 1 × centroidal (mean over the sites of ‖p_i − mean of its Delaunay
  neighbours‖², the Delaunay graph built every step for every image by
  scipy.spatial.Delaunay on the detached sites: what a PyTorch user would write, and what
  the Rust code does too, with an exact Delaunay triangulation per image per step). The
  Rust soft-argmin is sparse (soft-voronoi's kernel: a k-d tree finds the sites within
  τ/β = 0.3 of the nearest one, dropping weights below e^−30 of the largest, which
  changes V by < 1e−11); PyTorch's the dense softmax over all 128 sites;
- OccNet H (H = 128, 512, 16,384): per image, [z (16); point mapped to [−1, 1] (2)] →
  Linear(18, H) → ReLU → Linear(H, 1) → logit, BCE with logits averaged over the points
  and the images. PyTorch does it the natural way: z repeated per point, concatenated,
  one batched Linear over the B·P rows. (The Rust decoder computes W_z z + b₁ once per
  image and streams the points through the hidden layer tile by tile: the same function
  and gradients with less arithmetic; that is part of what is measured.)
Weights are He-uniform (±√(6/fan_in)), biases ±1/√fan_in on both sides (net.rs).

Data: the first B × (steps + 2) training images of `--data` (train10k-images-idx3-ubyte.gz,
or the official train-images-idx3-ubyte.gz; step k uses images kB … kB + B − 1, as `mnist
bench` does). The PyTorch side prepares everything before timing, in numpy: the images
as tensors, each image's boundary points (the midpoints of the pixel edges where the image
thresholded at 128 changes, zero outside, in unit-square coordinates x = (col + ½)/28,
y = (row + ½)/28 for pixel centres) and its P training points (half uniform in [0, 1]²,
half a boundary point plus N(0, (½/28)²) clipped to the square; occupancy the bilinearly
interpolated intensity ≥ ½). Its timed loop does only forward, loss, backward and Adam
on those fixed tensors, plus what a real step needs: the sites' side of the digit (the
thresholded pixel under each site) and the per-image scipy Delaunay of the Voronoi
centroidal term. The Rust timed loop does more per step: it also finds each image's
boundary (crossings of the bilinear intensity on lines every ¼ pixel, roughly 4× as many
points as the pixel edges, searched by brute force for the signed-distance term) and
samples its training points, as training does; so the comparison leans, if anything,
towards PyTorch. The Rust losses are computed in float64 on the sites, PyTorch's in
float32.

Timing: each side builds its model, does 2 untimed warm-up steps and then `--steps` timed
steps; images/s = steps × batch / seconds of the timed steps (Rust: the `seconds` its
JSON reports, which times the same loop, not the process). `--repeats` rounds, each
running, per method, ours and PyTorch once each, in alternating order from round to
round (ours first in odd rounds), so a change in the machine's load affects both alike.
Reported: the median images/s of each over the rounds and the ratio of the medians,
with its range over the per-round ratios. PyTorch runs with
`torch.set_num_threads(--threads)`; the Rust binary with RAYON_NUM_THREADS = --threads
(its JSON reports the thread count it used). PyTorch is skipped with a note when it
cannot be imported.

`--self-check` checks the PyTorch Voronoi loss before any timing: in float64 on one image,
each term against a plain numpy evaluation of its definition and its gradient against
finite differences (torch.autograd.gradcheck, the Delaunay graph held fixed), then 40
training steps on one image (loss finite and falling, by at least 5 %, gradients finite),
and 40 of an OccNet 128 likewise.

PyTorch: PyPI's Linux wheel is the CUDA build and pulls in the nvidia-* wheels (several
GB); it runs on the CPU without a GPU (the CPU-only index is not reachable from these
machines). Install it into a venv of its own (2.15.0 is what this was run with):

    python3 -m venv target/bench-torch
    target/bench-torch/bin/pip install torch==2.15.0 numpy scipy
    target/bench-torch/bin/python benches/compare_mnist.py --json benches/results/mnist_throughput.json
"""
import argparse
import gzip
import json
import os
import platform
import statistics
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import scipy
from scipy.spatial import Delaunay, QhullError

ROOT = Path(__file__).resolve().parents[1]
SIDE = 28
LATENT = 16
WIDTH = 1024
SITES = 128
BETA = 100.0
W_SIGNED = 10.0
W_CENTROIDAL = 1.0
WARMUP = 2
HIDDEN = {"voronoi": None, "occnet128": 128, "occnet512": 512, "occnet16k": 16384, "occnet16384": 16384}


def canonical(m):
    """Method name as the binary's JSON spells it (occnet16k → occnet16384)."""
    if m not in HIDDEN:
        sys.exit(f"unknown method {m!r} (expected voronoi, occnet128, occnet512, occnet16k)")
    return "voronoi" if m == "voronoi" else f"occnet{HIDDEN[m]}"


# ---------------------------------------------------------------------------------------
# Data, prepared in numpy before any timing
# ---------------------------------------------------------------------------------------

def read_images(folder):
    folder = Path(folder)
    for name in ["train10k-images-idx3-ubyte.gz", "train-images-idx3-ubyte.gz", "train10k-images-idx3-ubyte", "train-images-idx3-ubyte"]:
        p = folder / name
        if p.exists():
            raw = gzip.open(p).read() if name.endswith(".gz") else p.read_bytes()
            magic, n, rows, cols = struct.unpack(">IIII", raw[:16])
            if magic != 0x803 or (rows, cols) != (SIDE, SIDE) or len(raw) < 16 + n * rows * cols:
                sys.exit(f"{p}: not an IDX file of {SIDE}×{SIDE} images (magic {magic:#x}, {n}×{rows}×{cols}, {len(raw)} bytes)")
            return np.frombuffer(raw, dtype=np.uint8, offset=16, count=n * rows * cols).reshape(n, rows, cols), p
    sys.exit(f"no train10k-images-idx3-ubyte.gz or train-images-idx3-ubyte.gz in {folder}")


def boundary_points(img):
    """Midpoints of the pixel edges where the image thresholded at 128 changes (zero outside)."""
    t = np.pad(img >= 128, 1)  # padded index i ↔ pixel i − 1
    r, c = np.nonzero(t[:, 1:] != t[:, :-1])  # between padded columns c and c + 1
    horiz = np.stack([c / SIDE, (r - 0.5) / SIDE], axis=1)  # x = (c − 1 + 1)/28, y = (r − 1 + ½)/28
    r, c = np.nonzero(t[1:, :] != t[:-1, :])
    vert = np.stack([(c - 0.5) / SIDE, r / SIDE], axis=1)
    b = np.concatenate([horiz, vert]).astype(np.float64)
    return b[(b >= 0).all(1) & (b <= 1).all(1)]


def bilinear(img, p):
    """Bilinear intensity in [0, 1] at points p (n × 2, unit square; zero outside), as digit.rs."""
    f = np.pad(img.astype(np.float64) / 255.0, 3)  # pixel (r, c) at f[r + 3, c + 3]
    u = p[:, 0] * SIDE - 0.5
    v = p[:, 1] * SIDE - 0.5
    c0 = np.floor(u)
    r0 = np.floor(v)
    fu, fv = u - c0, v - r0
    c0 = np.clip(c0, -2, SIDE + 1).astype(int) + 3
    r0 = np.clip(r0, -2, SIDE + 1).astype(int) + 3
    a = f[r0, c0] * (1 - fu) + f[r0, c0 + 1] * fu
    b = f[r0 + 1, c0] * (1 - fu) + f[r0 + 1, c0 + 1] * fu
    return a * (1 - fv) + b * fv


def training_points(img, bnd, n, rng):
    """n points (odd indices near the boundary, even uniform) and their occupancy."""
    pts = rng.random((n, 2))
    if len(bnd):
        near = np.arange(1, n, 2)
        pick = bnd[rng.integers(0, len(bnd), len(near))]
        pts[near] = np.clip(pick + rng.normal(0.0, 0.5 / SIDE, (len(near), 2)), 0.0, 1.0)
    return pts, bilinear(img, pts) >= 0.5


def prepare(images, batch, points, nbatches, seed=0):
    """Per batch: flattened inputs, points, occupancy, thresholded images, padded boundaries."""
    rng = np.random.default_rng(seed)
    n = len(images)
    out = []
    for k in range(nbatches):
        idx = [(k * batch + i) % n for i in range(batch)]
        ims = images[idx]
        bnds = [boundary_points(im) for im in ims]
        pts, occ = zip(*(training_points(im, b, points, rng) for im, b in zip(ims, bnds)))
        m = max(1, max(len(b) for b in bnds))
        # Padding far outside the square: never the closest point; has_b masks empty images.
        bpad = np.full((batch, m, 2), 1e3, dtype=np.float32)
        for i, b in enumerate(bnds):
            bpad[i, : len(b)] = b
        out.append({
            "x": (ims.reshape(batch, -1).astype(np.float32) / 255.0),
            "pts": np.stack(pts).astype(np.float32),
            "occ": np.stack(occ).astype(np.float32),
            "thr": (ims >= 128),
            "bnd": bpad,
            "has_b": np.array([len(b) > 0 for b in bnds]),
            "n_boundary": [len(b) for b in bnds],
        })
    return out


# ---------------------------------------------------------------------------------------
# PyTorch models and losses
# ---------------------------------------------------------------------------------------

def mlp(torch, sizes):
    layers = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        lin = torch.nn.Linear(a, b)
        torch.nn.init.kaiming_uniform_(lin.weight, nonlinearity="relu")  # ±√(6/fan_in), as net.rs
        layers.append(lin)  # bias: PyTorch's default ±1/√fan_in, as net.rs
        if i + 2 < len(sizes):
            layers.append(torch.nn.ReLU())
    return torch.nn.Sequential(*layers)


def delaunay_mean_matrix(sites_np, dtype=np.float32):
    """B × K × K row-normalised Delaunay adjacency of each image's sites (scipy)."""
    b, k, _ = sites_np.shape
    a = np.zeros((b, k, k), dtype=dtype)
    for i in range(b):
        s = sites_np[i]
        if not np.isfinite(s).all():
            continue
        try:
            tri = Delaunay(s)
        except QhullError:
            try:
                tri = Delaunay(s, qhull_options="QJ")
            except QhullError:
                continue
        indptr, nb = tri.vertex_neighbor_vertices
        deg = np.diff(indptr)
        rows = np.repeat(np.arange(k), deg)
        a[i, rows, nb] = (1.0 / np.maximum(deg, 1))[rows]
    return a


def voronoi_terms(torch, sites, pts, occ, thr, bnd, has_b, labels, graph=None):
    """The four per-batch-mean terms (reconstruction, bounds, signed distance, centroidal);
    `graph` (B × K × K mean matrix) is built from the detached sites when not given."""
    f = torch.nn.functional
    d = torch.cdist(pts, sites)  # B × P × K
    v = torch.softmax(-BETA * d, dim=-1) @ labels  # B × P
    rec = (occ - v).abs().mean(dim=1)
    bounds = (f.relu(-sites) + f.relu(sites - 1)).sum(dim=(1, 2))
    with torch.no_grad():  # the side of each site: the thresholded pixel under it
        ij = torch.floor(sites.detach() * SIDE).long()
        ok = ((ij >= 0) & (ij < SIDE)).all(-1)
        ij = ij.clamp(0, SIDE - 1)
        bi = torch.arange(sites.shape[0]).unsqueeze(1).expand(-1, sites.shape[1])
        inside = thr[bi, ij[..., 1], ij[..., 0]] & ok
        wrong = (inside != (labels > 0.5)) & has_b.unsqueeze(1)
    dist = torch.cdist(sites, bnd).min(dim=-1).values  # B × K
    signed = (dist * wrong).mean(dim=1)
    if graph is None:
        graph = torch.from_numpy(delaunay_mean_matrix(sites.detach().double().numpy())).to(sites.dtype)
    lap = sites - graph @ sites
    centroidal = (lap * lap).sum(-1).mean(dim=1)
    return rec.mean(), bounds.mean(), signed.mean(), centroidal.mean()


def voronoi_loss(torch, *a, **k):
    rec, bounds, signed, centroidal = voronoi_terms(torch, *a, **k)
    return rec + bounds + W_SIGNED * signed + W_CENTROIDAL * centroidal


class TorchModel:
    def __init__(self, torch, method, seed=0):
        self.torch = torch
        self.method = method
        torch.manual_seed(seed)
        self.encoder = mlp(torch, [SIDE * SIDE, WIDTH, WIDTH, WIDTH, WIDTH, LATENT])
        h = HIDDEN[method]
        self.decoder = mlp(torch, [LATENT, WIDTH, WIDTH, WIDTH, 2 * SITES] if h is None else [LATENT + 2, h, 1])
        self.params = list(self.encoder.parameters()) + list(self.decoder.parameters())
        self.opt = torch.optim.Adam(self.params, lr=1e-3)
        self.labels = torch.cat([torch.ones(SITES // 2), torch.zeros(SITES - SITES // 2)])

    def decoder_params(self):
        return sum(p.numel() for p in self.decoder.parameters())

    def encoder_params(self):
        return sum(p.numel() for p in self.encoder.parameters())

    def loss(self, b):
        torch = self.torch
        z = self.encoder(b["x"])
        if HIDDEN[self.method] is None:
            sites = 0.5 + self.decoder(z).view(-1, SITES, 2)
            return voronoi_loss(torch, sites, b["pts"], b["occ"], b["thr"], b["bnd"], b["has_b"], self.labels)
        bsz, p, _ = b["pts"].shape
        inp = torch.cat([z.unsqueeze(1).expand(bsz, p, LATENT), 2 * b["pts"] - 1], dim=-1).reshape(bsz * p, LATENT + 2)
        logits = self.decoder(inp).view(bsz, p)
        return torch.nn.functional.binary_cross_entropy_with_logits(logits, b["occ"])

    def step(self, b):
        self.opt.zero_grad(set_to_none=True)
        loss = self.loss(b)
        loss.backward()
        self.opt.step()
        return loss


def to_torch(torch, b):
    return {k: (torch.from_numpy(v) if isinstance(v, np.ndarray) else v) for k, v in b.items()}


def time_torch(torch, method, batches, steps):
    model = TorchModel(torch, method)
    for k in range(WARMUP):
        model.step(batches[k])
    t = time.perf_counter()
    for k in range(steps):
        loss = model.step(batches[WARMUP + k])
    secs = time.perf_counter() - t
    last = float(loss.detach())
    if not np.isfinite(last):
        sys.exit(f"PyTorch {method}: the loss became {last}")
    return secs, model.decoder_params(), model.encoder_params(), last


def time_ours(binary, data, method, batch, points, steps, threads):
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    cmd = [str(binary), "mnist", "bench", "--data", str(data), "--batch", str(batch), "--points", str(points),
           "--steps", str(steps), "--methods", method]
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed (exit {r.returncode}):\n{r.stderr}{r.stdout}")
    try:
        rec = json.loads(r.stdout)[0]
    except (json.JSONDecodeError, IndexError, KeyError) as e:
        sys.exit(f"{' '.join(cmd)}: unexpected output ({e}):\n{r.stdout}\n{r.stderr}")
    return rec, cmd


# ---------------------------------------------------------------------------------------
# Self-check of the PyTorch losses
# ---------------------------------------------------------------------------------------

def self_check(torch, images):
    print("self-check of the PyTorch losses (float64, one image):")
    torch.manual_seed(0)
    rng = np.random.default_rng(1)
    img = images[0]
    b = prepare(img[None], 1, 64, 1)[0]
    t = to_torch(torch, b)
    t64 = {k: (v.double() if torch.is_tensor(v) and v.is_floating_point() else v) for k, v in t.items()}
    labels = torch.cat([torch.ones(SITES // 2), torch.zeros(SITES // 2)]).double()
    s = rng.random((1, SITES, 2)) * 1.1 - 0.05  # a few sites outside the square: bounds term ≠ 0
    sites = torch.tensor(s, requires_grad=True)
    graph = torch.from_numpy(delaunay_mean_matrix(s, np.float64))
    terms = [float(x.detach()) for x in voronoi_terms(torch, sites, t64["pts"], t64["occ"], t64["thr"], t64["bnd"], t64["has_b"], labels, graph)]
    # The definitions, by hand.
    p, o, sp = b["pts"][0].astype(np.float64), b["occ"][0], s[0]
    d = np.sqrt(((p[:, None, :] - sp[None, :, :]) ** 2).sum(-1))
    w = np.exp(-BETA * (d - d.min(1, keepdims=True)))
    w /= w.sum(1, keepdims=True)
    rec = np.abs(o - w[:, : SITES // 2].sum(1)).mean()
    bounds = (np.maximum(-sp, 0) + np.maximum(sp - 1, 0)).sum()
    bnd = b["bnd"][0][: b["n_boundary"][0]].astype(np.float64)
    signed = 0.0
    for k, q in enumerate(sp):
        c, r = int(np.floor(q[0] * SIDE)), int(np.floor(q[1] * SIDE))
        ins = 0 <= c < SIDE and 0 <= r < SIDE and bool(b["thr"][0, r, c])
        if ins != (k < SITES // 2):
            signed += np.sqrt(((bnd - q) ** 2).sum(1)).min()
    signed /= SITES
    tri = Delaunay(sp)
    nbrs = [set() for _ in range(SITES)]
    for simplex in tri.simplices:
        for i in simplex:
            nbrs[i].update(int(j) for j in simplex if j != i)
    centroidal = np.mean([((sp[i] - sp[sorted(nbrs[i])].mean(0)) ** 2).sum() for i in range(SITES)])
    ok = True
    for name, got, want in zip(["reconstruction", "bounds", "signed distance", "centroidal"], terms, [rec, bounds, signed, centroidal]):
        good = abs(got - want) <= 1e-9 * max(1.0, abs(want))
        ok &= good
        print(f"  {name:15s} torch {got:.12g}  by hand {want:.12g}  {'ok' if good else 'MISMATCH'}")
    ok &= bounds > 0 and signed > 0 and centroidal > 0

    def f(x):
        return voronoi_loss(torch, x, t64["pts"], t64["occ"], t64["thr"], t64["bnd"], t64["has_b"], labels, graph=graph)

    # β = 100 makes the soft-argmin steep: central differences at 1e-7 with a loose tolerance.
    try:
        g_ok = torch.autograd.gradcheck(f, (sites,), eps=1e-7, atol=1e-4, rtol=1e-3, raise_exception=True)
    except RuntimeError as e:
        g_ok = False
        print(f"  gradcheck failed: {str(e)[:400]}")
    print(f"  gradient vs finite differences (gradcheck, all 256 coordinates): {'ok' if g_ok else 'FAILED'}")
    ok &= g_ok

    for method, n_steps in [("voronoi", 40), ("occnet128", 40)]:
        model = TorchModel(torch, method, seed=0)
        b1 = to_torch(torch, prepare(img[None], 1, 256, 1)[0])
        losses = []
        finite = True
        for _ in range(n_steps):
            model.opt.zero_grad(set_to_none=True)
            loss = model.loss(b1)
            loss.backward()
            finite &= all(bool(torch.isfinite(p.grad).all()) for p in model.params if p.grad is not None)
            model.opt.step()
            losses.append(float(loss.detach()))
        dec = np.isfinite(losses).all() and finite and losses[-1] < 0.95 * losses[0] and min(losses[-5:]) < min(losses[:5])
        ok &= dec
        print(f"  {method}: {n_steps} Adam steps on one image, loss {losses[0]:.4f} → {losses[-1]:.4f}, "
              f"gradients finite: {finite}  {'ok' if dec else 'FAILED'}")
    print(f"self-check: {'passed' if ok else 'FAILED'}")
    return ok


# ---------------------------------------------------------------------------------------

def versions(torch):
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    v = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__, "cpu": cpu,
         "cpus": os.cpu_count()}
    if torch is not None:
        v["torch"] = torch.__version__
        v["torch_threads"] = torch.get_num_threads()
        v["torch_config"] = torch.__config__.show()
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--methods", default="voronoi,occnet128,occnet512,occnet16k")
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--points", type=int, default=256)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--bin", default=str(ROOT / "target" / "release" / "voronoi-fit"))
    ap.add_argument("--data", default=str(ROOT.parent / "shared" / "mnist"))
    ap.add_argument("--json", help="save every number, the command lines and the versions here")
    ap.add_argument("--no-torch", action="store_true")
    ap.add_argument("--self-check", action="store_true", help="check the PyTorch losses and exit")
    a = ap.parse_args()
    methods = [m.strip() for m in a.methods.split(",") if m.strip()]
    for m in methods:
        canonical(m)
    started = time.perf_counter()
    images, source = read_images(a.data)

    torch, note = None, None
    if not a.no_torch:
        try:
            import torch  # noqa: F811
            torch.set_num_threads(a.threads)
        except Exception as e:  # ImportError or a wheel whose native libraries are missing
            torch, note = None, f"PyTorch not available ({type(e).__name__}: {e}); skipped"
    if a.self_check:
        if torch is None:
            sys.exit(note or "--self-check needs PyTorch")
        sys.exit(0 if self_check(torch, images) else 1)

    binary = Path(a.bin)
    if not binary.exists():
        sys.exit(f"{binary}: no such binary (build it with cargo build --release, or give --bin)")
    ver = versions(torch)
    print(f"MNIST autoencoders, training throughput (forward + backward + Adam), batch {a.batch}, {a.points} points "
          f"per image, {WARMUP} warm-up + {a.steps} timed steps, {a.repeats} round(s), {a.threads} threads; "
          f"{ver['cpu']}, {ver['cpus']} CPUs; data {source}")
    if note:
        print(f"  {note}")
    batches = None
    if torch is not None:
        t0 = time.perf_counter()
        batches = [to_torch(torch, b) for b in prepare(images, a.batch, a.points, WARMUP + a.steps)]
        nb = [n for b in batches for n in b["n_boundary"]]
        print(f"  PyTorch {torch.__version__}: {len(batches)} batches prepared in {time.perf_counter() - t0:.1f} s "
              f"(boundary points per image: median {int(np.median(nb))}, {min(nb)}–{max(nb)})")
    rounds = {m: {"ours": [], "torch": [], "ours_records": [], "torch_final_loss": []} for m in methods}
    info = {}
    ours_cmds = {}
    for r in range(a.repeats):
        for m in methods:
            def run_ours():
                rec, cmd = time_ours(binary, a.data, m, a.batch, a.points, a.steps, a.threads)
                if rec.get("method") != canonical(m):
                    sys.exit(f"the binary reported method {rec.get('method')!r} for {m!r}")
                ours_cmds[m] = cmd
                rounds[m]["ours"].append(rec["images_per_second"])
                rounds[m]["ours_records"].append(rec)
                info.setdefault(m, {}).update(decoder_params=rec["decoder_params"], encoder_params=rec["encoder_params"],
                                              rust_threads=rec["threads"])

            def run_torch():
                secs, dp, ep, last = time_torch(torch, m, batches, a.steps)
                rounds[m]["torch"].append(a.steps * a.batch / secs)
                rounds[m]["torch_final_loss"].append(last)
                info.setdefault(m, {}).update(torch_decoder_params=dp, torch_encoder_params=ep)

            order = [run_ours] + ([run_torch] if torch is not None else [])
            for fn in (order if r % 2 == 0 else order[::-1]):
                fn()
            line = f"  round {r + 1}: {m}: ours {rounds[m]['ours'][-1]:.1f} img/s"
            if torch is not None:
                line += f", PyTorch {rounds[m]['torch'][-1]:.1f} img/s, ratio {rounds[m]['ours'][-1] / rounds[m]['torch'][-1]:.2f}"
            print(line, flush=True)
    wall = time.perf_counter() - started

    rows = []
    for m in methods:
        o = rounds[m]["ours"]
        row = {"method": canonical(m), **info[m], "ours_images_per_second": statistics.median(o), "ours_rounds": o,
               "ours_records": rounds[m]["ours_records"]}
        if torch is not None:
            t = rounds[m]["torch"]
            per = [x / y for x, y in zip(o, t)]
            row.update(torch_images_per_second=statistics.median(t), torch_rounds=t, ratio=statistics.median(o) / statistics.median(t),
                       ratio_min=min(per), ratio_max=max(per), ratio_rounds=per, torch_final_loss=rounds[m]["torch_final_loss"])
            if row["torch_decoder_params"] != row["decoder_params"] or row["torch_encoder_params"] != row["encoder_params"]:
                print(f"  note: {m}: parameter counts differ (Rust {row['decoder_params']}/{row['encoder_params']}, "
                      f"PyTorch {row['torch_decoder_params']}/{row['torch_encoder_params']})")
        rows.append(row)

    threads_rust = sorted({r["rust_threads"] for r in rows})
    print()
    tname = f"PyTorch {torch.__version__} img/s" if torch is not None else "PyTorch img/s"
    print(f"| method | decoder params | ours img/s | {tname} | ratio ours / PyTorch [range over rounds] |")
    print("|---|---:|---:|---:|---|")
    for row in rows:
        if torch is not None:
            tail = f"{row['torch_images_per_second']:.1f} | {row['ratio']:.2f} [{row['ratio_min']:.2f}–{row['ratio_max']:.2f}]"
        else:
            tail = "– | –"
        print(f"| {row['method']} | {row['decoder_params']:,} | {row['ours_images_per_second']:.1f} | {tail} |")
    print()
    print(f"Median of {a.repeats} round(s); {WARMUP} warm-up + {a.steps} timed steps of batch {a.batch}, {a.points} points per image; "
          f"forward + backward + Adam; ratio > 1: ours is faster. Rust: {', '.join(map(str, threads_rust))} rayon thread(s); "
          + (f"PyTorch {torch.__version__} (CPU), {torch.get_num_threads()} thread(s), numpy {np.__version__}, scipy {scipy.__version__}; "
             if torch is not None else f"{note or 'PyTorch skipped (--no-torch)'}; ")
          + f"Python {ver['python']}; {ver['cpu']}, {ver['cpus']} CPUs. Encoder {rows[0]['encoder_params']:,} parameters. "
          f"Wall time {wall:.0f} s.")
    if a.json:
        out = {"command": [sys.executable] + sys.argv, "settings": vars(a), "warmup": WARMUP, "data": str(source),
               "ours_commands": {m: c for m, c in ours_cmds.items()}, "versions": ver, "torch_note": note,
               "results": rows, "wall_seconds": wall, "date": time.strftime("%Y-%m-%d %H:%M:%S %Z")}
        Path(a.json).write_text(json.dumps(out, indent=2) + "\n")
        print(f"\nnumbers: {a.json}")


if __name__ == "__main__":
    main()
