#!/usr/bin/env bash
# End-to-end checks of the rend command: exit statuses, messages, and that bad input leaves
# nothing behind. Usage: tests/cli_test.sh path/to/rend   (run from the repository root)
set -uo pipefail
rend=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0

check() {  # check NAME CONDITION...
    local name=$1
    shift
    if "$@"; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        echo "FAILED: $name"
    fi
}
run() {  # run EXPECTED_STATUS args... ; leaves output in $tmp/stdout, $tmp/stderr
    local expected=$1
    shift
    "$rend" "$@" >"$tmp/stdout" 2>"$tmp/stderr"
    local status=$?
    if [[ $status -ne $expected ]]; then
        echo "rend $* exited $status, expected $expected"
        cat "$tmp/stderr"
        return 1
    fi
}
no_partial_files() { ! find "$1" -name '*.tmp' -o -name '*.partial' | grep -q .; }

# --version names every library actually in use.
check "version" run 0 --version
# The default thread count is the cores this process may use (app/Threads.h): one CPU of
# affinity, one thread; OMP_NUM_THREADS still wins.
if command -v taskset >/dev/null; then
    check "one CPU of affinity, one thread" bash -c "taskset -c 0 '$rend' --version | grep -q 'spec [0-9]*, 1 threads, 1 cores usable'"
fi
for lib in Eigen OpenMP Embree OpenVDB assimp OSMesa; do
    check "version names $lib" grep -q "$lib" "$tmp/stdout"
done

check "check accepts the shipped scenes" run 0 check scenes/stretch.toml
check "check accepts the shear scene" run 0 check scenes/shear.toml
check "check prints particle count" grep -q "particles" "$tmp/stdout"

# Every malformed scene: exit 2, a file:line:column message, and nothing written.
for bad in tests/scenes/bad_*.toml; do
    check "$bad is refused by check" run 2 check "$bad"
    check "$bad message has file:line:column" grep -qE "$(basename "$bad"):[0-9]+:[0-9]+: error" "$tmp/stderr"
    check "$bad is refused by run" run 2 run "$bad" --out "$tmp/bad_out"
    check "$bad leaves no output folder" test ! -e "$tmp/bad_out"
done

# A dt above the Silling-Askari bound is refused before anything is written.
check "unstable dt refused" run 2 run scenes/stretch.toml --set time.dt=0.01 --out "$tmp/unstable"
check "unstable dt message" grep -q "stable limit" "$tmp/stderr"
check "unstable dt from --set is located there" grep -qE "^--set 'time.dt=0.01': error: time.dt" "$tmp/stderr"
check "unstable dt in a file" run 2 check tests/scenes/unstable_dt.toml
check "unstable dt in a file has file:line:column" grep -qE "unstable_dt.toml:[0-9]+:[0-9]+: error: time.dt" "$tmp/stderr"
check "unstable dt leaves no output" test ! -e "$tmp/unstable"
check "bad --set refused" run 2 check scenes/stretch.toml --set material.E=-5
check "bad --frames refused" run 2 run scenes/stretch.toml --frames 0-3 --out "$tmp/frames"
check "bad --frames leaves no output" test ! -e "$tmp/frames"

# Forcing an unstable dt trips the guard: exit 3, the step and the particle named, and the
# outputs written so far are complete.
small=(--set 'sheet.size=[0.4,0.4]' --set time.duration=0.25)
check "blow-up exits 3" run 3 run scenes/stretch.toml "${small[@]}" --set time.dt=0.02 \
    --set time.allow_unstable=true --renderer none --out "$tmp/blowup"
check "blow-up names step and particle" grep -qE "step [0-9]+ .*particle [0-9]+" "$tmp/stderr"
check "blow-up suggests a dt" grep -q "use dt <=" "$tmp/stderr"
check "blow-up keeps complete stats" test -s "$tmp/blowup/stats.csv"
check "blow-up run.json says so" grep -q '"status": "blow-up"' "$tmp/blowup/run.json"
check "blow-up leaves no partial files" no_partial_files "$tmp/blowup"

# A short run writes frames, stats.csv (one row per frame) and a valid run.json.
check "short run" run 0 run scenes/stretch.toml "${small[@]}" --out "$tmp/ok" \
    --set render.width=160 --set render.height=90
