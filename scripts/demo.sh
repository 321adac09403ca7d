#!/usr/bin/env bash
# Set-up, Release build, and the default scene rendered into out/.
#   scripts/demo.sh [SCENE] [extra rend run options...]           preview: quick
#   scripts/demo.sh --final [SCENE] [extra rend run options...]   final quality (>= 250,000
#       particles), 1920x1080, path traced (Embree) at 2 samples a pixel and denoised, into
#       out/NAME-final/
set -euo pipefail
cd "$(dirname "$0")/.."
final=()
suffix=""
if [[ "${1:-}" == "--final" ]]; then
    shift
    final=(--quality final --renderer embree --set render.width=1920 --set render.height=1080 \
        --spp 2 --set render.denoise=true)
    suffix="-final"
fi
scripts/setup.sh
scripts/build.sh
scene=${1:-scenes/foil_tear_heat.toml}
shift || true
name=$(basename "$scene" .toml)$suffix
time build/rend run "$scene" --out "out/$name" ${final[@]+"${final[@]}"} "$@"
echo "demo: frames in out/$name/frames/, statistics in out/$name/stats.csv and out/$name/run.json"
