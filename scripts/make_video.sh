#!/usr/bin/env bash
# An MP4 (H.264, yuv420p: plays everywhere) from a run's frames with ffmpeg.
#   scripts/make_video.sh OUT_DIR [FPS] [VIDEO.mp4]
# FPS defaults to the run's own (run.json, time.fps), VIDEO to OUT_DIR/video.mp4. Installs ffmpeg
# from Debian when it is missing and we may (root or sudo).
set -euo pipefail
out=${1:?usage: scripts/make_video.sh OUT_DIR [FPS] [VIDEO.mp4]}
[[ -d "$out/frames" ]] || { echo "make_video: no $out/frames folder; run rend with a renderer first" >&2; exit 2; }
fps=${2:-$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['resolved_scene'].get('time', {}).get('fps', 24))" "$out/run.json" 2>/dev/null || echo 24)}
video=${3:-$out/video.mp4}
if ! command -v ffmpeg >/dev/null; then
    sudo=""; [[ $(id -u) -eq 0 ]] || sudo="sudo"
    echo "make_video: installing ffmpeg"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends ffmpeg >/dev/null
fi
# Written to a temporary name and renamed, like every other output of rend.
ffmpeg -loglevel error -y -framerate "$fps" -pattern_type glob -i "$out/frames/frame_*.png" \
    -c:v libx264 -pix_fmt yuv420p -vf "pad=ceil(iw/2)*2:ceil(ih/2)*2" -f mp4 "$video.tmp"
mv "$video.tmp" "$video"
echo "make_video: $video ($(ls "$out"/frames/frame_*.png | wc -l) frames at $fps fps)"