check "six frames written" test "$(ls "$tmp/ok/frames" | grep -c '^frame_000[1-6].png$')" -eq 6
check "stats has a row per frame" test "$(wc -l <"$tmp/ok/stats.csv")" -eq 7
check "run.json is JSON" python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['status']=='ok' and d['particles']>0 and d['ns_per_particle_step']>0 and d['extra_substeps']==0" "$tmp/ok/run.json"
check "short run leaves no partial files" no_partial_files "$tmp/ok"
check "frames option" run 0 run scenes/stretch.toml "${small[@]}" --out "$tmp/range" \
    --frames 5-6 --set render.width=32 --set render.height=32
check "only frames 5-6 written" test "$(ls "$tmp/range/frames" | tr '\n' ' ')" = "frame_0005.png frame_0006.png "
check "renderer none" run 0 run scenes/stretch.toml "${small[@]}" --renderer none --out "$tmp/none"
check "renderer none writes no frames" test ! -e "$tmp/none/frames"

# Solvers: any scene runs with another discretisation; one that asks for what the solver lacks
# (here a curved rest shape for the SPH) is refused before anything is written.
check "fem solver runs" run 0 run scenes/stretch.toml "${small[@]}" --set solver=fem_cst \
    --renderer none --out "$tmp/fem"
check "fem run.json ok" grep -q '"status": "ok"' "$tmp/fem/run.json"
for solver in fem_cst mass_spring_tp; do  # the foil's elastoplastic law and the film's power law
    for scene in foil_tear rubber_film; do
        check "$scene runs with $solver" run 0 run scenes/$scene.toml --set time.duration=0.3 \
            --set solver=$solver --renderer none --out "$tmp/$scene-$solver"
    done
done
check "a notched, breaking scene runs with sph" run 0 run scenes/crack_path_sources.toml \
    --set time.duration=0.3 --set solver=sph --renderer none --out "$tmp/sph-crack"
check "sph refuses a sphere" run 2 run scenes/pressurised_sphere.toml --set solver=sph --out "$tmp/sphsphere"
check "sph refusal names the solver" grep -q "solver: expected a solver that takes shape" "$tmp/stderr"
check "sph refusal leaves no output" test ! -e "$tmp/sphsphere"

# Skipping: --renderer none with no export builds no surface, and the simulation is bitwise the
# same with and without rendering and exports (run.json's state_hash covers x, v, theta, bonds).
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2], {}, {'d': d}))" "$@"; }
check "no surface without outputs" python3 -c "import json,sys; w=json.load(open(sys.argv[1]))['wall_seconds']; assert w['surface'] == 0 and w['render'] == 0" "$tmp/none/run.json"
check "surface built when rendering" python3 -c "import json,sys; assert json.load(open(sys.argv[1]))['wall_seconds']['surface'] > 0" "$tmp/ok/run.json"
# Contact: run.json counts the self-contact's list builds and their share of its time; a scene
# without contact has neither.
check "no contact, no list builds" python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['contact_list_builds'] == 0 and d['wall_seconds']['contact_lists'] == 0" "$tmp/none/run.json"
check "film_poke short run" run 0 run scenes/film_poke.toml --set time.duration=0.5 --renderer none --out "$tmp/poke"
check "contact list builds counted" python3 -c "import json,sys; d=json.load(open(sys.argv[1])); w=d['wall_seconds']; assert d['contact_list_builds'] > 0 and 0 < w['contact_lists'] <= w['contact'] <= w['simulate'], d" "$tmp/poke/run.json"
check "simulation identical with and without rendering" test "$(json "$tmp/none/run.json" "d['state_hash']")" = "$(json "$tmp/ok/run.json" "d['state_hash']")"

# Exports and surfaces.
check "exports" run 0 run scenes/stretch.toml "${small[@]}" --renderer none --export ply,obj,glb,vdb \
    --frames 6 --out "$tmp/export"
for f in meshes/frame_0006.ply meshes/frame_0006.obj meshes/frame_0006.glb vdb/frame_0006.vdb; do
    check "export writes $f" test -s "$tmp/export/$f"
done
check "exports leave no partial files" no_partial_files "$tmp/export"
# Every format carries the same vertices in order, the same triangles and loose parts, and every
# per-point value it can (tests/export_check.py): a torn frame, and a heated one with theta.
check "torn foil exports" run 0 run scenes/foil_tear.toml --renderer none --export ply,obj,glb \
    --frames 192 --out "$tmp/torn"
check "torn frame: the same in every format, two loose parts" python3 tests/export_check.py "$tmp/torn/meshes" 192 "$(json "$tmp/torn/run.json" "d['particles']")" 2
check "heated foil exports" run 0 run scenes/foil_tear_heat.toml --renderer none --export ply,obj,glb \
    --frames 120 --out "$tmp/heated"
