#!/usr/bin/env bash
# Ablation of the main job's default (README table "Which part buys what"): each variant
# switches one part of the default off, on the bundled bunny and two shared meshes, and
# prints a Markdown table of the `eval` metrics the report carries (Hausdorff and Chamfer
# as % of the input's bounding-box diagonal, F-score at 0.3%, normal consistency,
# misclassification). Run from the repository root:
#
#   bash benches/ablation.sh [MESH ...]
#
# Needs the release binary (cargo build --release) or VF_BIN; writes into target/ablation.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${VF_BIN:-target/release/voronoi-fit}
OUT=target/ablation
mkdir -p "$OUT"
MESHES=("$@")
if [ ${#MESHES[@]} -eq 0 ]; then
  MESHES=(assets/bunny.obj ../shared/meshes/alecjacobson__spot.obj ../shared/meshes/mikedh__featuretype.STL)
fi
declare -a NAMES=(
  "first default (random pairs, δ = ¼ spacing, seed losses only, lr 3e-5)"
  "pairs init, seed losses only"
  "default without the polish (the previous default)"
  "default without the polish and the normal alignment"
  "default without carving"
  "default without soft-Voronoi training (polish straight from the pairs)"
  "default"
)
declare -a FLAGS=(
  "--init surface --surface-offset 0.25 --lr 3e-5 --w-surface 0 --w-normal 0 --no-polish --no-relabel --no-carve"
  "--w-surface 0 --w-normal 0 --no-polish --no-relabel --no-carve"
  "--no-polish"
  "--no-polish --w-normal 0"
  "--no-carve"
  "--steps 0"
  ""
)
echo "| mesh | variant | Hausdorff % | Chamfer L1 % | F-score | normal consistency | misclassified % | seconds |"
echo "|---|---|---|---|---|---|---|---|"
for mesh in "${MESHES[@]}"; do
  stem=$(basename "${mesh%.*}")
  for i in "${!NAMES[@]}"; do
    out="$OUT/$stem-$i.glb"
    # shellcheck disable=SC2086
    "$BIN" "$mesh" -o "$out" --quiet --json ${FLAGS[$i]} > "$OUT/$stem-$i.json"
    python3 - "$OUT/$stem-$i.json" "$stem" "${NAMES[$i]}" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
m = r["metrics"]; s = m["surface"]; d = s["fscore_tau"] / 0.003
print(f"| {sys.argv[2]} | {sys.argv[3]} | {100*m['hausdorff']['hi']/d:.2f} | {100*s['chamfer_l1']/d:.4f} | "
      f"{s['fscore']:.4f} | {s['normal_consistency']:.4f} | {100*r['quality']['misclassification']:.3f} | {r['total_seconds']:.0f} |")
PY
  done
done
