#!/usr/bin/env bash
# A whole animation at final quality (>= 250,000 particles), 1920x1080, path traced at 2 samples
# a pixel and denoised (as scripts/demo.sh --final), and its wall time by stage (from run.json)
# and particle count.
#   scripts/bench_final.sh [SCENE] [extra rend run options, e.g. --set time.dt=auto]
#   REND=path/to/rend  OUT=folder  (defaults: build/rend, a temporary folder)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/foil_tear_heat.toml}
shift || true
rend=${REND:-build/rend}
out=${OUT:-$(mktemp -d)}
start=$(date +%s.%N)
"$rend" run "$scene" --out "$out" --quality final --renderer embree \
    --set render.width=1920 --set render.height=1080 --spp 2 --set render.denoise=true "$@" \
    >/dev/null
end=$(date +%s.%N)
python3 - "$out/run.json" "$scene" "$start" "$end" <<'PY'
import json, sys
run = json.load(open(sys.argv[1]))
wall = run["wall_seconds"]
total = float(sys.argv[4]) - float(sys.argv[3])
print(f"{sys.argv[2]} at final quality: {run['particles']} particles, {run['bonds']} bonds, "
      f"{run['frames_written']} frames, {run['steps']} steps of {run['dt']:.4g} s, "
      f"{run['threads']} threads")
for stage in ("setup", "simulate", "surface", "render", "write"):
    print(f"  {stage:9s} {wall[stage]:9.1f} s")
print(f"  {'total':9s} {sum(wall.values()):9.1f} s (the command: {total:.1f} s)")
PY