check "heated frame: theta in the PLY and the GLB" python3 tests/export_check.py "$tmp/heated/meshes" 120 "$(json "$tmp/heated/run.json" "d['particles']")" 1 theta
# The VDB holds the sheet at its thickness where the voxel resolves it, else two voxels.
check "run.json gives the VDB's voxel and thickness" python3 -c "import json,sys; v=json.load(open(sys.argv[1]))['vdb']; assert v['sheet_thickness'] == 0.001 and v['thickness'] == max(0.001, 2 * v['voxel_size']) > 0, v" "$tmp/export/run.json"
check "no VDB, no vdb entry" python3 -c "import json,sys; assert json.load(open(sys.argv[1]))['vdb'] is None" "$tmp/ok/run.json"
check "check estimates the VDB" run 0 check scenes/stretch.toml --set 'output.export=["vdb"]'
check "the estimate names the voxel for the sheet's thickness" grep -q "vdb at the sheet's thickness (render.vdb_voxel_size = h / 2): voxel 0.0005 m, 0.001 m thick" "$tmp/stdout"
check "exports keep the simulation identical" test "$(json "$tmp/export/run.json" "d['state_hash']")" = "$(json "$tmp/ok/run.json" "d['state_hash']")"
check "bad --export refused" run 2 run scenes/stretch.toml "${small[@]}" --export ply,stl --out "$tmp/badexport"
check "bad --export leaves no output" test ! -e "$tmp/badexport"
for surface in splat vdb; do
    for renderer in osmesa embree; do
        check "$surface surface with $renderer" run 0 run scenes/stretch.toml "${small[@]}" \
            --surface $surface --renderer $renderer --spp 2 --frames 6 --out "$tmp/$surface$renderer" \
            --set render.width=64 --set render.height=36
        check "$surface/$renderer frame written" test -s "$tmp/$surface$renderer/frames/frame_0006.png"
    done
done

# Hostile documents and options (issue 11): each refused with exit 2, a located message, and
# nothing written; none may crash or hang.
deep=$(python3 -c "print('.'.join(['a'] * 100000) + ' = 1')")
echo "$deep" >"$tmp/deep_keys.toml"
check "100000 dotted levels refused" run 2 check "$tmp/deep_keys.toml"
check "deep message located with the limit" grep -q "deep_keys.toml:1:65: error: expected at most 32 levels" "$tmp/stderr"
echo "[${deep% = 1}]" >"$tmp/deep_header.toml"
check "100000-level header refused" run 2 run "$tmp/deep_header.toml" --out "$tmp/deep_out"
check "deep header leaves no output" test ! -e "$tmp/deep_out"
check "deep --set value refused" run 2 check scenes/stretch.toml --set "sheet.size=$(printf '[%.0s' {1..40})"
check "deep --set located at the --set" grep -q "^--set 'sheet.size=\[\[\[.*error: expected at most 32 levels" "$tmp/stderr"
check "/dev/zero refused at once" bash -c "timeout 10 '$rend' check /dev/zero 2>'$tmp/stderr'; [[ \$? -eq 2 ]]"
check "/dev/zero message" grep -q "^/dev/zero: error: expected a scene file, found a character device" "$tmp/stderr"
check "a directory refused" run 2 check scenes
check "an endless pipe stops at 16 MiB" bash -c "yes | timeout 20 '$rend' check /dev/stdin 2>'$tmp/stderr'; [[ \$? -eq 2 ]]"
check "endless pipe message" grep -q "found more than the 16 MiB limit" "$tmp/stderr"
check "a piped scene is read" bash -c "'$rend' check /dev/stdin <scenes/stretch.toml >/dev/null"
mkfifo "$tmp/fifo.toml"
check "a FIFO nobody writes is refused at once" bash -c "timeout 10 '$rend' check '$tmp/fifo.toml' 2>'$tmp/stderr'; [[ \$? -eq 2 ]]"
check "FIFO message" grep -q "one that no process writes" "$tmp/stderr"
printf 'x = 1\xc3\xa9\n' >"$tmp/utf8.toml"
check "non-ASCII outside strings refused" run 2 check "$tmp/utf8.toml"
check "non-ASCII located" grep -q "utf8.toml:1:6: error: expected ASCII" "$tmp/stderr"
printf 'solver = "fem_cst"\0\n' >"$tmp/nul.toml"
check "NUL byte refused and located" run 2 check "$tmp/nul.toml"
check "NUL byte located" grep -q "nul.toml:1:19: error: TOML syntax" "$tmp/stderr"
for option in --frames --export --out; do
    out=(--out "$tmp/empty_option")
    [[ $option == --out ]] && out=()
    check "$option '' refused" run 2 run scenes/stretch.toml "${small[@]}" "${out[@]}" "$option" ''
    check "$option '' names the option" grep -q "^$option: expected .*, found an empty value" "$tmp/stderr"
