"""Shared fixtures for the Python reference checks.

Environment (set by tests/run.sh):
  VF_BIN            the built voronoi-fit binary
  VF_ROOT           the repository root
  VF_NODE_DIR       folder with node_modules/gltf-validator
  VF_SHARED_MESHES  ../shared/meshes (the public test meshes)
"""
import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(os.environ.get("VF_ROOT", Path(__file__).resolve().parents[2]))
BIN = Path(os.environ.get("VF_BIN", ROOT / "target" / "ci" / "voronoi-fit"))
NODE_DIR = Path(os.environ.get("VF_NODE_DIR", ROOT / "target" / "node"))
SHARED = Path(os.environ.get("VF_SHARED_MESHES", ROOT.parent / "shared" / "meshes"))

MESH_EXTS = {".obj", ".stl", ".ply", ".off", ".gltf", ".glb"}


def corpus():
    """Every real mesh: ../shared/meshes (scans, CAD, soups, open, GLB) and assets/."""
    files = sorted(p for p in SHARED.glob("*") if p.suffix.lower() in MESH_EXTS)
    assert files, f"no meshes found in {SHARED}; the shared meshes must sit beside the repository"
    files += sorted(p for p in (ROOT / "assets").glob("*") if p.suffix.lower() in MESH_EXTS)
    return files


def run(*args, check=True):
    """Run the CLI; return the CompletedProcess (text mode)."""
    r = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"voronoi-fit {' '.join(map(str, args))} exited {r.returncode}:\n{r.stderr}")
    return r


def info(path):
    return json.loads(run("info", "--json", path).stdout)


def validate_gltf(path):
    """Run the Khronos glTF validator on a file; return its JSON report."""
    script = (
        "const v=require('gltf-validator');const fs=require('fs');const path=require('path');"
        "const f=process.argv[1];const data=new Uint8Array(fs.readFileSync(f));"
        "v.validateBytes(data,{uri:f,maxIssues:100,externalResourceFunction:(u)=>"
        "new Promise((ok,no)=>{try{ok(new Uint8Array(fs.readFileSync(path.join(path.dirname(f),decodeURIComponent(u)))))}catch(e){no(e.toString())}})})"
        ".then(r=>console.log(JSON.stringify(r))).catch(e=>{console.error(e);process.exit(3)});"
    )
    r = subprocess.run(
        ["node", "-e", script, str(path)],
        capture_output=True,
        text=True,
        env={**os.environ, "NODE_PATH": str(NODE_DIR / "node_modules")},
    )
    assert r.returncode == 0, f"the glTF validator failed to run on {path}: {r.stderr}"
    return json.loads(r.stdout)


def assert_gltf_valid(path):
    rep = validate_gltf(path)
    issues = rep["issues"]
    bad = [m for m in issues["messages"] if m["severity"] <= 1]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, f"{path}: {json.dumps(bad, indent=1)}"
    return rep


@pytest.fixture(scope="session")
def bin_path():
    assert BIN.exists(), f"{BIN} is missing: build with cargo build --profile ci"
    return BIN
