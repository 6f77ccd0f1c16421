#!/usr/bin/env bash
# Installs lash's build and test dependencies from Debian packages only.
# Idempotent: packages already present are not touched and apt is not called.
# Uses sudo when not run as root.
set -euo pipefail

packages=(
  # build
  build-essential cmake ninja-build g++ clang pkg-config
  # libraries
  libeigen3-dev libcli11-dev libfmt-dev libtomlplusplus-dev nlohmann-json3-dev
  libmatio-dev zlib1g-dev libsqlite3-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev gnuplot-nox valgrind sqlite3
  rt-tests  # cyclictest, the peer of bench/latency_vs_cyclictest.py
  iproute2 util-linux
  # python oracles (Debian's /usr/bin/python3)
  python3 python3-numpy python3-scipy python3-statsmodels python3-can
  python3-canmatrix python3-msgpack python3-crcmod
  # the lash Python package, its examples and the fleet example on Dask
  pybind11-dev python3-dev python3-distributed python3-matplotlib python3-pytest
  # SocketCAN test under qemu
  qemu-system-x86 busybox-static cpio
  # libFuzzer / sanitizers runtime for clang
  libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