done
check "empty options leave no output" test ! -e "$tmp/empty_option"
check "empty scene path refused" run 2 check ''
check "--set without a value refused" run 2 check scenes/stretch.toml --set 'material.E='
check "--set without a value message" grep -q "^--set 'material.E=': error: material.E: expected a value after '='" "$tmp/stderr"
check "--set '' refused" run 2 check scenes/stretch.toml --set ''
check "--set =x refused" run 2 check scenes/stretch.toml --set '=x'
check "--threads 0 refused" run 2 run scenes/stretch.toml --threads 0 --out "$tmp/threads0"
check "--frames given twice refused" run 2 run scenes/stretch.toml --frames 1 --frames 2 --out "$tmp/twice"
check "refused options leave no output" bash -c "! ls -d '$tmp/threads0' '$tmp/twice' '$tmp/bad_out' 2>/dev/null | grep -q ."

# Hostile output conditions (helper "outputs"): a full disk, reruns into the same folder, a killed
# run, and the blow-up guard stopping early enough.
pngs_complete() {  # every PNG under $1 ends with its IEND chunk and decodes fully
    python3 - "$1" <<'PY'
import pathlib, struct, sys, zlib
for png in pathlib.Path(sys.argv[1]).rglob("*.png"):
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[-8:-4] == b"IEND", png
    at, idat = 8, b""
    while at < len(data):
        (n,) = struct.unpack(">I", data[at:at + 4])
        if data[at + 4:at + 8] == b"IDAT":
            idat += data[at + 8:at + 8 + n]
        at += 12 + n
    zlib.decompress(idat)
PY
}
no_empty_files() { ! find "$1" -type f -empty | grep -q .; }
json_status() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['status'])" "$1"; }
full_disk() {  # full_disk KIB args... : rend run, writes past KIB KiB fail (EFBIG); exits 1?
    local limit=$1
    shift
    (
        trap '' XFSZ
        ulimit -f "$limit"
        "$rend" run "$@" >"$tmp/stdout" 2>"$tmp/stderr"
    )
    [[ $? -eq 1 ]]
}
# The frame's PNG (15 KB: zlib's deflate) is the first file past 8 KiB; run.json is 3.5 KB.
check "full disk at a PNG exits 1" full_disk 8 scenes/stretch.toml "${small[@]}" --out "$tmp/full" \
    --set render.width=2560 --set render.height=1440
check "full disk names the PNG and the reason" grep -q "cannot write $tmp/full/frames/frame_0001.png: File too large" "$tmp/stderr"
check "full disk leaves no truncated PNG" pngs_complete "$tmp/full"
check "full disk leaves no empty file" no_empty_files "$tmp/full"
check "full disk leaves no partial files" no_partial_files "$tmp/full"
check "full disk keeps stats.csv complete up to the failure" test "$(wc -l <"$tmp/full/stats.csv")" -ge 2
check "full disk run.json says failed" test "$(json_status "$tmp/full/run.json")" = failed
check "full disk at an OBJ exits 1" full_disk 60 scenes/stretch.toml "${small[@]}" --out "$tmp/fullobj" --export ply,obj
check "full disk names the OBJ" grep -q "cannot write $tmp/fullobj/meshes/frame_0001.obj: File too large" "$tmp/stderr"
check "full disk leaves no OBJ nor its MTL" test ! -e "$tmp/fullobj/meshes/frame_0001.obj" -a ! -e "$tmp/fullobj/meshes/frame_0001.mtl"
check "full disk lists what was written" python3 -c "import json,sys; f=json.load(open(sys.argv[1]))['files']; assert f==['cache/source.toml','frames/frame_0001.png','meshes/frame_0001.ply','stats.csv'], f" "$tmp/fullobj/run.json"
check "full disk keeps the frames before the failure whole" pngs_complete "$tmp/fullobj"
# The cache's writes overlap the next frame's simulation (app/CacheWriter.h), but the run waits for
# one before it writes anything of the next frame: it stops where a write of its own stopped.
check "full disk at a cache file exits 1" full_disk 16 scenes/stretch.toml "${small[@]}" --out "$tmp/fullcache" \
    --set render.width=48 --set render.height=27
