"""Fit many meshes on a Ray cluster: one Ray task per mesh, results on shared storage.

    python -m voronoi_fit.cluster --ray ADDRESS manifest.txt --out DIR [--sites K] [...]

- ``ADDRESS`` is a running cluster (``ray start --head`` prints it, e.g. ``10.0.0.5:6379``),
  ``auto`` for the cluster this machine belongs to, or ``local`` to start one in this
  process on this machine.
- ``manifest.txt`` names one mesh per line (``#`` comments; relative paths are taken from
  the manifest's folder). Every worker must see the same paths and ``DIR``: a shared file
  system (NFS, a cloud file store mounted on every node), not a node's local disk.
- Each task fits one mesh with :func:`voronoi_fit.fit` in ``DIR/.work/NAME.ATTEMPT/`` and
  publishes it with one ``rename`` to ``DIR/NAME/`` (crust GLB, sites file, report,
  ``batch.json``), the layout ``voronoi-fit batch`` writes. The rename is the commit: if a
  retried attempt finds ``DIR/NAME/`` already there, it discards its own copy, so every
  mesh is published exactly once and never half.
- A task whose worker dies (killed, out of memory, node lost) is run again by Ray
  (``--retries``, default 3); a mesh the fit rejects is recorded as ``bad input`` with the
  message and not retried. Meshes already published with the same input and options are
  skipped, so a rerun finishes what a stopped run left.
- The driver gathers every task's row into ``DIR/summary.csv`` (rewritten atomically as
  tasks finish) and prints meshes per minute and the engine's overhead (wall time × task
  slots against the time spent inside fits).

Ray is the engine (``pip install "voronoi-fit[cluster]"``); nothing here schedules work
itself.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import os
import shutil
import sys
import time
import uuid
from pathlib import Path
from typing import Any, Optional

FIELDS = [
    "name",
    "input",
    "status",
    "error",
    "seconds",
    "attempt_pid",
    "node",
    "hausdorff_hi",
    "hausdorff_of_diagonal",
    "chamfer_l1",
    "fscore",
    "normal_consistency",
    "iou",
    "sites",
    "triangles",
    "genus",
    "folder",
]


def read_manifest(path: Path) -> list[Path]:
    """Mesh paths of a manifest, in order, without repeats."""
    out, seen = [], set()
    base = path.parent
    for n, line in enumerate(path.read_text().splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        p = Path(line)
        p = p if p.is_absolute() else base / p
        if not p.is_file():
            raise SystemExit(f"error: {path}, line {n}: `{line}` is not a file (paths are relative to the manifest)")
        key = p.resolve()
        if key not in seen:
            seen.add(key)
            out.append(p)
    return out


def names(paths: list[Path]) -> list[str]:
    """Output folder names exactly as `voronoi-fit batch` makes them: the stem, made safe;
    stems shared by several inputs get the low 32 bits of FNV-1a of the resolved path."""

    def stem(p: Path) -> str:
        s = "".join(c if (c.isalnum() or c in "-_.") else "_" for c in p.stem)
        return s if s and not s.startswith(".") else f"mesh{s}"

    counts: dict[str, int] = {}
    for p in paths:
        counts[stem(p)] = counts.get(stem(p), 0) + 1
    out = []
    for p in paths:
        s = stem(p)
        if counts[s] > 1:
            s = f"{s}-{_fnv1a64(str(p.resolve()).encode()) & 0xFFFFFFFF:08x}"
        out.append(s)
    return out


def _fnv1a64(data: bytes) -> int:
    """FNV-1a, 64 bits: the hash `voronoi-fit batch` puts in shared stems' folder names."""
    h = 0xCBF29CE484222325
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def provenance(path: Path, options: dict) -> dict:
    data = path.read_bytes()
    return {
        "input": str(path.resolve()),
        "input_bytes": len(data),
        "input_sha256": hashlib.sha256(data).hexdigest(),
        "fit_options": options,
        "format": "glb",
    }


