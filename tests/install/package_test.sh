#!/usr/bin/env bash
# ctest label "install": tools/package makes the Debian package from the
# build; as root with apt (CI: a fresh Debian 12), `apt-get install` takes it
# with its Depends, and the installed /usr/bin/vfield reports the versions of
# the four libraries it runs with and finds the installed OpenColorIO config. The package is removed again unless it was
# installed before. Exits 77 (skipped) when not root or without apt-get.
# Usage: package_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -euo pipefail
source=$1 build=$2 work=$3
fail() { echo "package test: $*" >&2; exit 1; }

rm -rf "$work"
deb=$("$source/tools/package" "$work" "$build")
[[ -f $deb ]] || fail "tools/package made no .deb ($deb)"
depends=$(dpkg-deb -f "$deb" Depends)
for package in libopenvdb10.0 libembree3-3 libopenimageio2.4 libtbb12 libassimp5 povray; do
    grep -qw -- "$package" <<< "$depends" || fail "Depends lacks $package: $depends"
done
echo "$(basename "$deb"): $(du -k "$deb" | cut -f1) KiB, Depends: $depends"

if [[ $(id -u) -ne 0 ]] || ! command -v apt-get >/dev/null; then
    echo "package test: skipped installing it (needs root and apt-get)"
    exit 77
fi
installed_before=$(dpkg-query -W -f='${Status}' vfield 2>/dev/null || true)
if [[ $installed_before != "install ok installed" ]]; then
    trap 'DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq vfield >/dev/null 2>&1 || true' EXIT
fi
log=$(cd "$(dirname "$deb")" && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "./$(basename "$deb")" 2>&1) ||
    fail "apt-get install ./$(basename "$deb") failed: $log"
version=$(/usr/bin/vfield --version) || fail "/usr/bin/vfield --version failed"
for library in OpenVDB Embree OpenImageIO POV-Ray; do
    grep -q "^$library [0-9]" <<< "$version" || fail "/usr/bin/vfield --version names no $library version: $version"
done
# Its OpenColorIO config is the package's, found from where the library lies.
grep -qx "OpenColorIO config /usr/share/vfield/ocio/config.ocio" <<< "$version" ||
    fail "/usr/bin/vfield does not find the installed OpenColorIO config: $version"
echo "$version"