check "full disk at a cache file names it" grep -q "cannot write $tmp/fullcache/cache/frame_0001.rcache: File too large" "$tmp/stderr"
check "full disk at a cache file lists what was written" python3 -c "import json,sys; f=json.load(open(sys.argv[1]))['files']; assert f==['cache/source.toml','frames/frame_0001.png','stats.csv'], f" "$tmp/fullcache/run.json"
check "full disk at a cache file writes nothing of the next frame" test ! -e "$tmp/fullcache/frames/frame_0002.png" -a "$(wc -l <"$tmp/fullcache/stats.csv")" -eq 2
check "full disk at a cache file leaves no partial files" no_partial_files "$tmp/fullcache"
check "full disk at run.json exits 1" full_disk 1 scenes/stretch.toml "${small[@]}" --out "$tmp/fulljson"
check "full disk at run.json writes nothing" test -z "$(find "$tmp/fulljson" -type f)"
check "full disk at a VDB exits 1" full_disk 100 scenes/stretch.toml "${small[@]}" --out "$tmp/fullvdb" \
    --renderer none --export vdb
check "full disk at a VDB names it" grep -q "cannot write $tmp/fullvdb/vdb/frame_0001.vdb: File too large" "$tmp/stderr"
check "full disk leaves no VDB" test -z "$(find "$tmp/fullvdb" -name '*.vdb*')"

# A rerun replaces the previous run's files: 12 frames, then 6, leaves 6 and says so (each
# frame's PNG, PLY and cache file: the second run removes 6 PNGs, 12 PLYs and 6 cache files).
rerun=(scenes/stretch.toml --set 'sheet.size=[0.4,0.4]' --set time.duration=0.5 --set render.width=32 --set render.height=32 --out "$tmp/rerun")
check "first run of 12 frames" run 0 run "${rerun[@]}" --export ply
check "rerun of 6 frames" run 0 run "${rerun[@]}" --frames 1-6
check "rerun says what it removed" grep -q "removed 24 files of the previous run in $tmp/rerun that this run does not write" "$tmp/stderr"
check "rerun leaves exactly 6 PNGs" test "$(ls "$tmp/rerun/frames" | tr '\n' ' ')" = "frame_0001.png frame_0002.png frame_0003.png frame_0004.png frame_0005.png frame_0006.png "
check "rerun removes the stale meshes and their folder" test ! -e "$tmp/rerun/meshes"
check "rerun run.json says 6" python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['frames_written']==6 and d['status']=='ok' and len(d['files'])==14, d['files']" "$tmp/rerun/run.json"
touch "$tmp/rerun/frames/notes.txt" "$tmp/rerun/frames/frame_0009.png"
check "rerun of frames 3-4" run 0 run "${rerun[@]}" --frames 3-4
check "a --frames rerun keeps only its own frames and files rend never wrote" test "$(ls "$tmp/rerun/frames" | tr '\n' ' ')" = "frame_0003.png frame_0004.png frame_0009.png notes.txt "
printf '{"files": ["../../outside.txt", "/etc/hostname", "frames/../stats.csv"]}\n' >"$tmp/rerun/run.json"
touch "$tmp/outside.txt"
check "a hostile run.json" run 0 run "${rerun[@]}" --frames 3-4
check "a hostile run.json removes nothing outside rend's names" test -e "$tmp/outside.txt" -a -e /etc/hostname

# kill -9 mid-run: run.json says the run did not finish.
# A fixed small step (Table 1's) keeps it running long enough to be killed mid-run.
"$rend" run scenes/stretch.toml --set time.duration=20 --set time.dt=1e-4 --renderer none --out "$tmp/rerun" >/dev/null 2>&1 &
killed=$!
for _ in $(seq 50); do [[ -e "$tmp/rerun/stats.csv.partial" ]] && break; sleep 0.1; done
sleep 0.5
kill -9 $killed
wait $killed 2>/dev/null
check "a killed run leaves run.json saying running" test "$(json_status "$tmp/rerun/run.json")" = running
check "a rerun after a kill" run 0 run "${rerun[@]}" --frames 1-6
check "a rerun after a kill is complete and clean" test "$(json_status "$tmp/rerun/run.json")" = ok
check "a rerun after a kill leaves no partial files" no_partial_files "$tmp/rerun"

