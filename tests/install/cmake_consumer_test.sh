#!/usr/bin/env bash
# ctest label "install": a CMake project of its own (consumer/) finds the
# installed vfield with find_package(vfield) (its dependencies through the
# package's config file), builds against vfield::vfield and runs.
# Usage: cmake_consumer_test.sh PREFIX WORK_DIR
set -euo pipefail
prefix=$1 work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
cmake -S "$here/consumer" -B "$work" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work" >/dev/null
# The program finds libvfield by the run path CMake gave it, in the prefix.
"$work/vfield_consumer"
