#!/usr/bin/env bash
# ctest label "install": a C host compiled against the installed vfield.h
# loads the installed libvfield with dlopen and simulates a scene through the
# C API (dlopen_host.c).
# Usage: dlopen_host_test.sh PREFIX LIBDIR WORK_DIR (LIBDIR relative to PREFIX)
set -euo pipefail
prefix=$1 libdir=$2 work=$3
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$work"
cc -std=c99 -Wall -Wextra -Werror -I"$prefix/include" "$here/dlopen_host.c" -o "$work/dlopen_host" -ldl
"$work/dlopen_host" "$prefix/$libdir/libvfield.so.0" "$here/cloud_on_box.json"
