#!/usr/bin/env bash
# The camera-cut table of docs/scene-culling.md ("Camera cuts"): how much the temporal strategy
# gains over one-pass as the camera moves further between frames. Each scene's generated walk
# (`homcull path --frames FRAMES --seed 1`) is taken every K-th frame, K = 1 .. 32, so that the
# eye steps K times as far and the view turns K times as much a frame, and culled three ways:
# one-pass, temporal without camera cuts (--cut-step inf --cut-turn 180), and temporal with
# the default cuts, the three in turn, ROUNDS times (3). Markdown on stdout: the median over the
# rounds of each walk's mean whole frame in ms, and the frames the defaults cut.
#   taskset -c 1 bash scripts/temporal-cuts.sh [FRAMES] [RESOLUTION]   (defaults: 960, 1280x720)
# Pin it to one core (taskset) on an otherwise idle machine: it times. Needs a build
# (scripts/build.sh), jq, and ../shared/scenes beside the repository; HOMCULL may name another
# binary, SCENES a subset of the shared scenes (names without .glb). The paths are kept in $OUT
# (a temp dir).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-960}
resolution=${2:-1280x720}
rounds=${ROUNDS:-3}
homcull=${HOMCULL:-build/tools/homcull/homcull}
scenes=../shared/scenes
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
command -v jq >/dev/null || { echo "temporal-cuts: jq is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
[ -x "$homcull" ] || { echo "temporal-cuts: $homcull not built (bash scripts/build.sh)" >&2; exit 2; }

# The mean frame_ms of a walk and, for temporal, its frames without history.
walk() {  # path options...
  local path=$1
  shift
  "$homcull" walk --scene "$file" --path "$path" --resolution "$resolution" --truth off --quiet "$@" |
    awk '/^frame_ms/ {ms = $2} /^frames without history/ {cut = $(NF - 2)} END {printf "%.2f %s\n", ms, cut}'
}
median() { sort -n | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }

echo "| scene | every K-th frame | eye step, near distances (median) | turn, degrees (median, max) | one-pass ms | temporal, no cuts | temporal (default) | frames cut |"
echo "|---|---|---|---|---|---|---|---|"
for scene in ${SCENES:-intel_castle crytek_sponza openarena_oa_thor openarena_pul1duel-oa fzk_haus}; do
  file=$scenes/$scene.glb
  [ -f "$file" ] || { echo "temporal-cuts: $file missing, skipped" >&2; continue; }
  "$homcull" path --scene "$file" --frames "$frames" --seed 1 --out "$out/$scene.path.json" >&2
  ks=(1 2 4 8 16 32)
  declare -A ms_of=() cut_of=() motion_of=()
  for k in "${ks[@]}"; do
    path=$out/$scene.every$k.json
    jq --argjson k "$k" '.frames |= [.[range(0; length; $k)]]' "$out/$scene.path.json" >"$path"
    # Median eye step over the near distance, and the view's turn in degrees, between frames.
    motion_of[$k]=$(jq -r 'def dir: [.target[0] - .eye[0], .target[1] - .eye[1], .target[2] - .eye[2]] |
                      (map(. * .) | add | sqrt) as $n | map(. / $n);
                    def median: sort | .[length / 2 | floor];
                    .frames as $f | [range(1; $f | length)] |
                    (map(. as $i | [range(3)] | map(($f[$i].eye[.] - $f[$i - 1].eye[.]) | . * .) | add | sqrt / $f[$i - 1].near) | median) as $step |
                    (map(. as $i | ($f[$i] | dir) as $a | ($f[$i - 1] | dir) as $b |
                         [range(3)] | map($a[.] * $b[.]) | add | if . > 1 then 1 elif . < -1 then -1 else . end | acos * 180 / 3.141592653589793)) as $turns |
                    "\($step * 10 | round / 10) | \($turns | median | . * 10 | round / 10), \($turns | max | . * 10 | round / 10)"' "$path")
  done
  # Rounds outside the strides, so that a burst of load on the host lands on one round of
  # several strides rather than on every round of one.
  for ((r = 0; r < rounds; ++r)); do
    for k in "${ks[@]}"; do
      path=$out/$scene.every$k.json
      echo "temporal-cuts: $scene, round $((r + 1)) of $rounds, K = $k" >&2
      read -r ms _ < <(walk "$path" --strategy one-pass) && ms_of[$k,one]+="$ms "
      read -r ms _ < <(walk "$path" --strategy temporal --cut-step inf --cut-turn 180) && ms_of[$k,uncut]+="$ms "
      read -r ms cut < <(walk "$path" --strategy temporal) && ms_of[$k,cut]+="$ms " && cut_of[$k]=$cut
    done
  done
  for k in "${ks[@]}"; do
    path=$out/$scene.every$k.json
    one=$(printf '%s\n' ${ms_of[$k,one]} | median)
    uncut=$(printf '%s\n' ${ms_of[$k,uncut]} | median)
    cut=$(printf '%s\n' ${ms_of[$k,cut]} | median)
    echo "| $scene | $k | ${motion_of[$k]} | $one | $uncut | $cut | ${cut_of[$k]} of $(jq '.frames | length' "$path") |"
  done
  unset ms_of cut_of motion_of
done
echo "temporal-cuts: paths in $out" >&2
