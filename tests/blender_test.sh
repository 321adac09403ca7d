#!/usr/bin/env bash
# Exports a short mesh sequence, loads it into Blender headless and renders a frame with Cycles.
# Skipped (exit 77, ctest's SKIP_RETURN_CODE) when Debian's blender is not installed.
set -euo pipefail
rend=$1
command -v blender >/dev/null || { echo "blender is not installed: skipped"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$rend" run scenes/stretch.toml --out "$tmp/run" --renderer none --export ply \
    --set 'sheet.size=[0.6,0.6]' --set time.duration=0.125 >/dev/null 2>&1
log=$(blender -b --factory-startup -P scripts/blender_import.py -- "$tmp/run" --frame 3 \
    --samples 4 --width 96 --height 54 2>&1)
echo "$log" | grep -E "blender_import:|render_seconds=|coverage="
test -s "$tmp/run/blender_0003.png" || { echo "FAILED: no image"; exit 1; }
coverage=$(echo "$log" | sed -n 's/^coverage=//p')
python3 -c "import sys; c = float(sys.argv[1]); sys.exit(0 if c > 0.05 else 1)" "$coverage" \
    || { echo "FAILED: the sheet covers only $coverage of the image"; exit 1; }
echo "blender test: 1 passed, 0 failed"
