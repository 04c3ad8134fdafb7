"""Fit many meshes on a Ray cluster: one Ray task per mesh, results on shared storage.

    python -m voronoi_fit.cluster --ray ADDRESS manifest.txt --out DIR [--sites K] [...]

- ``ADDRESS`` is a running cluster (``ray start --head`` prints it, e.g. ``10.0.0.5:6379``),
  ``auto`` for the cluster this machine belongs to, or ``local`` to start one in this
  process on this machine.
- ``manifest.txt`` names one mesh per line (``#`` comments; relative paths are taken from
  the manifest's folder). Every worker must see the same paths and ``DIR``: a shared file
  system (NFS, a cloud file store mounted on every node), not a node's local disk.
- The batch protocol is ``voronoi-fit batch``'s own, the Rust ``jobs::batch`` module called
  through the native module: the folder names, ``batch.json`` (what a result was made
  from), the fit itself, publishing by rename and ``summary.csv``. Each task fits one mesh
  in its private ``DIR/.work/NAME.ATTEMPT/`` and publishes it with one ``rename`` to
  ``DIR/NAME/`` (crust GLB, sites file, picture, report, ``batch.json``), the layout
  ``voronoi-fit batch`` writes. The rename is the commit: if a retried attempt finds
  ``DIR/NAME/`` already there, it discards its own copy, so every mesh is published
  exactly once and never half.
- A task whose worker dies (killed, out of memory, node lost) is run again by Ray
  (``--retries``, default 3); a mesh the fit rejects is recorded as ``bad input`` with the
  message and not retried. Meshes already published with the same input and options are
  skipped, so a rerun finishes what a stopped run left.
- The driver gathers every task's row into ``DIR/summary.csv`` (``voronoi-fit batch``'s
  columns, then the attempt's process id and node; rewritten atomically as tasks finish)
  and prints meshes per minute and the engine's overhead (wall time × task
  slots against the time spent inside fits).

Ray is the engine (``pip install "voronoi-fit[cluster]"``); nothing here schedules work
itself.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import time
import uuid
from pathlib import Path
from typing import Any, Optional

# The runner's own columns of summary.csv, after voronoi-fit batch's.
EXTRA_FIELDS = ["attempt_pid", "node"]


def plan(manifest: Path) -> list[tuple[str, str]]:
    """The manifest's meshes as (path, folder name) pairs, in order, without repeats, named
    exactly as ``voronoi-fit batch`` names them (the Rust protocol's plan)."""
    from voronoi_fit import InputError, _native

    try:
        return _native.batch_plan([f"@{manifest}"])
    except InputError as e:
        raise SystemExit(f"error: {e}") from None


def batch_options(out: Path, options: dict) -> str:
    """The batch's options for the Rust protocol, as JSON: the fit options (the CLI's long
    names; ``occupancy``: N occupancy samples of the fitted solid per mesh, as the CLI's
    ``--occupancy N``), GLB crusts, and the options as flags recorded in each
    ``batch.json``."""
    from voronoi_fit import __version__

    fit_args = []
    for k in sorted(options):
        fit_args += [f"--{k.replace('_', '-')}", str(options[k])]
    fit_options = {k: v for k, v in options.items() if k != "occupancy"}
    fit: dict[str, Any] = {"options": fit_options}
    if options.get("occupancy") is not None:
        fit["occupancy"] = {"points": int(options["occupancy"])}
    return json.dumps(
        {
            "out": str(out),
            "jobs": 1,
            "format": "glb",
            "fit": fit,
            "fit_args": fit_args,
            "version": __version__,
        }
    )


def fit_one(path: str, name: str, out: str, batch: str) -> dict:
    """One mesh, on a worker: fit into a private work folder, publish by rename (the Rust
    protocol). Returns the summary row. Bad input is a row, not an exception (no retry)."""
    from voronoi_fit import InputError, _native

    t0 = time.time()
    out_dir = Path(out)
    row: dict[str, Any] = {"name": name, "input": path, "attempt_pid": os.getpid(), "node": os.uname().nodename}
    if _native.batch_finished(batch, path, name):
        return {**row, "status": "done earlier", "finished": True}
    attempt = uuid.uuid4().hex[:12]
    work = out_dir / ".work" / f"{name}.{attempt}"
    work.mkdir(parents=True)
    # Tell whoever watches (the test kills the worker named here) which process works.
    (work / "attempt.pid").write_text(str(os.getpid()))
    try:
        _native.batch_fit_into(batch, path, name, str(work))
    except InputError as e:
        shutil.rmtree(work, ignore_errors=True)
        return {**row, "status": "bad input", "error": str(e), "seconds": f"{time.time() - t0:.1f}"}
    (work / "attempt.pid").unlink()
    aside = out_dir / ".work" / f"{name}.replaced.{attempt}"
    moved = _native.batch_publish(batch, path, name, str(work), str(aside))
    status = "fitted" if moved else "fitted (another attempt published first)"
    return {**row, "status": status, "seconds": f"{time.time() - t0:.1f}", "finished": True}


def write_summary(out: Path, rows: list[dict], jobs: list[tuple[str, str]]) -> None:
    """``summary.csv`` by the Rust protocol: one row per finished task, in manifest order,
    with the report's figures and the attempt's process id and node."""
    from voronoi_fit import _native

    inputs = dict((n, p) for p, n in jobs)
    summary = [
        {
            "job": {"input": r.get("input") or inputs.get(r["name"], ""), "name": r["name"]},
            "status": str(r.get("status", "")),
            "error": str(r.get("error", "")).replace("\n", " "),
            "seconds": str(r.get("seconds", "")),
            "finished": bool(r.get("finished")),
            "extra": [str(r.get(k, "")) for k in EXTRA_FIELDS],
        }
        for r in rows
    ]
    _native.batch_write_summary(str(out), json.dumps(summary), EXTRA_FIELDS)


def _atomic_json(path: Path, obj: Any) -> None:
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}")
    tmp.write_text(json.dumps(obj, indent=2))
    os.replace(tmp, path)


