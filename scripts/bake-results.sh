#!/usr/bin/env bash
# The occluder-ranking table of docs/scene-culling.md: on the castle, one-pass culling under a
# triangle budget with the candidates ranked by distance, by projected area, or by a baked
# visibility grid (homcull bake), with and without occluder LODs; several generated walks,
# Embree ground truth. Markdown on stdout.
#   bash scripts/bake-results.sh [FRAMES] [RESOLUTION] [SEEDS]   (defaults: 120, 640x360, "1 7 13")
# BUDGETS="2000 4000 10000" (the default) chooses the rows.
# Needs a build (scripts/build.sh), jq, and ../shared/scenes beside the repository. HOMCULL may
# name another binary. Progress goes to stderr; JSON and the grid are kept in $OUT (a temp dir).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-120}
resolution=${2:-640x360}
seeds=${3:-1 7 13}
homcull=${HOMCULL:-build/tools/homcull/homcull}
file=../shared/scenes/intel_castle.glb
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
command -v jq >/dev/null || { echo "bake-results: jq is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
[ -x "$homcull" ] || { echo "bake-results: $homcull not built (bash scripts/build.sh)" >&2; exit 2; }
[ -f "$file" ] || { echo "bake-results: $file missing" >&2; exit 2; }

"$homcull" bake --scene "$file" --out "$out/castle.grid.json" --quiet >&2
for seed in $seeds; do
  "$homcull" path --scene "$file" --frames "$frames" --seed "$seed" --out "$out/path.$seed.json" >&2
done

runs=("distance|off" "area|off" "baked|off" "distance|on" "baked|on")
header="| budget (triangles) |"
rule="|---|"
for run in "${runs[@]}"; do
  IFS='|' read -r rank lod <<<"$run"
  label=$rank
  if [ "$lod" = on ]; then label="$rank + LOD"; fi
  header="$header $label |"
  rule="$rule---|"
done
echo "$header"
echo "$rule"
for budget in ${BUDGETS:-2000 4000 10000}; do
  row="| $budget |"
  for run in "${runs[@]}"; do
    IFS='|' read -r rank lod <<<"$run"
    hidden=0 culled=0 false_culls=0
    for seed in $seeds; do
      grid=()
      [ "$rank" = baked ] && grid=(--grid "$out/castle.grid.json")
      json=$out/walk.$budget.$rank.$lod.$seed.json
      echo "bake-results: budget $budget, $rank, LOD $lod, path $seed" >&2
      "$homcull" walk --scene "$file" --path "$out/path.$seed.json" --resolution "$resolution" --strategy one-pass \
        --rank "$rank" "${grid[@]}" --budget "$budget" --lod "$lod" --quiet --json >"$json"
      read -r h m f < <(jq -r '[([.frames[].hidden_in_frustum]|add), ([.frames[].missed_culls]|add), .summary.total_false_culls] | @tsv' "$json")
      hidden=$((hidden + h)); culled=$((culled + h - m)); false_culls=$((false_culls + f))
    done
    row="$row $(jq -n --argjson c "$culled" --argjson h "$hidden" '($c * 1000 / $h | round) / 10') %"
    if [ "$false_culls" != 0 ]; then row="$row ($false_culls FALSE CULLS)"; fi
    row="$row |"
  done
  echo "$row"
done
echo "bake-results: JSON in $out" >&2
