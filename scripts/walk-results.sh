#!/usr/bin/env bash
# The results table of docs/scene-culling.md: every strategy of `homcull walk` on generated
# walkthroughs of the shared scenes, with Embree ground truth, as a Markdown table on stdout.
# Also one-pass under a 4,000-triangle budget ranked by distance and by a baked visibility
# grid (baked here, per scene), one-pass with occluder LODs, and every object an occluder (no
# complexity filter either).
#   bash scripts/walk-results.sh [FRAMES] [RESOLUTION]      (defaults: 120 frames, 1280x720)
# Needs a build (scripts/build.sh) and ../shared/scenes beside the repository. HOMCULL may
# name another binary. Progress goes to stderr; each walk's JSON is kept in $OUT (a temp dir).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-120}
resolution=${2:-1280x720}
homcull=${HOMCULL:-build/tools/homcull/homcull}
scenes=../shared/scenes
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
command -v jq >/dev/null || { echo "walk-results: jq is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
[ -x "$homcull" ] || { echo "walk-results: $homcull not built (bash scripts/build.sh)" >&2; exit 2; }

echo "| scene | strategy | candidates | efficiency | false culls | occluder tris (mean) | select | render | maps | tests | cull ms mean (max) | kept (mean) | exactly visible (mean) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for scene in intel_castle crytek_sponza openarena_oa_thor openarena_pul1duel-oa fzk_haus; do
  file=$scenes/$scene.glb
  [ -f "$file" ] || { echo "walk-results: $file missing, skipped" >&2; continue; }
  "$homcull" path --scene "$file" --frames "$frames" --seed 1 --out "$out/$scene.path.json" >&2
  # The castle marks its occluders; the other scenes get Zhang's size filter.
  candidates=auto
  [ "$scene" = intel_castle ] && candidates=role
  echo "walk-results: $scene, baking its visibility grid" >&2
  "$homcull" bake --scene "$file" --occluders "$candidates" --quiet --out "$out/$scene.grid.json" >&2
  runs=("one-pass|$candidates|" "temporal|$candidates|" "progressive|$candidates|"
        "one-pass|$candidates|--rank distance --budget 4000"
        "one-pass|$candidates|--rank baked --grid $out/$scene.grid.json --budget 4000"
        "one-pass|$candidates|--lod on" "one-pass|all|--complexity 0")
  for run in "${runs[@]}"; do
    IFS='|' read -r strategy occluders extra <<<"$run"
    name="$strategy${extra:+ ($extra)}"
    name=${name/ --grid $out\/$scene.grid.json/}
    tag=${extra// /_}
    json=$out/$scene.$strategy.$occluders.${tag//\//_}.json
    echo "walk-results: $scene, $name, occluders $occluders" >&2
    # shellcheck disable=SC2086
    "$homcull" walk --scene "$file" --path "$out/$scene.path.json" --resolution "$resolution" --strategy "$strategy" \
      --occluders "$occluders" $extra --quiet --json >"$json"
    jq -r --arg scene "$scene" --arg name "$name" --arg occ "$occluders" '.summary as $s |
      "| \($scene) | \($name) | \($occ) | \(($s.efficiency*1000|round)/10) % | \($s.total_false_culls) | \($s.occluder_triangles.mean|round) | \(($s.select_ms.mean*100|round)/100) | \(($s.render_ms.mean*100|round)/100) | \(($s.maps_ms.mean*100|round)/100) | \(($s.tests_ms.mean*100|round)/100) | \(($s.cull_ms.mean*100|round)/100) (\(($s.cull_ms.max*10|round)/10)) | \(($s.objects_after_occlusion.mean*10|round)/10) | \(($s.objects_exactly_visible.mean*10|round)/10) |"' "$json"
  done
done
echo "walk-results: JSON in $out" >&2