# The guard stops the issue's unstable stretch (dt = 1/120 s, 1.44 x the bound) at frame 5, while
# the largest speed is 0.27 m/s, where it used to run to frame 8 and 176 m/s.
check "unstable stretch is caught" run 3 run scenes/stretch.toml --set time.dt=0.0084 \
    --set time.allow_unstable=true --renderer none --out "$tmp/guard"
check "blow-up located at time.dt" grep -q "^--set 'time.dt=0.0084': error: numerical blow-up" "$tmp/stderr"
check "unstable stretch is caught in frame 5" test "$(wc -l <"$tmp/guard/stats.csv")" -eq 5
check "guard message names the growth" grep -q "kinetic energy grew" "$tmp/stderr"
check "guard message gives no inf or nan" bash -c "! grep -qiE 'inf|nan' '$tmp/stderr'"
check "absurd gravity is refused at load without inf advice" run 2 run scenes/stretch.toml "${small[@]}" \
    --set 'forces.gravity=[0,0,-1e300]' --renderer none --out "$tmp/gravity"
check "absurd gravity message gives no inf or nan" bash -c "! grep -qiE 'inf|nan' '$tmp/stderr'"

# --quality: final picks a spacing giving >= 250,000 particles; the CLI wins over the file.
check "check --quality final" run 0 check scenes/foil_tear.toml --quality final
check "final quality says so with its spacing" grep -q "ok (quality final, dx 0.00429 m)" "$tmp/stdout"
check "final quality holds >= 250,000 particles" \
    test "$(grep -oE '[0-9]+ particles' "$tmp/stdout" | head -1 | cut -d' ' -f1)" -ge 250000
check "--quality wins over the file" run 0 check scenes/foil_tear.toml --set sheet.quality=final --quality preview
check "--quality preview keeps dx" grep -q "ok (quality preview, dx 0.04 m)" "$tmp/stdout"
check "dx_final overrides the chosen spacing" run 0 check scenes/foil_tear.toml --quality final --set sheet.dx_final=0.02
check "dx_final is the spacing" grep -q "dx 0.02 m" "$tmp/stdout"
check "bad --quality refused" run 2 run scenes/stretch.toml --quality ultra --out "$tmp/quality"
check "bad --quality names both levels" grep -q "expected preview, final, found \"ultra\"" "$tmp/stderr"
check "bad --quality leaves no output" test ! -e "$tmp/quality"
check "bad quality in --set refused" run 2 check scenes/stretch.toml --set sheet.quality=ultra

# An --out that names a file is bad input, refused before anything is written.
touch "$tmp/a_file"
check "--out naming a file refused" run 2 run scenes/stretch.toml --out "$tmp/a_file"
check "--out naming a file says so" grep -q "^--out .*a_file: error: expected an output folder, found a file" "$tmp/stderr"
check "--out naming a file leaves it empty" test ! -s "$tmp/a_file"

# scripts/final_frames.sh: the last frame of each scene at final quality (here a coarse
# dx_final and a short run, so the check takes a second).
final_frames() {
    OUT="$tmp/final" REND="$rend" SIZE=64x36 SPP=2 \
        REND_ARGS="--set sheet.dx_final=0.04 --set time.duration=0.5" \
        scripts/final_frames.sh scenes/seaweed.toml >"$tmp/final.txt"
}
check "final_frames runs" final_frames
check "final_frames renders the last frame" cmp -s "$tmp/final/seaweed.png" \
    "$tmp/final/seaweed/frames/frame_0012.png"
check "final_frames writes no other frame" test ! -e "$tmp/final/seaweed/frames/frame_0011.png"
check "final_frames reports the run" \
    grep -qE "^seaweed: 2929 particles, [0-9]+ steps, [1-9][0-9]* broken bonds" "$tmp/final.txt"

