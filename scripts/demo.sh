#!/usr/bin/env bash
# Set-up, Release build, and the default scene rendered into out/.
#   scripts/demo.sh [SCENE] [extra rend run options...]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
scene=${1:-scenes/foil_tear_heat.toml}
shift || true
name=$(basename "$scene" .toml)
time build/rend run "$scene" --out "out/$name" "$@"
echo "demo: frames in out/$name/frames/, statistics in out/$name/stats.csv and out/$name/run.json"
