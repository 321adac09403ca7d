#!/usr/bin/env bash
# rend's exports read back by Debian's Blender, headless (tests/blender_check.py): a torn foil
# frame in every format (the same loose parts, the attributes and normals kept), a heated one
# (theta), a VDB sequence that starts late on its own frame numbers; then a frame rendered
# with Cycles through scripts/blender_import.py.
# Skipped (exit 77, ctest's SKIP_RETURN_CODE) when blender is not installed.
set -euo pipefail
rend=$1
command -v blender >/dev/null || { echo "blender is not installed: skipped"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
check() {
    blender -b --factory-startup --python-exit-code 1 -P tests/blender_check.py -- "$@" 2>&1 |
        grep "^blender_check:" || true
    blender -b --factory-startup --python-exit-code 1 -P tests/blender_check.py -- "$@" \
        >/dev/null 2>&1 || { echo "FAILED: blender_check $*"; exit 1; }
}
# Torn in two by frame 192; the late, strided frames also test a sequence not starting at 1.
"$rend" run scenes/foil_tear.toml --out "$tmp/torn" --renderer none --export ply,obj,glb,vdb \
    --frames 150-192:6 >/dev/null 2>&1
check "$tmp/torn" 192 2
"$rend" run scenes/foil_tear_heat.toml --out "$tmp/heat" --renderer none \
    --export ply,obj,glb,vdb --frames 100-120:5 >/dev/null 2>&1
check "$tmp/heat" 115
log=$(blender -b --factory-startup -P scripts/blender_import.py -- "$tmp/heat" --frame 120 \
    --samples 4 --width 96 --height 54 2>&1)
echo "$log" | grep -E "blender_import:|render_seconds=|coverage="
test -s "$tmp/heat/blender_0120.png" || { echo "FAILED: no image"; exit 1; }
coverage=$(echo "$log" | sed -n 's/^coverage=//p')
python3 -c "import sys; c = float(sys.argv[1]); sys.exit(0 if c > 0.05 else 1)" "$coverage" \
    || { echo "FAILED: the sheet covers only $coverage of the image"; exit 1; }
echo "blender test: passed"
