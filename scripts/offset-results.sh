#!/usr/bin/env bash
# Scenes far from the origin: `homcull accuracy --offset` on each shared scene moved by 0, 1e3,
# 1e4, 1e5 and 1e6 (along x and z), culled by the default culler from random views (eye anywhere
# in the scene's free space, any direction) and from walk views, judged against Embree on the
# unmoved scene, as a Markdown table on stdout: false culls, and the efficiency over every hidden
# object and over those hidden outright, beside the unmoved scene's.
#   bash scripts/offset-results.sh [VIEWS] [RESOLUTION]    (defaults: 20 views, 1280x720)
# Needs a build (scripts/build.sh) and ../shared/scenes beside the repository. HOMCULL may
# name another binary. Progress goes to stderr; each run's JSON is kept in $OUT (a temp dir).
set -euo pipefail
cd "$(dirname "$0")/.."
views=${1:-20}
resolution=${2:-1280x720}
homcull=${HOMCULL:-build/tools/homcull/homcull}
scenes=../shared/scenes
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
command -v jq >/dev/null || { echo "offset-results: jq is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
[ -x "$homcull" ] || { echo "offset-results: $homcull not built (bash scripts/build.sh)" >&2; exit 2; }

offsets=(0 1e3 1e4 1e5 1e6)
echo "| scene | views | false culls at offset ${offsets[*]} (through ties only) | efficiency at each offset | over objects hidden outright |"
echo "|---|---|---|---|---|"
for scene in intel_castle crytek_sponza openarena_oa_thor openarena_pul1duel-oa fzk_haus; do
  file=$scenes/$scene.glb
  [ -f "$file" ] || { echo "offset-results: $file missing, skipped" >&2; continue; }
  occluders=all
  [ "$scene" = intel_castle ] && occluders=role  # the castle marks its occluders
  for kind in random walk; do
    runs=()
    for offset in "${offsets[@]}"; do
      json=$out/$scene.$kind.$offset.json
      echo "offset-results: $scene, $kind views, offset $offset" >&2
      "$homcull" accuracy --scene "$file" "--$kind" "$views" --resolution "$resolution" --occluders "$occluders" \
        --offset "$offset,0,$offset" --json >"$json"
      runs+=("$json")
    done
    # One row: the false culls at each offset, and each efficiency that occurs (one when the
    # offsets agree, as they should).
    jq -rs --arg scene "$scene" --arg kind "$views $kind" '
      "| \($scene) | \($kind) | \(map("\(.false_culls) (\(.false_culls - .robust_false_culls))") | join(", ")) | \(map("\((.efficiency*1000|round)/10) % (\(.culled_hidden)/\(.hidden_in_frustum))") | unique | join(" / ")) | \(map("\((.robust_efficiency*1000|round)/10) %") | unique | join(" / ")) |"' "${runs[@]}"
  done
done
echo "offset-results: JSON in $out" >&2
