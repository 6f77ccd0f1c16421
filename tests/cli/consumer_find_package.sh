#!/usr/bin/env bash
# Installs lash into a temporary prefix and builds tests/consumer against it with find_package(lash).
set -euo pipefail
d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
cmake --install "$LASH_BUILD_DIR" --prefix "$d/prefix" >/dev/null
cmake -S "$LASH_SOURCE_DIR/tests/consumer" -B "$d/build" -G Ninja -DCMAKE_PREFIX_PATH="$d/prefix" >/dev/null
cmake --build "$d/build" >/dev/null
"$d/build/consumer"
