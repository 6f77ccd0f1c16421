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
  libcpp-httplib-dev  # the console's HTTP server (docs/console.md)
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
  # the console's browser test (tests/cli/console_browser.py) and uPlot's installer
  chromium chromium-driver python3-selenium
  # libFuzzer / sanitizers runtime for clang
  libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} > 0)); then
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  echo "install-deps: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# uPlot, the console's plotting library (browser side), from the npm registry at a pinned
# version, into a cache outside the repository; the console serves its files from there
# (cmake -DLASH_UPLOT_DIR=... or the environment's LASH_UPLOT_DIR point elsewhere).
UPLOT_VERSION=1.6.32
npm_prefix="${LASH_NPM_PREFIX:-${XDG_CACHE_HOME:-$HOME/.cache}/lash/npm}"
if [[ ! -f "$npm_prefix/node_modules/uplot/dist/uPlot.iife.min.js" ]] ||
   ! grep -q "\"version\": \"$UPLOT_VERSION\"" "$npm_prefix/node_modules/uplot/package.json"; then
  command -v npm >/dev/null || { echo "install-deps: npm is needed to install uPlot (the console)" >&2; exit 1; }
  mkdir -p "$npm_prefix"
  echo "install-deps: npm install uplot@$UPLOT_VERSION into $npm_prefix" >&2
  npm install --prefix "$npm_prefix" --no-audit --no-fund --save-exact "uplot@$UPLOT_VERSION" >/dev/null
fi
