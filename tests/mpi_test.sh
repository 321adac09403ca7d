#!/usr/bin/env bash
# mpirun -np 2 rend run (app/MpiDomain.h): the state hash equals one process's, with fracture,
# diffusion and each bond law; the outputs are the same files written once; what a decomposed
# run does not support is refused with the reason. Skips (77) without mpirun or an MPI build.
set -uo pipefail
rend=$(realpath "$1")
command -v mpirun >/dev/null || { echo "SKIP: no mpirun (apt-get install openmpi-bin)"; exit 77; }
"$rend" --version | grep -q "MPI" || { echo "SKIP: rend was built without MPI"; exit 77; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
check() {  # name, then a command that must succeed
    local name=$1
    shift
    if "$@"; then echo "ok   $name"; else echo "FAIL $name"; failures=$((failures + 1)); fi
}
hash_of() { grep -o '"state_hash": *"[0-9a-f]*"' "$1/run.json" | grep -o '[0-9a-f]\{16\}'; }

# law, fracture and diffusion: crack_path_sources (linear, heat sources, breaking), foil_tear_heat
# (elastoplastic, heat, tearing), rubber_film (power law: its look-ahead counts only its own
# pairs), paper_towel_wet (bonds breaking across the slabs' boundary by frame 6: both processes
# break them in the same step)
for case in "crack_path_sources 1-8" "foil_tear_heat 1-8" "rubber_film 1-8" "paper_towel_wet 1-8"; do
    set -- $case
    scene=$1 frames=$2
    args=(run "scenes/$scene.toml" --renderer none --frames "$frames" --threads 1)
    "$rend" "${args[@]}" --out "$work/$scene.1" >"$work/$scene.1.log" 2>&1
    mpirun -np 2 "$rend" "${args[@]}" --out "$work/$scene.2" >"$work/$scene.2.log" 2>&1
    one=$(hash_of "$work/$scene.1") two=$(hash_of "$work/$scene.2")
    check "$scene: 2 processes give one's state hash ($one = $two)" test -n "$one" -a "$one" = "$two"
    check "$scene: the same files" diff <(cd "$work/$scene.1" && find . -type f | sort) \
        <(cd "$work/$scene.2" && find . -type f | sort)
    check "$scene: the same stats" cmp -s "$work/$scene.1/stats.csv" "$work/$scene.2/stats.csv"
    check "$scene: one report line" test "$(grep -c '^wrote' "$work/$scene.2.log")" = 1
done
broken=$(tail -1 "$work/crack_path_sources.2/stats.csv" | cut -d, -f7)
check "crack_path_sources breaks bonds ($broken) and diffuses" test "${broken:-0}" -gt 0

# resumed from a cache on 2 processes: the same state as straight through
args=(run scenes/crack_path_sources.toml --renderer none --frames 1-8 --threads 1)
mpirun -np 2 "$rend" "${args[@]/1-8/1-4}" --out "$work/resume" >/dev/null 2>&1
mpirun -np 2 "$rend" "${args[@]}" --resume --out "$work/resume" >/dev/null 2>&1
check "a 2-process resume gives the straight run's hash" \
    test "$(hash_of "$work/resume")" = "$(hash_of "$work/crack_path_sources.1")"

refused() {  # processes, --set value, words the error must hold
    local out
    out=$(mpirun -np "$1" "$rend" run scenes/stretch.toml --renderer none --frames 1 --set "$2" \
        --out "$work/refused" 2>&1)
    local rc=$?
    [[ $rc -ne 0 ]] && grep -q "$3" <<<"$out" && ! grep -q "^wrote" <<<"$out" || { echo "rc $rc: $out" | head -5; false; }
}
check "the FEM is refused with its reason" refused 2 solver=fem_cst "runs on one process only"
check "self-contact is refused with its reason" refused 2 contact.self=true "self-contact"
check "8 processes for 23 particles are refused" refused 8 sheet.dx=0.5 "run with fewer processes"

echo "$failures failures"
[[ $failures -eq 0 ]]
