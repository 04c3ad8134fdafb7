#!/usr/bin/env python3
"""How large the winding solid's caps would be on open meshes, and which solid
`--solid auto` takes for them (`CAPS_SHELL_ABOVE`); with `--baseline-bin OLD`, the same
fits by an older binary beside them (a before/after of one change).

    python3 benches/caps_share.py --bin target/release/voronoi-fit \\
        --out benches/results/caps_share.json \\
        halftunnel=benches/real_world/meshes/halftunnel.off \\
        halftunnel:winding=benches/real_world/meshes/halftunnel.off ...

Each NAME=PATH runs the main job at its defaults (`NAME:winding=PATH` with
`--solid winding`, the capped solid for comparison) and keeps from its report the rule,
why it was chosen, the caps' share of the input's area (`solid.cap_area_share`), the
band's half-thickness and the sites it would need for τ (thin shell), and the four
metrics against the input as given. Writes OUT (JSON, `rows`) and OUT.provenance.json
(the command, the commit of the binary's tree, each input's SHA-256). With
`--baseline-bin`, each row also has the older binary's figures as `FIELD_before` and the
number of solid-guard mirrors of both (`mirrors`, `mirrors_before`). Standard library only.
"""
import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def row(exe, name, path, work):
    base, _, variant = name.partition(":")
    out = Path(work) / f"{name.replace(':', '_')}.glb"
    cmd = [str(exe), str(path), "-o", str(out), "--quiet"]
    if variant:
        cmd += ["--solid", variant]
    t = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.time() - t
    if r.returncode != 0:
        return {"mesh": base, "variant": variant or "auto", "status": f"exit {r.returncode}", "stderr": r.stderr[-2000:]}
    rep = json.loads(out.with_suffix(".report.json").read_text())
    s, m = rep["solid"], rep["metrics"]
    d = m["reference_diagonal"]
    band = s.get("sheet_band") or {}
    return {
        "mesh": base,
        "variant": variant or "auto",
        "status": "ok",
        "rule": s["rule"],
        "chosen_by": s["chosen_by"],
        "cap_area_share": s.get("cap_area_share"),
        "cap_area_pct": None if s.get("cap_area_share") is None else 100.0 * s["cap_area_share"],
        "half_thickness_pct": None if s.get("half_thickness_of_diagonal") is None else 100.0 * s["half_thickness_of_diagonal"],
        "sites_for_tau": band.get("sites_for_tau"),
        "hausdorff_pct": 100.0 * m["hausdorff"]["hi"] / d,
        "chamfer_pct": 100.0 * m["surface"]["chamfer_l1"] / d,
        "fscore": m["surface"]["fscore"],
        "normal_consistency": m["surface"]["normal_consistency"],
        "crust_closed": rep["crust"]["is_closed"],
        "mirrors": sum((rep.get("guard") or {}).get("solid_mirrors_per_round") or []),
        "seconds": seconds,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("meshes", nargs="+", help="NAME=PATH or NAME:winding=PATH")
    ap.add_argument("--bin", required=True)
    ap.add_argument("--baseline-bin", help="an older binary run on the same meshes (fields FIELD_before)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--source", action="append", default=[], help="NAME=where it comes from (provenance)")
    a = ap.parse_args()
    sources = dict(s.split("=", 1) for s in a.source)
    rows, inputs = [], {}
    with tempfile.TemporaryDirectory() as work:
        for spec in a.meshes:
            name, _, path = spec.partition("=")
            path = Path(path)
            inputs[name.split(":")[0]] = {
                "path": str(path),
                "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
                "source": sources.get(name.split(":")[0], ""),
            }
            r = row(a.bin, name, path, work)
            if a.baseline_bin:
                old = row(a.baseline_bin, name, path, work)
                r.update({f"{k}_before": v for k, v in old.items() if k not in ("mesh", "variant")})
            print(json.dumps(r), flush=True)
            rows.append(r)
    out = Path(a.out)
    out.write_text(json.dumps({"rows": rows}, indent=1) + "\n")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT).stdout.strip()
    prov = {
        "command": "python3 benches/caps_share.py " + " ".join(sys.argv[1:]),
        "commit": commit,
        "date": time.strftime("%Y-%m-%d"),
        "inputs": inputs,
    }
    Path(str(out) + ".provenance.json").write_text(json.dumps(prov, indent=2) + "\n")


if __name__ == "__main__":
    main()