def run(
    address: str,
    manifest: Path,
    out: Path,
    options: dict,
    retries: int = 3,
    cpus_per_task: float = 1.0,
    quiet: bool = False,
) -> list[dict]:
    """Fans the manifest's meshes out as Ray tasks and gathers the summary. Returns the
    rows (input order)."""
    import ray

    jobs = plan(manifest)
    out.mkdir(parents=True, exist_ok=True)
    batch = batch_options(out.resolve(), options)
    (out / ".work").mkdir(exist_ok=True)
    t0 = time.time()
    if address == "local":
        ray.init(include_dashboard=False, log_to_driver=not quiet)
    else:
        ray.init(address=address, log_to_driver=not quiet)
    slots = max(1, int(ray.cluster_resources().get("CPU", 1) // cpus_per_task))
    task = ray.remote(num_cpus=cpus_per_task, max_retries=retries, retry_exceptions=False)(fit_one)
    refs = {}
    for p, n in jobs:
        refs[task.remote(str(Path(p).resolve()), n, str(out.resolve()), batch)] = n
    rows: dict[str, dict] = {}
    order = [n for _, n in jobs]
    pending = list(refs)
    bar = None
    if not quiet:
        try:
            from tqdm.auto import tqdm

            bar = tqdm(total=len(pending), desc="meshes", unit="mesh")
        except ImportError:
            pass
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        for ref in done:
            n = refs[ref]
            try:
                rows[n] = ray.get(ref)
            except Exception as e:  # a task whose retries ran out (its workers kept dying)
                rows[n] = {"name": n, "status": "failed", "error": f"{type(e).__name__}: {e}".replace("\n", " ")[:500]}
            if bar is not None:
                bar.update(1)
        write_summary(out, [rows[n] for n in order if n in rows], jobs)
    if bar is not None:
        bar.close()
    wall = time.time() - t0
    ray.shutdown()
    # Attempts killed midway leave their private work folders; nothing else is in .work.
    for leftover in (out / ".work").iterdir():
        shutil.rmtree(leftover, ignore_errors=True)
    final = [rows[n] for n in order]
    write_summary(out, final, jobs)
    fitted = [r for r in final if str(r.get("status", "")).startswith("fitted")]
    inside = sum(float(r.get("seconds") or 0) for r in fitted)
    stats = {
        "meshes": len(final),
        "fitted": len(fitted),
        "done_earlier": sum(r.get("status") == "done earlier" for r in final),
        "failed": sum(r.get("status") in ("failed", "bad input") for r in final),
        "wall_seconds": wall,
        "task_slots": slots,
        "seconds_in_fits": inside,
        "meshes_per_minute": 60 * len(fitted) / wall if wall > 0 else 0.0,
        # Slot-seconds not spent inside a fit: start-up, scheduling, transfers, idle tails.
        "overhead_share": max(0.0, 1 - inside / (wall * slots)) if wall > 0 else 0.0,
    }
    _atomic_json(out / "cluster.json", stats)
    print(
        f"{stats['meshes']} meshes: {stats['fitted']} fitted, {stats['done_earlier']} done earlier, "
        f"{stats['failed']} failed; {wall:.1f} s on {slots} task slot(s), {stats['meshes_per_minute']:.2f} meshes "
        f"per minute; {100 * stats['overhead_share']:.0f}% of the slot time outside fits. Summary: {out / 'summary.csv'}"
    )
    return final


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m voronoi_fit.cluster", description=__doc__.split("\n\n")[0])
    ap.add_argument("--ray", required=True, metavar="ADDRESS", help="cluster address, `auto`, or `local`")
    ap.add_argument("manifest", type=Path, help="one mesh path per line")
    ap.add_argument("--out", required=True, type=Path, help="shared output folder")
    ap.add_argument("--sites", type=int, default=8192)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--steps", type=int)
    ap.add_argument("--samples", type=int)
    ap.add_argument("--eval-samples", type=int)
    ap.add_argument("--polish-steps", type=int, help="steps of the surface polish (0: none; default as the CLI's)")
    ap.add_argument(
        "--polish-align",
        type=float,
        help="alignment weight of the polish (0: plain polish only, faster; default: both tried on closed meshes)",
    )
    ap.add_argument(
        "--occupancy",
        type=int,
        metavar="N",
        help="also write NAME.voronoi.points.npz per mesh: N occupancy samples of the fitted solid (OccNet's layout)",
    )
    ap.add_argument("--retries", type=int, default=3, help="runs of a task whose worker died (Ray max_retries)")
    ap.add_argument("--cpus-per-task", type=float, default=1.0)
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    options = {"sites": a.sites, "seed": a.seed}
    for k in ("steps", "samples", "eval_samples", "polish_steps", "polish_align", "occupancy"):
        if getattr(a, k) is not None:
            options[k] = getattr(a, k)
    rows = run(a.ray, a.manifest, a.out, options, a.retries, a.cpus_per_task, a.quiet)
    return 0 if all(str(r.get("status", "")).startswith(("fitted", "done")) for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
