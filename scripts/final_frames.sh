#!/usr/bin/env bash
# The last frame of each scene at final quality (>= 250,000 particles), path traced and denoised,
# to look at: OUT/NAME.png, plus one line per scene with its particle count, steps, broken bonds
# and wall time by stage (from run.json). The whole animation is simulated (the simulation
# always starts at t = 0); only the last frame is surfaced and rendered.
#   scripts/final_frames.sh [SCENE...]      (default: every scene in scenes/)
#   REND=path/to/rend  OUT=folder  SPP=16  SIZE=1280x720  (extra rend options in REND_ARGS)
set -euo pipefail
cd "$(dirname "$0")/.."
rend=${REND:-build/rend}
out=${OUT:-out/final_frames}
spp=${SPP:-16}
size=${SIZE:-1280x720}
[[ $# -gt 0 ]] || set -- scenes/*.toml
mkdir -p "$out"
for scene in "$@"; do
    name=$(basename "$scene" .toml)
    # shellcheck disable=SC2086
    frames=$("$rend" check "$scene" --quality final ${REND_ARGS:-} | grep -oE '[0-9]+ frames' | head -1 |
        grep -oE '[0-9]+')
    run_dir="$out/$name"
    # shellcheck disable=SC2086
    "$rend" run "$scene" --out "$run_dir" --quality final --frames "$frames" --renderer embree \
        --spp "$spp" --set render.width="${size%x*}" --set render.height="${size#*x}" \
        --set render.denoise=true ${REND_ARGS:-} >"$run_dir.log" 2>&1 ||
        { echo "$name: rend failed (exit $?), see $run_dir.log"; continue; }
    cp "$run_dir/frames/frame_$(printf %04d "$frames").png" "$out/$name.png"
    python3 - "$run_dir" "$name" <<'PY'
import csv, json, pathlib, sys
folder = pathlib.Path(sys.argv[1])
run = json.loads((folder / "run.json").read_text())
broken = list(csv.DictReader(open(folder / "stats.csv")))[-1]["broken_bonds"]
wall = run["wall_seconds"]
stages = " ".join(f"{k} {wall.get(k, 0):.1f}" for k in ("simulate", "contact", "surface", "render"))
print(f"{sys.argv[2]}: {run['particles']} particles, {run['steps']} steps, "
      f"{broken} broken bonds, {stages} s")
PY
done
