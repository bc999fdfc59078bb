#!/usr/bin/env bash
# The efficiency / whole-frame-time frontier of the scene culler on the castle (issue 36's plot):
# `homcull bench --workload frame` in each configuration below, on the views of
# data/views/castle.json and on random viewpoints, one thread, pinned; then
# scripts/frontier_plot.py draws frontier.png and writes frontier.md, with the peers' points
# (Intel MOC, rawrunprotected) when a ../shared/peers/measure.sh summary is found.
# The configurations run in PASSES passes, forward then backward in turn, so that no
# configuration always runs first (the first process of a run, or the minute it lands in, can
# be 30 % slower on these machines); frontier_plot.py takes each view's median over the passes.
# Settings (environment): HOMCULL (the program), OUT (results folder, under build/), PASSES (5),
# ROUNDS (timed rounds per view and pass, 5), CORE (the core to pin to, 1), RANDOM_VIEWS (30,
# 0: none), PEERS (a measure.sh summary.md; default: the newest under build/peers/results).
# Needs python3-matplotlib (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
HOMCULL=${HOMCULL:-build/tools/homcull/homcull}
OUT=${OUT:-build/frontier/$(date +%Y%m%d-%H%M%S)}
PASSES=${PASSES:-5}
ROUNDS=${ROUNDS:-5}
CORE=${CORE:-1}
RANDOM_VIEWS=${RANDOM_VIEWS:-30}
SCENE=${SCENE:-../shared/scenes/intel_castle.glb}
if [ -z "${PEERS+x}" ]; then
  PEERS=$(ls -t build/peers/results/*/summary.md 2>/dev/null | head -n 1 || true)
fi
[ -x "$HOMCULL" ] || { echo "frontier.sh: $HOMCULL is missing: build first (scripts/build.sh)" >&2; exit 1; }
[ -f "$SCENE" ] || { echo "frontier.sh: $SCENE is missing (../shared/scenes)" >&2; exit 1; }
pin=()
if command -v taskset >/dev/null 2>&1; then pin=(taskset -c "$CORE"); else echo "frontier.sh: no taskset: unpinned" >&2; fi
mkdir -p "$OUT"

# name|bench arguments: the scene culler's configurations, cheapest first.
configs=(
  "boxes, clusters|--occludees box --clusters 124"
  "boxes, clusters, 32 parts|--occludees box --clusters 124 --occludee-parts 32"
  "boxes, clusters, back faces culled|--occludees box --clusters 124 --back-faces cull"
  "boxes|--occludees box --clusters 0"
  "triangles, clusters (default)|"
  "triangles, clusters, back faces culled|--back-faces cull"
  "triangles|--clusters 0"
  "triangles, clusters, every object cheap for its surface an occluder|--occluders all --complexity 0.25"
  "triangles, clusters, every object cheap for its surface an occluder where large on screen|--occluders all --complexity 0.25 --min-occluder-size 0.02"
)
run_config() {
  local name=${1%%|*} args=${1#*|} pass=$2 file
  file=$(echo "$name" | tr -c 'a-z0-9\n' '_')
  echo "frontier.sh: pass $pass: $name" >&2
  # shellcheck disable=SC2086
  "${pin[@]}" "$HOMCULL" bench --workload frame --scene "$SCENE" --views data/views/castle.json --repeat "$ROUNDS" $args --json \
    > "$OUT/${file}_castle.pass$pass.json"
  if [ "$RANDOM_VIEWS" -gt 0 ]; then
    # shellcheck disable=SC2086
    "${pin[@]}" "$HOMCULL" bench --workload frame --scene "$SCENE" --random "$RANDOM_VIEWS" --seed 1 --repeat "$ROUNDS" $args --json \
      > "$OUT/${file}_random.pass$pass.json"
  fi
}
for ((pass = 1; pass <= PASSES; ++pass)); do
  if ((pass % 2 == 1)); then
    for ((k = 0; k < ${#configs[@]}; ++k)); do run_config "${configs[k]}" "$pass"; done
  else
    for ((k = ${#configs[@]} - 1; k >= 0; --k)); do run_config "${configs[k]}" "$pass"; done
  fi
done
# Debian's python3, which has python3-matplotlib (a python3 earlier on PATH may not).
PYTHON=${PYTHON:-$(command -v /usr/bin/python3 || command -v python3)}
"$PYTHON" scripts/frontier_plot.py "$OUT" ${PEERS:+"$PEERS"}
echo "frontier.sh: $OUT/frontier.png, $OUT/frontier.md" >&2
