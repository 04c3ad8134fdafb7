#!/usr/bin/env bash
# The whole test suite, on a fresh machine: the one command the README names and .ci/run
# calls.
#
#   1. a Python venv under target/venv with the pinned reference libraries
#      (tests/requirements.txt: libigl, trimesh, numpy, scipy, pytest);
#   2. the Khronos glTF validator (npm gltf-validator) and playwright-core under
#      target/node, and Debian's chromium + chromium-driver (apt-get, when absent) for the
#      viewer page test;
#   3. cargo test --workspace in the `ci` profile (release speed with debug assertions);
#   4. the Python package (crates/python) built with maturin and installed into the venv;
#   5. the Python reference checks in tests/reference against the built binary and package.
#
# Any failed step fails the run. The last line is `N passed, N failed`.
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
STARTED=$(date +%s)
TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
LOG=$TARGET/test-logs
mkdir -p "$LOG"
passed=0
failed=0
step_failed=()

note() { printf '\n=== %s\n' "$*"; }

note "Python reference venv ($TARGET/venv)"
VENV=$TARGET/venv
stamp=$VENV/.requirements.sha
want=$(sha256sum tests/requirements.txt | cut -d' ' -f1)
if [ ! -x "$VENV/bin/python" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  rm -rf "$VENV"
  if python3 -m venv "$VENV" && "$VENV/bin/pip" install -q --disable-pip-version-check -r tests/requirements.txt; then
    echo "$want" > "$stamp"
  else
    step_failed+=("python venv")
  fi
fi

note "glTF validator ($TARGET/node)"
NODE_DIR=$TARGET/node
if [ ! -f "$NODE_DIR/node_modules/gltf-validator/package.json" ] || [ ! -f "$NODE_DIR/node_modules/playwright-core/package.json" ] || ! cmp -s tests/package.json "$NODE_DIR/package.json"; then
  mkdir -p "$NODE_DIR"
  cp tests/package.json "$NODE_DIR/package.json"
  (cd "$NODE_DIR" && npm install --no-audit --no-fund --loglevel=error) || step_failed+=("npm install")
fi

note "Chromium for the viewer page test (tests/browser, tests/reference/test_view.py)"
# Debian's chromium and chromium-driver; installed here when absent. If that fails, the
# step fails (and so does the browser test): nothing is skipped silently.
if [ ! -x /usr/bin/chromium ] || [ ! -x /usr/bin/chromedriver ]; then
  if [ "$(id -u)" -eq 0 ]; then as_root=(); else as_root=(sudo -n); fi
  if "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q > "$LOG/apt-chromium.log" 2>&1 \
     && "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q chromium chromium-driver >> "$LOG/apt-chromium.log" 2>&1; then
    echo "installed: $(/usr/bin/chromium --version 2>/dev/null)"
  else
    echo "apt-get could not install chromium and chromium-driver (log: $LOG/apt-chromium.log)"
    step_failed+=("install chromium")
  fi
fi
[ -x /usr/bin/chromium ] || step_failed+=("chromium missing")

note "cargo test --workspace --profile ci"
# GLB/glTF files written by the Rust tests land here for the validator (pytest, below).
export VF_GLB_OUT=$TARGET/test-output/gltf
rm -rf "$VF_GLB_OUT"
# The occupancy issue's accuracy figure is stated on 1M queries per mesh; run it in full.
export VF_OCC_QUERIES=${VF_OCC_QUERIES:-1000000}
cargo build --profile ci --workspace --bins 2>&1 | tail -n 3
cargo test --workspace --profile ci --no-fail-fast 2>&1 | tee "$LOG/cargo.log"
cargo_rc=${PIPESTATUS[0]}
read -r cp cf < <(awk '/^test result:/ { for (i = 1; i <= NF; i++) { if ($(i+1) ~ /^passed/) p += $i; if ($(i+1) ~ /^failed/) f += $i } } END { print p+0, f+0 }' "$LOG/cargo.log")
passed=$((passed + cp)); failed=$((failed + cf))
if [ "$cargo_rc" -ne 0 ] && [ "$cf" -eq 0 ]; then step_failed+=("cargo test (exit $cargo_rc)"); fi

note "Python package (maturin build --profile ci, installed into $VENV)"
# The wheel the README's one-line install builds, here in the ci profile so it reuses the
# crates cargo test just built; tests/reference/test_python.py imports it.
rm -rf "$TARGET/wheels"
if "$VENV/bin/maturin" build --profile ci -m crates/python/Cargo.toml --out "$TARGET/wheels" -i "$VENV/bin/python" > "$LOG/maturin.log" 2>&1 \
   && "$VENV/bin/pip" install -q --disable-pip-version-check --force-reinstall --no-deps "$TARGET"/wheels/voronoi_fit-*.whl >> "$LOG/maturin.log" 2>&1; then
  tail -n 1 "$LOG/maturin.log"
else
  tail -n 20 "$LOG/maturin.log"
  step_failed+=("python package build")
fi

note "Python reference checks (pytest tests/reference)"
export VF_BIN=$TARGET/ci/voronoi-fit
export VF_ROOT=$ROOT
export VF_NODE_DIR=$NODE_DIR
export VF_SHARED_MESHES=${VF_SHARED_MESHES:-$ROOT/../shared/meshes}
export VF_SHARED_MNIST=${VF_SHARED_MNIST:-$ROOT/../shared/mnist}
if [ -x "$VENV/bin/python" ]; then
  "$VENV/bin/python" -m pytest tests/reference -q -p no:cacheprovider --junitxml="$LOG/pytest.xml" 2>&1 | tee "$LOG/pytest.log"
  py_rc=${PIPESTATUS[0]}
  read -r pp pf < <("$VENV/bin/python" - "$LOG/pytest.xml" <<'PY'
import sys, xml.etree.ElementTree as ET
try:
    r = ET.parse(sys.argv[1]).getroot()
    s = r if r.tag == "testsuite" else r.find("testsuite")
    t, f, e, k = (int(s.get(a, 0)) for a in ("tests", "failures", "errors", "skipped"))
    print(t - f - e - k, f + e)
except Exception:
    print(0, 0)
PY
)
  passed=$((passed + pp)); failed=$((failed + pf))
  if [ "$py_rc" -ne 0 ] && [ "$pf" -eq 0 ]; then step_failed+=("pytest (exit $py_rc)"); fi
else
  step_failed+=("pytest (no venv)")
fi

echo
if [ ${#step_failed[@]} -gt 0 ]; then
  echo "failed steps: ${step_failed[*]}"
  failed=$((failed + ${#step_failed[@]}))
fi
# A machine-readable record of this run (benches/results/test_suite.json is a committed
# copy of one, the source of the docs' test count and suite time).
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
printf '{"command": "bash tests/run.sh", "commit": "%s", "date": "%s", "passed": %d, "failed": %d, "seconds": %d, "cargo_passed": %d, "pytest_passed": %d}\n' \
  "$commit" "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "$passed" "$failed" "$(( $(date +%s) - STARTED ))" "${cp:-0}" "${pp:-0}" > "$LOG/suite.json"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
