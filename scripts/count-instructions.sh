#!/usr/bin/env bash
# Instructions executed by SceneCuller::cull along a walk, per binary: a measure of a change's
# work that does not move with the host. These machines' times move by 30 % and more from one
# minute to the next, which hides changes of a few percent even in alternating rounds; the
# instruction count of the same walk is the same on every run. It is not a time (it counts no
# cache miss, no misprediction, and a `rep stos` memset counts per element), so a speed claim
# still needs alternating pinned rounds; it tells whether a change did less work, and where.
#   bash scripts/count-instructions.sh SCENE BINARY [BINARY ...] [-- WALK OPTIONS]
#     SCENE: a name under ../shared/scenes (intel_castle, openarena_oa_thor, ...) or a file
#     BINARY: homcull programs to compare (the first is the reference for the ratios)
# Example: bash scripts/count-instructions.sh openarena_oa_thor /tmp/homcull.before build/tools/homcull/homcull
# The walk: `homcull path --frames ${FRAMES:-120} --seed 1`, culled with `--truth off` and the
# defaults (or WALK OPTIONS), under valgrind's callgrind with collection on inside
# SceneCullerState::cull only (loading and setup left out). Valgrind hides AVX-512, so the
# binaries run their AVX2 kernels. Prints each binary's total and ratio, then the reference's
# and the last binary's top functions (self instructions). Keeps callgrind's files in $OUT.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n 8,10p "$0" >&2; exit 2; }
scene=$1; shift
binaries=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do binaries+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
walk_options=("$@")
[ ${#binaries[@]} -gt 0 ] || { echo "count-instructions: no homcull program given" >&2; sed -n 8,10p "$0" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "count-instructions: valgrind is missing (bash scripts/install-deps.sh)" >&2; exit 2; }
file=$scene
[ -f "$file" ] || file=../shared/scenes/$scene.glb
[ -f "$file" ] || { echo "count-instructions: no scene $scene (nor $file)" >&2; exit 2; }
for b in "${binaries[@]}"; do [ -f "$b" ] && [ -x "$b" ] || { echo "count-instructions: $b is not a program" >&2; exit 2; }; done
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
path=$out/path.json
"${binaries[0]}" path --scene "$file" --frames "${FRAMES:-120}" --seed 1 --out "$path" >&2

totals=()
for k in "${!binaries[@]}"; do
  cg=$out/callgrind.$k.out
  valgrind --tool=callgrind --toggle-collect='homcull::detail::SceneCullerState::cull(*' --callgrind-out-file="$cg" \
    "${binaries[$k]}" walk --scene "$file" --path "$path" --truth off --quiet "${walk_options[@]}" > "$out/walk.$k.txt" 2> "$out/valgrind.$k.log" ||
    { echo "count-instructions: ${binaries[$k]} failed under valgrind ($out/valgrind.$k.log)" >&2; exit 1; }
  total=$(awk '/^(summary|totals):/ {print $2; exit}' "$cg")
  # A wrapper script around homcull counts nothing: valgrind runs the shell, not what it starts.
  [ -n "$total" ] && [ "$total" -gt 0 ] ||
    { echo "count-instructions: nothing counted in SceneCullerState::cull ($cg; give the homcull program itself, not a wrapper)" >&2; exit 1; }
  totals+=("$total")
done
echo "instructions in SceneCuller::cull, $(basename "$file"), ${FRAMES:-120}-frame walk ${walk_options[*]}"
for k in "${!binaries[@]}"; do
  awk -v b="${binaries[$k]}" -v t="${totals[$k]}" -v r="${totals[0]}" -v f="${FRAMES:-120}" \
    'BEGIN { printf "  %-48s %15d  (%.0f a frame)  %.4f\n", b, t, t / f, t / r }'
done
for k in 0 $(( ${#binaries[@]} - 1 )); do
  echo "top functions, ${binaries[$k]}:"
  callgrind_annotate "$out/callgrind.$k.out" 2>/dev/null | sed -n '/PROGRAM TOTALS/,$p' | grep -E '^ *[0-9,]+ \(' | sed -n 2,13p | cut -c1-150
  [ ${#binaries[@]} -eq 1 ] && break
done
echo "(callgrind files in $out)"
