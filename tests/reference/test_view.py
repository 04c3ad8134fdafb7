"""The main job's picture (OUT.png) and `voronoi-fit view`'s page, opened in a real
headless browser (Debian's chromium, driven by playwright-core from VF_NODE_DIR).

Nothing here is skipped: without /usr/bin/chromium (tests/run.sh installs it) or
playwright-core (tests/package.json) the browser test fails.
"""
import json
import os
import shutil
import struct
import subprocess
from pathlib import Path

import pytest

from conftest import NODE_DIR, ROOT, run

CHROMIUM = Path(os.environ.get("VF_CHROMIUM", "/usr/bin/chromium"))
CHECK_PAGE = ROOT / "tests" / "browser" / "check_page.mjs"


@pytest.fixture(scope="module")
def quick_fit(tmp_path_factory):
    """A small, quick fit of the bundled bunny: OUT.glb, .sites.npz, .report.json, .png
    and (--html) .html."""
    d = tmp_path_factory.mktemp("view")
    out = d / "bunny.glb"
    run(ROOT / "assets" / "bunny.obj", "-o", out, "--sites", "1024", "--steps", "40",
        "--samples", "100000", "--eval-samples", "20000", "--polish-steps", "100", "--quiet", "--html")
    return out


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def check_page(html, shot, timeout_ms=90000):
    assert CHROMIUM.exists(), f"{CHROMIUM} is missing: tests/run.sh installs Debian's chromium and chromium-driver"
    assert (NODE_DIR / "node_modules" / "playwright-core").is_dir(), \
        f"playwright-core is missing in {NODE_DIR}: tests/run.sh npm-installs tests/package.json there"
    r = subprocess.run(["node", str(CHECK_PAGE), str(html), str(shot), str(timeout_ms)],
                       capture_output=True, text=True, timeout=timeout_ms / 1000 + 60,
                       env={**os.environ, "VF_NODE_DIR": str(NODE_DIR), "VF_CHROMIUM": str(CHROMIUM)})
    assert r.returncode == 0, f"the browser check failed (exit {r.returncode}):\n{r.stdout}\n{r.stderr}"
    return json.loads(r.stdout)


def test_fit_writes_a_picture_beside_its_outputs(quick_fit):
    png = quick_fit.with_suffix(".png")
    assert png.exists()
    # Two rows (input, crust) of three 400×400 views under a 28-pixel title.
    assert png_size(png) == (1200, 828)
    # Every cell shows its mesh: a plausible share of pixels is not background (the
    # background is a light grey-blue, every channel ≥ 218).
    from PIL import Image
    import numpy as np
    img = np.asarray(Image.open(png).convert("RGB")).astype(int)
    for row in range(2):
        for col in range(3):
            cell = img[28 + row * 400 + 22: 28 + (row + 1) * 400 - 2, col * 400 + 2: (col + 1) * 400 - 2]
            share = float((cell.min(axis=2) < 218).mean())
            assert 0.1 < share < 0.8, f"cell {row},{col}: {share:.3f} of its pixels drawn"
    # Input (warm grey) above, crust (sky blue) below.
    top, bottom = img[28:428], img[428:]
    assert (bottom[..., 2] - bottom[..., 0]).max() > 100 and (top[..., 2] - top[..., 0]).max() < 60
    assert not list(quick_fit.parent.glob("*.tmp*")), "a temporary file was left behind"
    # --html wrote the viewer page beside them, with every part.
    html = quick_fit.with_suffix(".html").read_text()
    for part in ('"input"', '"crust"', '"inside"', '"wrong"', "Training losses"):
        assert part in html, part


def test_view_page_opens_offline_in_chromium(quick_fit, tmp_path):
    page = tmp_path / "bunny.html"
    cells = tmp_path / "cells.glb"
    run("crust", quick_fit.with_suffix(".sites.npz"), "-o", tmp_path / "crust.glb", "--cells", cells)
    r = run("view", quick_fit, "--cells", cells, "-o", page)
    assert page.exists() and "Wrote" in r.stdout
    html = page.read_text()
    # Self-contained: no external script, style or fetch.
    for needle in ('src="http', "src='http", 'href="http', "import('http", 'from"http', "from 'http"):
        assert needle not in html, f"the page refers to the network: {needle}"
    # The vendored library's licence travels with it.
    assert "Permission is hereby granted" in html and "three.js authors" in html
    res = check_page(page, tmp_path / "shot.png")
    assert res["ready"] == "1", res
    assert res["console_errors"] == [] and res["page_errors"] == [], res
    assert res["network_requests"] == [], res
    # Input and crust side by side fill a plausible share of the 3D canvas.
    assert 0.05 < res["coverage"] < 0.9, res
    assert res["stats"]["triangles"] > 3000, res
    # Every part is on the page, and every control works (no error after toggling).
    assert set(res["toggled"]) == {"vf-wire", "vf-side", "vf-show-input", "vf-show-crust", "vf-show-inside",
                                   "vf-show-outside", "vf-show-wrong", "vf-show-cells"}, res
    assert png_size(tmp_path / "shot.png")[0] > 600
    # The report's parts are on the page.
    assert "Training losses" in html and "<svg" in html and "Stage timings" in html
    assert '"wrong"' in html, "misclassified points missing"


