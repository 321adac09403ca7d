#!/usr/bin/env bash
# Installs exactly the Debian packages rend needs. Idempotent: when everything is present it
# only asks dpkg and returns in well under a second.
set -euo pipefail

packages=(
    cmake g++ ninja-build pkg-config clang-format python3
    libeigen3-dev libembree-dev libopenvdb-dev libboost-dev libboost-iostreams-dev libtbb-dev
    zlib1g-dev  # the PNG frames' deflate (render/Image)
    libopenexr-dev  # OpenEXR 3.1: frames for compositing (render/ExrWriter)
    libosmesa6-dev libstb-dev libassimp-dev libtomlplusplus-dev libcli11-dev
    libzstd-dev  # the simulation cache (app/Cache): compressed, checksummed frames
    libopenmpi-dev openmpi-bin  # mpirun -np N rend run (app/MpiDomain), tests/mpi_test.sh
    python3-matplotlib  # scripts/plot_run.py and plot_bench.py (tested in tests/cli_test.sh)
    libgtest-dev libbenchmark-dev
    clang libclang-rt-14-dev  # scripts/fuzz.sh: libFuzzer with ASan and UBSan over the loader
)

missing=()
for p in "${packages[@]}"; do
    status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
    [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
if [[ ${#missing[@]} -eq 0 ]]; then
    echo "setup: all ${#packages[@]} packages present"
    exit 0
fi

echo "setup: installing ${missing[*]}"
sudo=""
if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "setup: need root or sudo to install packages" >&2; exit 1; }
    sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
