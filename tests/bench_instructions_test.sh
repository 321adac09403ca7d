#!/usr/bin/env bash
# scripts/bench_instructions.sh on two steps of stretch and crack_path_sources (linear law):
# every part of a step is counted where the scene has it and nowhere else (stretch has no theta,
# so no diffusion), the parts add up to the total, and bench_instructions refuses what it cannot
# read. Exit 77 (skipped) without valgrind.
#   tests/bench_instructions_test.sh BUILD_DIR
set -uo pipefail
build=$1
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || {
    echo "SKIPPED: valgrind not installed (apt-get install valgrind)"
    exit 77
}
failed=0
check() {
    local what=$1
    shift
    if "$@"; then echo "ok: $what"; else echo "FAILED: $what"; failed=1; fi
}

for args in "stretch.toml" "stretch.toml cubic" "stretch.toml linear 5" \
    "stretch.toml linear 0 3" "stretch.toml linear 2 x" "stretch.toml linear 2 2 cubic" "stretch.toml linear 2 2 square -1"; do
    check "bench_instructions refuses '$args'" bash -c \
        '"$1"/bench_instructions $2 >/dev/null 2>"$3"; [[ $? -eq 2 ]] && grep -q expected "$3"' \
        _ "$build" "$args" "$(mktemp)"
done

out=$(BUILD=$build SCENES="stretch crack_path_sources" LAWS=linear WARM=2 STEPS=2 \
    scripts/bench_instructions.sh) || { echo "FAILED: the script: $out"; exit 1; }
echo "$out"
row() { echo "$out" | awk -v s="$1" '$1 == s && $2 == "linear"'; }
stretch=$(row stretch) crack=$(row crack_path_sources)
check "a row per scene" test -n "$stretch" -a -n "$crack"
# Columns: scene law particles total pair sums kick diffusion guard other.
check "stretch: 10,201 particles" test "$(echo "$stretch" | awk '{print $3}')" = 10201
check "stretch: no diffusion (no theta)" awk '{exit !($8 == 0)}' <<<"$stretch"
# The kick in the force pass takes each guard block's sums in its own loop (Membrane's
# KickInPass): no guard pass is left without theta.
check "stretch: the guard's sums taken in the kick" awk '{exit !($9 < 1)}' <<<"$stretch"
# The guard's share of theta is its own pass (its motion's is the kick's: kickDriftSampled).
check "crack_path_sources: every part counted" \
    awk '{exit !($5 > 20 && $6 > 5 && $7 > 5 && $8 > 5 && $9 > 1)}' <<<"$crack"
check "crack_path_sources: the pair kernel above stretch's (theta and breaking)" \
    awk -v s="$(echo "$stretch" | awk '{print $5}')" '{exit !($5 > s)}' <<<"$crack"
for r in "$stretch" "$crack"; do
    check "the parts add up to the total: $r" \
        awk '{d = $5 + $6 + $7 + $8 + $9 + $10 - $4; exit !(d < 0.5 && d > -0.5)}' <<<"$r"
done
exit $failed