def test_view_defaults_and_partial_pages(quick_fit, tmp_path):
    # Only the crust: a page without input, sites and report; notes say what is missing.
    lone = tmp_path / "lone.glb"
    shutil.copy(quick_fit, lone)
    r = run("view", lone)
    assert (tmp_path / "lone.html").exists()
    assert "no report" in r.stderr and "no sites file" in r.stderr


def test_view_errors_leave_no_page(quick_fit, tmp_path):
    out = tmp_path / "p.html"
    # A file named by a flag must exist.
    r = run("view", quick_fit, "--report", tmp_path / "missing.json", "-o", out, check=False)
    assert r.returncode == 2 and "missing.json" in r.stderr and not out.exists()
    # A malformed report beside the crust is an error, not ignored.
    crust = tmp_path / "c.glb"
    shutil.copy(quick_fit, crust)
    (tmp_path / "c.report.json").write_text("{ not json")
    r = run("view", crust, "-o", out, check=False)
    assert r.returncode == 2 and "c.report.json" in r.stderr and not out.exists()
    (tmp_path / "c.report.json").write_text('{"format_version": 7}')
    r = run("view", crust, "-o", out, check=False)
    assert r.returncode == 2 and "format_version 7" in r.stderr and not out.exists()
    # A malformed sites file beside the crust.
    (tmp_path / "c.report.json").unlink()
    (tmp_path / "c.sites.npz").write_bytes(b"not an npz")
    r = run("view", crust, "-o", out, check=False)
    assert r.returncode == 2 and "c.sites.npz" in r.stderr and not out.exists()
    # No crust; an output that is not .html.
    r = run("view", tmp_path / "none.glb", "-o", out, check=False)
    assert r.returncode == 2 and not out.exists()
    r = run("view", quick_fit, "-o", tmp_path / "p.txt", check=False)
    assert r.returncode == 2 and not (tmp_path / "p.txt").exists()
    assert not list(tmp_path.glob("*.tmp*"))


def test_python_view_writes_the_same_self_contained_page(quick_fit, tmp_path):
    """`voronoi_fit.view` calls the same library as `voronoi-fit view`: the page is written,
    self-contained, embeds the meshes, and equals the CLI's byte for byte (same inputs,
    no fresh samples, so nothing random)."""
    import base64
    import warnings

    import numpy as np
    import voronoi_fit as vf

    cli_page, py_page = tmp_path / "cli.html", tmp_path / "py.html"
    run("view", quick_fit, "-o", cli_page, "--check-samples", "0")
    got = vf.view(quick_fit, out=py_page, check_samples=0)
    assert got == py_page and py_page.is_file()
    html = py_page.read_text()
    assert html == cli_page.read_text().replace(str(cli_page), str(py_page))
    for needle in ('src="http', "src='http", 'href="http', "from 'http"):
        assert needle not in html
    # The embedded crust is the GLB's: its triangle count and vertex positions.
    meta = json.loads(html.split('id="vf-meta">', 1)[1].split("</script>", 1)[0].replace("<\\/", "</"))
    crust_v, crust_f = vf.load_mesh(quick_fit)
    assert meta["meshes"]["crust"]["triangles"] == len(crust_f)
    blob = html.split(f'id="{meta["meshes"]["crust"]["positions"]}">', 1)[1].split("</script>", 1)[0]
    pos = np.frombuffer(base64.b64decode(blob), "<f4").reshape(-1, 3) + np.array(meta["center"])
    assert np.allclose(np.sort(pos, axis=0), np.sort(crust_v, axis=0), atol=1e-4 * meta["radius"])
    assert "input" in meta["meshes"] and "inside" in meta["points"]
    # Defaults beside the crust; a lone crust warns what it left out; a missing file given
    # explicitly raises InputError and writes nothing.
    lone = tmp_path / "lone.glb"
    shutil.copy(quick_fit, lone)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        assert vf.view(lone) == tmp_path / "lone.html"
    assert any("no report" in str(x.message) for x in w)
    with pytest.raises(vf.InputError, match="missing.json"):
        vf.view(quick_fit, report=tmp_path / "missing.json", out=tmp_path / "x.html")
    assert not (tmp_path / "x.html").exists()
