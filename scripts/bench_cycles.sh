#!/usr/bin/env bash
# Render speed at equal noise: rend's Embree path tracer against Blender Cycles (CPU, denoiser
# off) on the same mesh, camera, sun, sky, ground, material and resolution, on this machine.
#   scripts/bench_cycles.sh [SCENE] [FRAME] [WIDTH] [HEIGHT] [REFERENCE_SPP]
# Each renderer renders the frame at several sample counts and once at REFERENCE_SPP (1024 by
# default); noise is the RMSE of linear R, G, B (clamped to [0, 1], the display range) against
# the renderer's OWN reference, rendered with another seed (so its noise is independent of the
# measured images'; with the same seed both renderers would reuse their first samples) and
# corrected for that noise (below). Time to a
# target RMSE is interpolated log-log between the measured points; the targets are Cycles' RMSE
# at 16 and 64 spp. Prints the table and the ratio Cycles time / rend time, for wall seconds
# and for CPU seconds (all threads; the robust figure when other jobs share the cores).
# Counted: rend from handing the mesh to a new renderer (device, BVH build, tracing) to the
# linear image; Cycles bpy.ops.render.render alone (sync, BVH build, tracing). Neither counts
# start-up, the simulation, the import or the file writes. Needs Debian's blender; says so and
# exits 0 without it. Never fails on a time. CYCLES_FROM=DIR reuses the Cycles renders of a run
# kept with KEEP_BENCH=1 (the same arguments), to measure a change to rend alone.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/foil_tear.toml}; frame=${2:-192}; width=${3:-960}; height=${4:-540}
reference=${5:-1024}
rend_spp=${REND_SPP:-"1 2 4 8 16 32 64"}
cycles_spp=${CYCLES_SPP:-"4 8 16 32 64 128"}
command -v blender >/dev/null || { echo "bench_cycles: blender not installed (apt-get install blender)"; exit 0; }
[[ -x build/bench_noise ]] || cmake --build build --target bench_noise >/dev/null
tmp=$(mktemp -d)
[[ -n ${KEEP_BENCH:-} ]] && echo "bench_cycles: keeping $tmp" || trap 'rm -rf "$tmp"' EXIT
OMP_WAIT_POLICY=passive build/bench_noise render "$scene" "$frame" "$width" "$height" "$tmp" \
    $rend_spp "ref=$reference" > "$tmp/rend.txt"
blender_run() {
    blender -b --factory-startup -P scripts/blender_import.py -- "$tmp" --frame "$frame" \
        --width "$width" --height "$height" --exr-dir "$tmp" "$@" 2>/dev/null | grep '^cycles '
}
if [[ -n ${CYCLES_FROM:-} ]]; then
    # Cycles' renders of an earlier run kept with KEEP_BENCH (same scene, frame, size and spp):
    # for iterating on rend alone.
    cp "$CYCLES_FROM"/cycles*.txt "$CYCLES_FROM"/cycles_*.exr "$tmp"/
else
    blender_run --samples "$(echo $cycles_spp | tr ' ' ',')" > "$tmp/cycles.txt"
    blender_run --samples "$reference" --reference > "$tmp/cycles_ref.txt"
fi
for r in rend cycles; do
    spps=$rend_spp; [[ $r == cycles ]] && spps=$cycles_spp
    build/bench_noise rmse "$tmp/${r}_$reference.exr" $(for s in $spps; do echo "$tmp/${r}_$s.exr"; done) \
        > "$tmp/${r}_rmse.txt"
done
python3 - "$tmp" "$scene" "$frame" "$width" "$height" "$reference" <<'PY'
import math, pathlib, re, sys
tmp, scene, frame, w, h, ref = sys.argv[1:]
tmp, ref = pathlib.Path(tmp), int(ref)

def runs(name):
    rows = {}
    for line in (tmp / f"{name}.txt").read_text().splitlines():
        m = re.match(r"\w+ spp=(\d+) seconds=([\d.]+) cpu=([\d.]+)", line)
        if m:
            rows[int(m[1])] = (float(m[2]), float(m[3]))
    for line in (tmp / f"{name}_rmse.txt").read_text().splitlines():
        _, path, clamped, _raw = line.split()
        spp = int(re.search(r"_(\d+)\.exr$", path)[1])
        # E|x_N - x_ref|^2 = v/N + v/ref: the reference's own noise is removed.
        rows[spp] += (float(clamped) / math.sqrt(1.0 + spp / ref),)
    return sorted((s, *v) for s, v in rows.items() if len(v) == 3)

def time_at(points, target, column):
    """Seconds to reach `target` RMSE, log-log between the bracketing points (or the ends)."""
    pts = sorted(points, key=lambda p: -p[3])
    for a, b in zip(pts, pts[1:]):
        if a[3] >= target >= b[3] or b is pts[-1] or (a is pts[0] and target > a[3]):
            t = (math.log(target) - math.log(a[3])) / (math.log(b[3]) - math.log(a[3]))
            return math.exp(math.log(a[column]) + t * (math.log(b[column]) - math.log(a[column])))

rend, cycles = runs("rend"), runs("cycles")
print(f"bench_cycles: {scene} frame {frame}, {w}x{h}, references at {ref} spp")
print(f"  {'renderer':8} {'spp':>5} {'wall s':>8} {'cpu s':>8} {'rmse':>9}")
for name, rows in (("rend", rend), ("cycles", cycles)):
    for spp, wall, cpu, rmse in rows:
        print(f"  {name:8} {spp:5d} {wall:8.3f} {cpu:8.3f} {rmse:9.5f}")
for spp in (16, 64):
    target = next((r[3] for r in cycles if r[0] == spp), None)
    if target is None:
        continue
    ours = [time_at(rend, target, c) for c in (1, 2)]
    theirs = [time_at(cycles, target, c) for c in (1, 2)]
    print(f"  at Cycles' {spp}-spp RMSE {target:.5f}: rend {ours[0]:.3f} s wall, {ours[1]:.3f} s cpu;"
          f" cycles {theirs[0]:.3f} s wall, {theirs[1]:.3f} s cpu;"
          f" rend is {theirs[0] / ours[0]:.1f}x faster (wall), {theirs[1] / ours[1]:.1f}x (cpu)")
PY
