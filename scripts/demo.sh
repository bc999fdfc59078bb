#!/usr/bin/env bash
# The main job, end to end on a scene the project generates: installs the dependencies,
# builds, generates a city, walks through it, computes exact per-object visibility (Embree
# ground truth) along the walk, and culls with the occlusion buffer, counting its false and
# missed culls against that truth. Prints what it found and where its output went.
# Usage: scripts/demo.sh [output folder]   (default: out/demo)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh >/dev/null
homcull=build/tools/homcull/homcull
out=${1:-out/demo}
mkdir -p "$out"

echo "== generating a city (gen:city:seed=1) and a 120-frame walk through its streets"
"$homcull" export --scene gen:city:seed=1 --out "$out/city.glb"
"$homcull" path --scene "$out/city.glb" --kind walk --frames 120 --out "$out/city_walk.json"

echo
echo "== exact visibility (Embree, 1280x720, 2x2 samples per pixel) along the walk"
printf '%6s  %s\n' frame "objects"
for frame in 0 30 60 90 119; do
  line=$("$homcull" truth --scene "$out/city.glb" --path "$out/city_walk.json" --frame "$frame" \
           --resolution 1280x720 --samples 2 --id-image "$out/frame${frame}_ids.png" | sed -n 's/^objects *//p')
  printf '%6s  %s\n' "$frame" "$line"
done
"$homcull" truth --scene "$out/city.glb" --path "$out/city_walk.json" --frame 60 \
  --resolution 1280x720 --samples 2 --json > "$out/frame60_truth.json"

echo
echo "== frame 60 in detail"
"$homcull" truth --scene "$out/city.glb" --path "$out/city_walk.json" --frame 60 --resolution 1280x720 --samples 2 \
  | sed -n 1,16p  # not head: under pipefail, head leaving early could kill homcull (SIGPIPE)

echo
echo "== occlusion culling along the walk: the scene culler's answers for every object"
echo "   against the exact visibility above (1280x720 display, 320x180 buffer with 4x4 samples)"
"$homcull" accuracy --scene "$out/city.glb" --path "$out/city_walk.json" --resolution 1280x720 --samples 4 2>/dev/null
"$homcull" accuracy --scene "$out/city.glb" --path "$out/city_walk.json" --resolution 1280x720 --samples 4 --json \
  > "$out/culling_accuracy.json" 2>/dev/null

echo
echo "== frame 60 culled on its own, with Embree's answer beside each object's"
"$homcull" cull --scene "$out/city.glb" --path "$out/city_walk.json" --frame 60 --resolution 1280x720 --samples 4 --truth
"$homcull" cull --scene "$out/city.glb" --path "$out/city_walk.json" --frame 60 --resolution 1280x720 --samples 4 --truth --json \
  > "$out/frame60_cull.json"

echo
echo "== output in $out/"
echo "   city.glb                the generated scene (binary glTF; open it in any glTF viewer)"
echo "   city_walk.json          the camera path (DESIGN.md path format)"
echo "   frame*_ids.png          the object seen by every sample, one colour per object"
echo "   frame60_truth.json      per-object results for frame 60 (homcull truth --json)"
echo "   culling_accuracy.json   false culls, missed culls and culling efficiency along the walk"
echo "   frame60_cull.json       per-object culling answers, levels of visibility and stage times for frame 60"
