#!/usr/bin/env bash
# The results table of docs/visibility-sorting.md: `homcull sort` on the paper's toothpicks
# (200 at the default scale, 1,600 at uniform density, tumbling in front of one camera, every
# object sorted as in the paper) and along walks of the shared scenes (the objects in the view
# frustum), one thread, with every frame checked against Embree's occlusion edges.
#   bash scripts/sort-results.sh [FRAMES] [ROUNDS]      (defaults: 100 frames, 3 rounds)
# Needs a build (scripts/build.sh) and ../shared/scenes beside the repository. HOMCULL may
# name another binary. Progress goes to stderr; each run's JSON is kept in $OUT (a temp dir).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-100}
rounds=${2:-3}
homcull=${HOMCULL:-build/tools/homcull/homcull}
scenes=../shared/scenes
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
command -v jq >/dev/null || { echo "sort-results: jq is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
[ -x "$homcull" ] || { echo "sort-results: $homcull not built (bash scripts/build.sh)" >&2; exit 2; }

row() {  # name, json file
  jq -r --arg name "$1" '.summary as $s | .frames as $f |
    "| \($name) | \($s.frames) | \($s.objects) | \($f | map(.sorted) | add / length | floor) | \($s.mean_ms * 1000 | round / 1000) | \($s.worst_ms * 1000 | round / 1000) | \($s.mean_stages_ms.extents * 1000 | round / 1000) / \($s.mean_stages_ms.tree * 1000 | round / 1000) / \($s.mean_stages_ms.order * 1000 | round / 1000) | \($s.hull_tests_per_frame | floor) | \($s.percent_in_cycles * 10 | round / 10) % | \($s.mean_cycle_size * 100 | round / 100) | \($f | map(.cycles | map(length) | max // 0) | max) | \($s.check.violations) | \($s.check.needlessly_grouped / ($f | map(.sorted) | add) * 1000 | round / 10) % |"' "$2"
}

echo "| scene | frames | objects | sorted (mean) | mean ms | worst ms | extents / tree / order ms | hull tests | in cycles | mean cycle | largest | violations | grouped outside a true cycle |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
echo "sort-results: toothpicks, 200" >&2
"$homcull" sort --scene gen:toothpicks:count=200 --eye 0,4,24 --target 0,0,0 --fov-y 40 --resolution 640x480 \
  --frames "$frames" --rounds "$rounds" --all-directions --check --json > "$out/toothpicks200.json"
row "toothpicks, 200" "$out/toothpicks200.json"
echo "sort-results: toothpicks, 1600 at uniform density" >&2
"$homcull" sort --scene gen:toothpicks:count=1600,density=uniform --eye 0,8,48 --target 0,0,0 --fov-y 40 --resolution 640x480 \
  --frames "$frames" --rounds "$rounds" --all-directions --check --json > "$out/toothpicks1600.json"
row "toothpicks, 1,600 uniform" "$out/toothpicks1600.json"
for scene in intel_castle crytek_sponza fzk_haus openarena_oa_thor openarena_pul1duel-oa; do
  file=$scenes/$scene.glb
  [ -f "$file" ] || { echo "sort-results: $file missing, skipped" >&2; continue; }
  echo "sort-results: $scene, walk of $frames frames" >&2
  "$homcull" sort --scene "$file" --walk "$frames" --resolution 640x360 --rounds "$rounds" --check --json > "$out/$scene.json"
  row "$scene walk" "$out/$scene.json"
done
