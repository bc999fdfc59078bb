#!/usr/bin/env bash
# The results table of docs/occlusion-maps.md ("Results"): `homcull accuracy` on 20 walk views
# of each shared scene, per culling mode, depth test and occlusion buffer, against Embree at
# the display's pixel centres, as a Markdown table on stdout: efficiency (over every hidden
# object and over those hidden outright), false culls, and the time per view of each stage.
#   bash scripts/maps-results.sh [RESOLUTION]      (default: 1920x1080)
# Needs a build (scripts/build.sh) and ../shared/scenes beside the repository. HOMCULL may
# name another binary. Progress goes to stderr; each run's JSON is kept in $OUT (a temp dir).
set -euo pipefail
cd "$(dirname "$0")/.."
resolution=${1:-1920x1080}
homcull=${HOMCULL:-build/tools/homcull/homcull}
scenes=../shared/scenes
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
command -v jq >/dev/null || { echo "maps-results: jq is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
[ -x "$homcull" ] || { echo "maps-results: $homcull not built (bash scripts/build.sh)" >&2; exit 2; }

# name|options (the defaults: conservative, masked depth, occludee triangles sample by sample
# with per-sample depth, a buffer with one sample per display pixel)
configs=(
  "defaults|"
  "boxes only|--occludees box"
  "hzb|--depth hzb"
  "deb|--depth deb"
  "plane|--depth plane"
  "nbz (not conservative)|--depth nbz"
  "buffer 480x270 S=4|--buffer 480x270 --samples 4"
  "approximate L=16|--mode approximate --hole 16"
  "approximate L=4, buffer 512x256 S=4|--mode approximate --hole 4 --buffer 512x256 --samples 4"
  "approximate L=4, buffer 256x128 S=4|--mode approximate --hole 4 --buffer 256x128 --samples 4"
)
# (Conservative mode needs the buffer's samples on the display's pixel centres: buffer x S =
# display. Coarser buffers, down to 256x128, are approximate mode's.)
echo "| scene (occluders) | configuration | efficiency | over objects hidden outright | false culls (through ties only) | render / maps / tests ms per view |"
echo "|---|---|---|---|---|---|"
for scene in intel_castle crytek_sponza openarena_oa_thor openarena_pul1duel-oa fzk_haus; do
  file=$scenes/$scene.glb
  [ -f "$file" ] || { echo "maps-results: $file missing, skipped" >&2; continue; }
  occluders=all
  [ "$scene" = intel_castle ] && occluders=role  # the castle marks its occluders
  for config in "${configs[@]}"; do
    IFS='|' read -r name options <<<"$config"
    json=$out/$scene.${name//[^a-zA-Z0-9]/_}.json
    echo "maps-results: $scene, $name" >&2
    # shellcheck disable=SC2086
    "$homcull" accuracy --scene "$file" --walk 20 --resolution "$resolution" --occluders "$occluders" $options --json >"$json"
    jq -r --arg scene "$scene ($occluders)" --arg name "$name" '
      "| \($scene) | \($name) | \((.efficiency*1000|round)/10) % (\(.culled_hidden)/\(.hidden_in_frustum)) | \((.robust_efficiency*1000|round)/10) % | \(.false_culls) (\(.false_culls - .robust_false_culls)) | \((.ms_per_view.render*100|round)/100) / \((.ms_per_view.maps*100|round)/100) / \((.ms_per_view.tests*100|round)/100) |"' "$json"
  done
done
echo "maps-results: JSON in $out" >&2
