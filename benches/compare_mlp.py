"""One training step (forward + backward + Adam) of the OccNet-style MLP 3→256×5→1, batch
65,536, float32, binary cross-entropy: the `baselines` crate against PyTorch (CPU) and a
numpy implementation of the same step, in one run.

    python benches/compare_mlp.py [--width 256] [--depth 5] [--batch 65536] [--steps 5]
                                  [--threads 2] [--repeats 3] [--no-torch] [--no-numpy]

The crate is timed by its example (`cargo run --release -p baselines --example
step_timing`, built first; honours CARGO_TARGET_DIR). Each implementation does one
untimed warm-up step, then `--steps` timed steps on the same batch, in `--repeats` rounds
that time every implementation once each; reported: the median seconds per step and
steps/s, and the ratio crate / other in steps per second (> 1: the crate is faster) with
its range over the rounds. PyTorch runs with `torch.set_num_threads(--threads)`; numpy uses its BLAS's
threads (set OPENBLAS_NUM_THREADS to pin them). PyTorch is skipped with a note when it
cannot be imported. PyPI's Linux wheel is the CUDA build and pulls in the nvidia-* wheels
(5.4 GB in all); it runs on the CPU without a GPU. Install it into a venv of its own:

    python3 -m venv target/bench-torch && target/bench-torch/bin/pip install torch==2.15.0 numpy
    target/bench-torch/bin/python benches/compare_mlp.py
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def data(batch, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.random((batch, 3), dtype=np.float64).astype(np.float32)
    d = np.sqrt(((x - 0.5) ** 2).sum(axis=1)) - 0.35
    y = (d < 0).astype(np.float32)
    return x, y


def ours(width, depth, batch, steps):
    env = dict(os.environ)
    cmd = ["cargo", "run", "--release", "-q", "-p", "baselines", "--example", "step_timing", "--",
           str(width), str(depth), str(batch), str(steps)]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        sys.exit(f"cargo failed:\n{r.stderr}")
    rec = json.loads(r.stdout.strip().splitlines()[-1])
    return rec["step_s"], rec


def numpy_step_fn(width, depth, batch):
    rng = np.random.default_rng(1)
    dims = [3] + [width] * depth + [1]
    params = []
    for i, o in zip(dims[:-1], dims[1:]):
        bound = 1 / np.sqrt(i)
        params += [rng.uniform(-bound, bound, (i, o)).astype(np.float32), rng.uniform(-bound, bound, o).astype(np.float32)]
    m = [np.zeros_like(p) for p in params]
    v = [np.zeros_like(p) for p in params]
    x, y = data(batch)
    t = [0]

    def step(lr=1e-3, b1=0.9, b2=0.999, eps=1e-8):
        acts = [x]
        a = x
        n = len(dims) - 1
        for l in range(n):
            z = a @ params[2 * l] + params[2 * l + 1]
            a = np.maximum(z, 0) if l < n - 1 else z
            acts.append(a)
        z = acts[-1][:, 0]
        loss = np.mean(np.maximum(z, 0) - y * z + np.log1p(np.exp(-np.abs(z))))
        dz = ((1 / (1 + np.exp(-z)) - y) / batch)[:, None].astype(np.float32)
        grads = [None] * len(params)
        for l in reversed(range(n)):
            grads[2 * l] = acts[l].T @ dz
            grads[2 * l + 1] = dz.sum(axis=0)
            if l > 0:
                dz = (dz @ params[2 * l].T) * (acts[l] > 0)
        t[0] += 1
        bc1, bc2 = 1 - b1 ** t[0], 1 - b2 ** t[0]
        for p, g, mm, vv in zip(params, grads, m, v):
            mm *= b1
            mm += (1 - b1) * g
            vv *= b2
            vv += (1 - b2) * g * g
            p -= (lr / bc1) * mm / (np.sqrt(vv) / np.sqrt(bc2) + eps)
        return loss

    return step


def torch_step_fn(width, depth, batch, threads):
    import torch

    torch.set_num_threads(threads)
    torch.manual_seed(0)
    layers = []
    dims = [3] + [width] * depth
    for i, o in zip(dims[:-1], dims[1:]):
        layers += [torch.nn.Linear(i, o), torch.nn.ReLU()]
    layers.append(torch.nn.Linear(width, 1))
    net = torch.nn.Sequential(*layers)
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    x, y = data(batch)
    x, y = torch.from_numpy(x), torch.from_numpy(y)
    lossf = torch.nn.BCEWithLogitsLoss()

    def step():
        opt.zero_grad(set_to_none=True)
        loss = lossf(net(x)[:, 0], y)
        loss.backward()
        opt.step()
        return loss.item()

    return step, torch.__version__


def time_steps(step, steps):
    step()  # warm-up
    t = time.perf_counter()
    for _ in range(steps):
        step()
    return (time.perf_counter() - t) / steps


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--depth", type=int, default=5)
    ap.add_argument("--batch", type=int, default=65536)
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-torch", action="store_true")
    ap.add_argument("--no-numpy", action="store_true")
    a = ap.parse_args()
    params = 3 * a.width + a.width + (a.depth - 1) * (a.width * a.width + a.width) + a.width + 1
    print(f"MLP 3→{a.width}×{a.depth}→1 ({params:,} parameters), batch {a.batch:,}, float32, BCE + Adam; "
          f"{a.steps} timed steps after one warm-up; {os.cpu_count()} CPUs")
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "baselines", "--example", "step_timing"], cwd=ROOT, check=True)
    impls = {}
    if not a.no_torch:
        try:
            step, ver = torch_step_fn(a.width, a.depth, a.batch, a.threads)
        except Exception as e:  # ImportError or a wheel whose native libraries are missing
            print(f"  PyTorch: not available ({type(e).__name__}: {e}); skipped")
        else:
            impls[f"PyTorch {ver} (CPU, {a.threads} threads)"] = step
    if not a.no_numpy:
        impls[f"numpy {np.__version__} (same step by hand, BLAS threads as configured)"] = numpy_step_fn(a.width, a.depth, a.batch)
    # Interleaved repeats: every implementation is timed once per round, so a change in the
    # machine's load affects all of them alike.
    times = {"baselines": []} | {name: [] for name in impls}
    for r in range(a.repeats):
        s_ours, rec = ours(a.width, a.depth, a.batch, a.steps)
        times["baselines"].append(s_ours)
        line = [f"baselines {1 / s_ours:.3f}"]
        for name, step in impls.items():
            times[name].append(time_steps(step, a.steps))
            line.append(f"{name.split(' (')[0]} {1 / times[name][-1]:.3f}")
        print(f"  round {r + 1}: steps/s " + ", ".join(line))
    med = {name: float(np.median(ts)) for name, ts in times.items()}
    print(f"median over {a.repeats} round(s):")
    print(f"  baselines (Rust, {rec['threads']} rayon threads): {med['baselines']:.3f} s/step = {1 / med['baselines']:.3f} steps/s")
    for name in impls:
        print(f"  {name}: {med[name]:.3f} s/step = {1 / med[name]:.3f} steps/s")
    for name in impls:
        per_round = [t / o for t, o in zip(times[name], times["baselines"])]
        print(f"ratio baselines / {name.split(' (')[0]} (steps per second): {med[name] / med['baselines']:.2f} "
              f"(rounds: {min(per_round):.2f}–{max(per_round):.2f})")

if __name__ == "__main__":
    main()
