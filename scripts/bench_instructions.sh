#!/usr/bin/env bash
# Instructions per particle-step of each part of the membrane step, counted by callgrind: the
# same count on every run, where a shared machine's timings move by a third (README, issue 16).
# For each scene and bond law (square lattice, dt 1e-4, one thread: bench_speed's per-law rows),
# build/bench_instructions steps the membrane WARM times and then STEPS times, and only those
# are counted (callgrind --toggle-collect on its measuredSteps). The functions' own counts are
# summed by part:
#   pair       the pair kernel (eqs. 18-20, 27-28: each bond's force once, into its slot)
#   sums       each particle's sum of its bonds' forces (sim/PairSums)
#   kick       the kick and drift (symplectic Euler; with the guard's sums where they are taken
#              in its loop, as with adaptive steps)
#   diffusion  eq. 25 (sim/Diffusion, sim/DiffusionKernels)
#   guard      the blow-up guard's sample (sim/BlowUpGuard, sim/StepKernels)
#   other      the rest (the step's bookkeeping, fracture's proposals, OpenMP)
# and divided by particles x STEPS.
#
#   scripts/bench_instructions.sh                 stretch and crack_path_sources, three laws
#   SCENES="stretch" LAWS="linear" STEPS=5 scripts/bench_instructions.sh
#   BASE=/path/to/other/build scripts/bench_instructions.sh   that build's counts beside, and
#                                                              the change
#   LATTICE=hexagonal scripts/bench_instructions.sh           (or scene: each scene's own)
#   DT=scene LATTICE=scene WARM=2 STEPS=1 scripts/bench_instructions.sh
#        the scenes as shipped, frame by frame (adaptive steps: the kick in its own pass); WARM
#        and STEPS then count frames
# Needs valgrind (apt-get install valgrind); says so and exits 0 without it. Each run of 10^4
# particles and 25 steps takes 10-20 s.
set -euo pipefail
cd "$(dirname "$0")/.."
scenes=${SCENES:-"stretch crack_path_sources"}
laws=${LAWS:-"linear power_law elastoplastic"}
warm=${WARM:-5}
steps=${STEPS:-20}
build=${BUILD:-build}
lattice=${LATTICE:-square}
dt=${DT:-1e-4}
# Passed on only when asked for: a BASE build from before LATTICE takes four arguments.
lattice_arg=()
[[ -n ${LATTICE:-} || -n ${DT:-} ]] && lattice_arg=("$lattice")
[[ -n ${DT:-} ]] && lattice_arg+=("$DT")
command -v valgrind >/dev/null || {
    echo "bench_instructions: valgrind not installed (apt-get install valgrind)"
    exit 0
}
[[ -x $build/bench_instructions ]] || cmake --build "$build" --target bench_instructions >/dev/null
if [[ -n ${BASE:-} && ! -x $BASE/bench_instructions ]]; then
    echo "bench_instructions: BASE=$BASE has no bench_instructions (build it there first)" >&2
    exit 2
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# count BINARY SCENE LAW OUT: the parts' counts per particle-step into OUT (one line).
count() {
    local binary=$1 scene=$2 law=$3 out=$4
    local shape
    shape=$(valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*measuredSteps*' \
        --callgrind-out-file="$tmp/cg" "$binary" "$scene.toml" "$law" "$warm" "$steps" "${lattice_arg[@]}" \
        2>"$tmp/valgrind.txt") || {
        echo "bench_instructions: $binary $scene $law failed:" >&2
        tail -5 "$tmp/valgrind.txt" >&2
        exit 1
    }
    callgrind_annotate --inclusive=no --threshold=100 "$tmp/cg" >"$tmp/annotate.txt"
    python3 - "$tmp/annotate.txt" "$shape" >"$out" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
particles, steps = map(int, re.match(r"particles (\d+) steps (\d+)", sys.argv[2]).groups())
parts = [("pair", r"pairLoop|PairKernel|linearPairForces|simdPairs|plasticForces"),
         ("sums", r"gatherTiles|gatherParticle|gatherLoop|gatherPairForces|sum\w*Tile"),
         ("kick", r"kickDrift|kickQuads|kickGuard"),
         ("diffusion", r"diffuse|Diffusion"),
         ("guard", r"guard|BlowUpGuard")]
totals = dict.fromkeys([p for p, _ in parts] + ["other"], 0)
total = 0
for line in text.splitlines():
    m = re.match(r"\s*([\d,]+) \(\s*[\d.]+%\)\s+(.*)", line)
    if not m or "PROGRAM TOTALS" in line:
        continue
    n = int(m.group(1).replace(",", ""))
    name = m.group(2)
    part = next((p for p, pattern in parts if re.search(pattern, name)), "other")
    totals[part] += n
    total += n
m = re.search(r"([\d,]+) \(100\.0%\)\s+PROGRAM TOTALS", text)
program = int(m.group(1).replace(",", "")) if m else total
scale = 1.0 / (particles * steps)
print(particles, program * scale, *(totals[p] * scale for p in totals))
EOF
}

printf 'instructions per particle-step (callgrind), %s steps counted after %s, one thread, %s lattice, dt %s\n' \
    "$steps" "$warm" "$lattice" "$dt"
printf '%-20s %-14s %9s %8s %8s %8s %8s %9s %8s %8s\n' scene law particles total pair sums kick \
    diffusion guard other
for scene in $scenes; do
    for law in $laws; do
        count "$build/bench_instructions" "$scene" "$law" "$tmp/new"
        read -r n total pair sums kick diffusion guard other <"$tmp/new"
        printf '%-20s %-14s %9d %8.1f %8.1f %8.1f %8.1f %9.1f %8.1f %8.1f\n' "$scene" "$law" \
            "$n" "$total" "$pair" "$sums" "$kick" "$diffusion" "$guard" "$other"
        [[ -n ${BASE:-} ]] || continue
        count "$BASE/bench_instructions" "$scene" "$law" "$tmp/base"
        read -r _ btotal bpair bsums bkick bdiffusion bguard bother <"$tmp/base"
        printf '%-20s %-14s %9s %8.1f %8.1f %8.1f %8.1f %9.1f %8.1f %8.1f\n' "  BASE" "" "" \
            "$btotal" "$bpair" "$bsums" "$bkick" "$bdiffusion" "$bguard" "$bother"
        change() { python3 -c "import sys; a, b = map(float, sys.argv[1:]); print(f'{(a / b - 1) * 100:+.1f}%' if b else '-')" "$1" "$2"; }
        printf '%-20s %-14s %9s %8s %8s %8s %8s %9s %8s %8s\n' "  change" "" "" \
            "$(change "$total" "$btotal")" "$(change "$pair" "$bpair")" \
            "$(change "$sums" "$bsums")" "$(change "$kick" "$bkick")" \
            "$(change "$diffusion" "$bdiffusion")" "$(change "$guard" "$bguard")" \
            "$(change "$other" "$bother")"
    done
done
