#!/usr/bin/env bash
# Builds the scene-loader fuzz target (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer)
# with clang in build-fuzz/ and runs it for a bounded time. A crash, leak, UB or hang fails
# (exit 1) and leaves the input in build-fuzz/artifacts/. Skips with a message (exit 0) when
# clang++ or its libFuzzer runtime is absent.
# Usage: scripts/fuzz.sh [SECONDS]   (default 60; REND_FUZZ_CXX picks the compiler)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
cxx=${REND_FUZZ_CXX:-clang++}
cc=${REND_FUZZ_CC:-clang}
build=build-fuzz

if ! command -v "$cxx" >/dev/null 2>&1; then
    echo "fuzz: skipped ($cxx not found; install clang to fuzz the scene loader)"
    exit 0
fi
# Distributions ship the libFuzzer runtime apart from clang: link an empty target to know.
probe=$(mktemp -d)
trap 'rm -rf "$probe"' EXIT
echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' \
    >"$probe/probe.cpp"
if ! "$cxx" -fsanitize=fuzzer,address,undefined "$probe/probe.cpp" -o "$probe/probe" 2>/dev/null
then
    echo "fuzz: skipped ($cxx cannot link -fsanitize=fuzzer; install its libFuzzer runtime)"
    exit 0
fi

launcher=()
command -v ccache >/dev/null 2>&1 && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
mkdir -p "$build"
if ! cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER="$cc" \
    -DCMAKE_CXX_COMPILER="$cxx" -DREND_FUZZ=ON -DREND_BUILD_TESTS=OFF -DREND_BUILD_BENCH=OFF \
    "${launcher[@]}" >"$build/configure.log" 2>&1; then
    cat "$build/configure.log"
    exit 1
fi
cmake --build "$build" --target rend_scene_fuzz

# Seeds: every shipped scene and preset, --set examples and the saved regressions. New inputs
# libFuzzer finds stay in the corpus folder for the next run.
corpus=$build/corpus
mkdir -p "$corpus" "$build/artifacts"
for seed in scenes/*.toml assets/materials/*.toml fuzz/seeds/* tests/fuzz/regressions/*; do
    [[ -f $seed ]] && cp "$seed" "$corpus/$(dirname "$seed" | tr / _)_$(basename "$seed")"
done
# A dictionary of the keys the shipped scenes use, so mutations stay near valid scenes.
grep -ohE '^\s*\[*[a-z_.]+' scenes/*.toml assets/materials/*.toml | tr -d ' [' | tr '.' '\n' |
    sort -u | sed 's/.*/"&"/' >"$build/keys.dict"

status=0
"$build/fuzz/rend_scene_fuzz" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=16384 -dict="$build/keys.dict" -artifact_prefix="$build/artifacts/" \
    -print_final_stats=1 "$corpus" 2>"$build/fuzz.log" || status=$?
runs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$build/fuzz.log" | grep -oE '[0-9]+$' ||
    true)
if [[ $status -ne 0 ]]; then
    tail -n 40 "$build/fuzz.log"
    echo "fuzz: FAILED after ${runs:-?} executions; the input is in $build/artifacts/." \
        "Once fixed, keep it in tests/fuzz/regressions/ (rend_app_tests replays it)."
    exit 1
fi
echo "fuzz: ${runs:-?} executions in ${seconds} s, no crash ($(ls "$corpus" | wc -l) inputs in $corpus)"
