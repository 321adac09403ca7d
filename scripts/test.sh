#!/usr/bin/env bash
# Set-up, build, the whole test suite through ctest, then a minute of fuzzing the scene loader.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
# ctest runs tests side by side on few cores: spinning OpenMP threads would starve each other.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
(cd build && ctest --output-on-failure -j "$(nproc 2>/dev/null || echo 2)" "$@")
# The scene loader under libFuzzer for a bounded time (skipped with a message without clang); a
# crash, leak, UB or hang fails.
scripts/fuzz.sh "${REND_FUZZ_SECONDS:-60}"