def fit_one(path: str, name: str, out: str, options: dict) -> dict:
    """One mesh, on a worker: fit, write into a private work folder, publish by rename.
    Returns the summary row. Bad input is a row, not an exception (no retry)."""
    import voronoi_fit as vf

    t0 = time.time()
    p, out_dir = Path(path), Path(out)
    row: dict[str, Any] = {"name": name, "input": path, "attempt_pid": os.getpid(), "node": os.uname().nodename}
    final = out_dir / name
    prov = provenance(p, options)
    if _matches(final, prov):
        return {**row, "status": "done earlier", **_figures(final, name)}
    work = out_dir / ".work" / f"{name}.{uuid.uuid4().hex[:12]}"
    work.mkdir(parents=True)
    # Tell whoever watches (the test kills the worker named here) which process works.
    (work / "attempt.pid").write_text(str(os.getpid()))
    try:
        result = vf.fit(p, progress=False, float32=True, name=path, **options)
    except vf.InputError as e:
        shutil.rmtree(work, ignore_errors=True)
        return {**row, "status": "bad input", "error": str(e), "seconds": f"{time.time() - t0:.1f}"}
    result.save(work / f"{name}", format="glb")
    (work / "attempt.pid").unlink()
    _atomic_json(work / "batch.json", prov)
    try:
        os.rename(work, final)
        status = "fitted"
    except OSError:
        # Another attempt published first (this one was a retry that raced it), or an older
        # result with other settings is in the way: keep exactly one.
        if _matches(final, prov):
            shutil.rmtree(work, ignore_errors=True)
            status = "fitted (another attempt published first)"
        else:
            old = out_dir / ".work" / f"{name}.replaced.{uuid.uuid4().hex[:8]}"
            os.rename(final, old)
            os.rename(work, final)
            shutil.rmtree(old, ignore_errors=True)
            status = "fitted"
    return {**row, "status": status, "seconds": f"{time.time() - t0:.1f}", **_figures(final, name)}


def _matches(folder: Path, prov: dict) -> bool:
    try:
        return json.loads((folder / "batch.json").read_text()) == prov and (
            folder / f"{folder.name}.voronoi.report.json"
        ).is_file()
    except (OSError, ValueError):
        return False


def _figures(folder: Path, name: str) -> dict:
    try:
        r = json.loads((folder / f"{name}.voronoi.report.json").read_text())
    except (OSError, ValueError):
        return {}
    m = r.get("metrics") or {}
    h, s, c = m.get("hausdorff") or {}, m.get("surface") or {}, r.get("crust") or {}
    return {
        "hausdorff_hi": h.get("hi", ""),
        "hausdorff_of_diagonal": (h["hi"] / h["diagonal"]) if h.get("diagonal") else "",
        "chamfer_l1": s.get("chamfer_l1", ""),
        "fscore": s.get("fscore", ""),
        "normal_consistency": s.get("normal_consistency", ""),
        "iou": (m.get("iou") or {}).get("iou", ""),
        "sites": c.get("num_sites", ""),
        "triangles": c.get("num_triangles", ""),
        "genus": c.get("genus", ""),
        "folder": str(folder),
        "seconds": r.get("total_seconds", ""),
    }


def _atomic_json(path: Path, obj: Any) -> None:
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}")
    tmp.write_text(json.dumps(obj, indent=2))
    os.replace(tmp, path)


def write_summary(out: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=FIELDS, extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow(r)
    tmp = out / f".summary.csv.{uuid.uuid4().hex[:8]}"
    tmp.write_text(buf.getvalue())
    os.replace(tmp, out / "summary.csv")


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

    paths = read_manifest(manifest)
    if not paths:
        raise SystemExit(f"error: {manifest}: no meshes listed")
    out.mkdir(parents=True, exist_ok=True)
    (out / ".work").mkdir(exist_ok=True)
    t0 = time.time()
    if address == "local":
        ray.init(include_dashboard=False, log_to_driver=not quiet)
    else:
        ray.init(address=address, log_to_driver=not quiet)
    slots = max(1, int(ray.cluster_resources().get("CPU", 1) // cpus_per_task))
    task = ray.remote(num_cpus=cpus_per_task, max_retries=retries, retry_exceptions=False)(fit_one)
    refs = {}
    for p, n in zip(paths, names(paths)):
        refs[task.remote(str(p.resolve()), n, str(out.resolve()), options)] = n
    rows: dict[str, dict] = {}
    order = names(paths)
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
        write_summary(out, [rows[n] for n in order if n in rows])
    if bar is not None:
        bar.close()
    wall = time.time() - t0
    ray.shutdown()
    # Attempts killed midway leave their private work folders; nothing else is in .work.
    for leftover in (out / ".work").iterdir():
        shutil.rmtree(leftover, ignore_errors=True)
    final = [rows[n] for n in order]
    write_summary(out, final)
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
    ap.add_argument("--retries", type=int, default=3, help="runs of a task whose worker died (Ray max_retries)")
    ap.add_argument("--cpus-per-task", type=float, default=1.0)
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    options = {"sites": a.sites, "seed": a.seed}
    for k in ("steps", "samples", "eval_samples", "polish_steps", "polish_align"):
        if getattr(a, k) is not None:
            options[k] = getattr(a, k)
    rows = run(a.ray, a.manifest, a.out, options, a.retries, a.cpus_per_task, a.quiet)
    return 0 if all(str(r.get("status", "")).startswith(("fitted", "done")) for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
