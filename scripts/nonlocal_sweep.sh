#!/usr/bin/env bash
# The non-local sweep of the membrane paper's Fig. 11: scenes/nonlocal.toml at the five cutoffs
# R = 0.0681, 0.0749, 0.0851, 0.0953, 0.102 m (dx = 0.04, so horizon = R / dx), each into
# out/nonlocal_R<R>/. Extra arguments go to every `rend run`.
set -euo pipefail
cd "$(dirname "$0")/.."
[[ -x build/rend ]] || scripts/build.sh
for R in 0.0681 0.0749 0.0851 0.0953 0.102; do
    horizon=$(python3 -c "print($R / 0.04)")
    echo "nonlocal: R = $R m (horizon $horizon dx)"
    build/rend run scenes/nonlocal.toml --set "sheet.horizon=$horizon" --out "out/nonlocal_R$R" "$@"
done
echo "nonlocal: broken bonds at the last frame:"
for R in 0.0681 0.0749 0.0851 0.0953 0.102; do
    echo "  R = $R: $(tail -1 "out/nonlocal_R$R/stats.csv" | cut -d, -f7)"
done
