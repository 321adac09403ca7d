#!/usr/bin/env bash
# Seconds to path-trace one frame: rend's Embree renderer against Blender Cycles (CPU), on the
# same exported mesh, same resolution and samples, same machine, same run. Prints, never fails
# on time. Needs Debian's blender (apt-get install blender); says so and exits 0 without it.
#   scripts/bench_cycles.sh [SCENE] [FRAME] [WIDTH] [HEIGHT] [SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/foil_tear.toml}; frame=${2:-24}; width=${3:-320}; height=${4:-180}; spp=${5:-16}
command -v blender >/dev/null || { echo "bench_cycles: blender not installed (apt-get install blender)"; exit 0; }
[[ -x build/rend ]] || scripts/build.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sets=(--set render.width=$width --set render.height=$height)
build/rend run "$scene" --renderer embree --spp "$spp" --export ply --frames "$frame" "${sets[@]}" \
    --out "$tmp/run" >/dev/null 2>&1
ours=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['wall_seconds']['render'])" "$tmp/run/run.json")
cycles=$(blender -b --factory-startup -P scripts/blender_import.py -- "$tmp/run" --frame "$frame" \
    --samples "$spp" --width "$width" --height "$height" 2>/dev/null | sed -n 's/^render_seconds=//p')
python3 - "$scene" "$frame" "$width" "$height" "$spp" "$ours" "$cycles" <<'PY'
import sys
scene, frame, w, h, spp, ours, cycles = sys.argv[1:]
print(f"bench_cycles: {scene} frame {frame}, {w}x{h}, {spp} spp")
print(f"  rend embree    {float(ours):8.3f} s")
print(f"  blender cycles {float(cycles):8.3f} s  ({float(cycles) / float(ours):.1f}x ours)")
PY