# The simulation cache: a run killed with SIGKILL resumes from its last whole cached frame and
# ends with the bits of a run that never stopped; rend render redraws frames from the cache, in
# chunks as a job array would, and refuses a damaged cache file by name.
cached=(scenes/towel_pile.toml --set render.width=48 --set render.height=27 --threads 1)
check "uninterrupted run" run 0 run "${cached[@]}" --out "$tmp/straight"
"$rend" run "${cached[@]}" --out "$tmp/killed" >/dev/null 2>&1 &
pid=$!
for _ in $(seq 200); do [[ -e "$tmp/killed/cache/frame_0012.rcache" ]] && break; sleep 0.05; done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
check "killed before the end" test ! -e "$tmp/killed/stats.csv"
check "resume" run 0 run "${cached[@]}" --out "$tmp/killed" --resume
check "resume says where it continues" grep -q "^resuming after frame [0-9]" "$tmp/stderr"
state_hash() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['state_hash'])" "$1/run.json"; }
check "resumed state hash is the uninterrupted one" test "$(state_hash "$tmp/killed")" = "$(state_hash "$tmp/straight")"
check "resumed stats are the uninterrupted ones" cmp -s "$tmp/killed/stats.csv" "$tmp/straight/stats.csv"
check "resumed frames are the uninterrupted ones" diff -r -q "$tmp/killed/frames" "$tmp/straight/frames"
check "resumed run lists every frame and cache file" python3 -c "import json,sys; f=json.load(open(sys.argv[1]))['files']; assert sum(n.startswith('frames/') for n in f)==48 and sum(n.endswith('.rcache') for n in f)==48, f" "$tmp/killed/run.json"
check "resume leaves no temporary file" no_partial_files "$tmp/killed"
check "resume of another scene's cache refused" run 2 run scenes/towel_pile.toml --set material.E=4e5 --out "$tmp/killed" --resume
check "resume of another scene names the fix" grep -q "no complete cached frame of this scene" "$tmp/stderr"
check "resume with no cache refused" run 2 run scenes/stretch.toml --out "$tmp/nocache" --resume
check "--cache-every 0 writes no cache" run 0 run scenes/stretch.toml --set time.duration=0.25 --renderer none --cache-every 0 --out "$tmp/nocache"
check "--cache-every 0 leaves no cache folder" test ! -e "$tmp/nocache/cache"
check "--cache-every 4 caches every fourth frame" run 0 run scenes/stretch.toml --set time.duration=0.5 --renderer none --cache-every 4 --out "$tmp/every4"
check "every fourth frame cached" test "$(ls "$tmp/every4/cache" | tr '\n' ' ')" = "frame_0004.rcache frame_0008.rcache frame_0012.rcache source.toml "
# A cache of another format (its header rewritten to format 2, with the header's checksum) is
# refused by --resume with the reason, not only "no complete cached frame".
python3 - "$tmp/every4/cache" <<'PY'
import pathlib, struct, sys
for f in pathlib.Path(sys.argv[1]).glob("*.rcache"):
    data = bytearray(f.read_bytes())
    data[8:12] = struct.pack("<I", 2)
    h = 0xcbf29ce484222325
    for b in data[:56]:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    data[56:64] = struct.pack("<Q", h)
    f.write_bytes(bytes(data))
PY
check "resume from another format's cache refused" run 2 run scenes/stretch.toml --set time.duration=0.5 --renderer none --cache-every 4 --out "$tmp/every4" --resume
check "resume from another format's cache says why" grep -q "frame_0012.rcache: error: written by cache format 2, this rend reads 3: another version of rend wrote it" "$tmp/stderr"
check "check prints the cache estimate" run 0 check scenes/towel_pile.toml
check "cache estimate line" grep -qE "cache \(rend run --cache-every 1\): [0-9.]+ MB a frame" "$tmp/stdout"

mkdir -p "$tmp/farm"
cp -r "$tmp/straight/cache" "$tmp/farm/"
for k in 1 2 3; do
    check "render chunk $k/3" run 0 render "$tmp/farm" --chunk $k/3 --threads 1
