#!/usr/bin/env bash
# ctest label "install": the installed vfield.pc resolves (with its
# dependencies' .pc files) to flags that compile and link the consumer's
# program, which then runs against the installed library.
# Usage: pkg_config_test.sh PREFIX LIBDIR WORK_DIR (LIBDIR relative to PREFIX)
set -euo pipefail
prefix=$1 libdir=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
export PKG_CONFIG_PATH=$prefix/$libdir/pkgconfig
rm -rf "$work"
mkdir -p "$work"
read -ra flags <<< "$(pkg-config --cflags --libs vfield)"
c++ -std=c++17 -DVFIELD_PACKAGE_VERSION="\"$(pkg-config --modversion vfield)\"" \
    "$here/consumer/main.cpp" -o "$work/vfield_consumer" "${flags[@]}"
LD_LIBRARY_PATH=$prefix/$libdir "$work/vfield_consumer"