done
check "three chunks are the whole run's frames" diff -r -q "$tmp/farm/frames" "$tmp/straight/frames"
check "render a farm frame list" run 0 render "$tmp/farm" --frames 1-10,20,30-40:2 --skip-existing
check "skip-existing skips what is there" grep -q "rendered 0 frames .*(17 skipped" "$tmp/stdout"
rm "$tmp/farm/frames/frame_0020.png"
check "skip-existing redraws what is missing" run 0 render "$tmp/farm" --frames 20 --skip-existing
check "the redrawn frame is the run's" cmp -s "$tmp/farm/frames/frame_0020.png" "$tmp/straight/frames/frame_0020.png"
check "render exports from the cache" run 0 render "$tmp/farm" --frames 48 --export ply --renderer none
check "export written" test -s "$tmp/farm/meshes/frame_0048.ply"
# The particle level set is state, carried only by a run that draws it: its cache redraws a
# frame with surface = "particle_level_set" as the run drew it, and a cache without it is
# refused with the reason.
check "level-set run" run 0 run "${cached[@]}" --frames 24 --surface particle_level_set --out "$tmp/pls"
check "level-set cache of another surface refused" run 2 render "$tmp/farm" --frames 24 --surface particle_level_set
check "level-set refusal names the reason" grep -q "whose particle level set the state lacks" "$tmp/stderr"
mkdir -p "$tmp/farm_pls"
cp -r "$tmp/pls/cache" "$tmp/farm_pls/"
check "render a cached frame with the level-set surface" run 0 render "$tmp/farm_pls" --frames 24 --surface particle_level_set --threads 1
check "the level-set frame from the cache is the run's" cmp -s "$tmp/farm_pls/frames/frame_0024.png" "$tmp/pls/frames/frame_0024.png"
check "level-set stretch run" run 0 run scenes/stretch.toml --set time.duration=0.25 --renderer none --surface particle_level_set --cache-every 0 --out "$tmp/pls_hash"
check "lattice stretch run" run 0 run scenes/stretch.toml --set time.duration=0.25 --renderer none --cache-every 0 --out "$tmp/lat_hash"
check "the level set never changes the motion" test "$(state_hash "$tmp/pls_hash")" = "$(state_hash "$tmp/lat_hash")"
check "a level-set cache redraws the lattice surface too" run 0 render "$tmp/farm_pls" --frames 12 --threads 1
check "its lattice frame is the lattice run's" cmp -s "$tmp/farm_pls/frames/frame_0012.png" "$tmp/straight/frames/frame_0012.png"
differ() { ! cmp -s "$1" "$2"; }
check "the level-set frame differs from the lattice one" differ "$tmp/pls/frames/frame_0024.png" "$tmp/straight/frames/frame_0024.png"
rm "$tmp/farm/frames/frame_0030.png"
printf 'x' | dd of="$tmp/farm/cache/frame_0030.rcache" bs=1 seek=300 conv=notrunc 2>/dev/null
check "damaged cache file refused" run 2 render "$tmp/farm" --frames 30
check "damaged cache file named" grep -q "frame_0030.rcache: error: damaged" "$tmp/stderr"
check "nothing rendered from a damaged file" test ! -e "$tmp/farm/frames/frame_0030.png"
head -c 100 "$tmp/straight/cache/frame_0031.rcache" > "$tmp/farm/cache/frame_0031.rcache"
check "truncated cache file refused" run 2 render "$tmp/farm" --frames 31
check "truncated cache file named" grep -q "frame_0031.rcache: error: truncated" "$tmp/stderr"
check "render of a sim change refused" run 2 render "$tmp/farm" --frames 5 --set material.E=4e5
check "render of a sim change says so" grep -q "written for another scene" "$tmp/stderr"
check "render of a folder without cache refused" run 2 render "$tmp/nocache"
check "bad chunk refused" run 2 render "$tmp/farm" --chunk 4/3

# scripts/plot_run.py draws a run's stats.csv; plot_bench.py refuses one with a pointer to it.
mkdir -p "$tmp/empty"
if /usr/bin/python3 -c "import matplotlib" 2>/dev/null; then
    check "plot_run draws the run" scripts/plot_run.py "$tmp/straight" --out "$tmp/stats.png"
    check "plot_run writes a PNG" python3 -c "import sys; d=open(sys.argv[1],'rb').read(); assert d[:8]==b'\x89PNG\r\n\x1a\n' and len(d)>20000, len(d)" "$tmp/stats.png"
else
    echo "SKIPPED: plot_run.py (python3-matplotlib is not installed; scripts/setup.sh installs it)"
fi
check "plot_run refuses a folder without stats" bash -c '! scripts/plot_run.py "$1" 2>"$2" && grep -q "holds no stats.csv" "$2"' _ "$tmp/empty" "$tmp/plot_err"
check "plot_bench refuses stats.csv by name" bash -c '! scripts/plot_bench.py "$1" 2>"$2" && grep -q "draw it with scripts/plot_run.py" "$2" && ! grep -q Traceback "$2"' _ "$tmp/straight/stats.csv" "$tmp/plot_err"

# bench_speed (built beside rend) refuses an argument it cannot read before it measures anything:
# "1e6" is a million, and a number with anything after it is refused, not read as its start.
bench="$(dirname "$rend")/bench_speed"
if [[ -x $bench ]]; then
    for args in "--largest 1e6x" "--largest" "--largest 0" "--cpu 1.5" "--cpu -1" "--threads 2"; do
        check "bench_speed refuses $args" bash -c '"$1" $2 >/dev/null 2>"$3"; [[ $? -eq 2 ]] && grep -q "expected" "$3"' _ "$bench" "$args" "$tmp/bench_err"
    done
else
    echo "SKIPPED: bench_speed's arguments (not built: Google Benchmark missing)"
fi

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
