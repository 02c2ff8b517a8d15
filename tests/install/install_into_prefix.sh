#!/usr/bin/env bash
# ctest label "install", the other install tests' fixture: `cmake --install`
# of the build into PREFIX (emptied first) puts every part where it belongs,
# and the installed vfield runs from there: it reports its version, and the
# farm's jobs it writes run the installed make-sheet, not the source tree's.
# Usage: install_into_prefix.sh BUILD_DIR PREFIX LIBDIR (LIBDIR relative to PREFIX)
set -euo pipefail
build=$1 prefix=$2 libdir=$3
here=$(cd "$(dirname "$0")" && pwd)
fail() { echo "install test: $*" >&2; exit 1; }

rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
for file in bin/vfield "$libdir/libvfield.so.0" "$libdir/libvfield.so" include/vfield/vfield.h \
    include/vfield/host/session.h "$libdir/cmake/vfield/vfieldConfig.cmake" \
    "$libdir/cmake/vfield/vfieldConfigVersion.cmake" "$libdir/cmake/vfield/vfieldTargets.cmake" \
    "$libdir/pkgconfig/vfield.pc" libexec/vfield/make-sheet share/vfield/vfield_blender.zip; do
    [[ -e $prefix/$file ]] || fail "$prefix/$file was not installed"
done

# The installed command loads the installed library (its run path), not the build's.
loaded=$(ldd "$prefix/bin/vfield" | awk '$1 == "libvfield.so.0" { print $3 }')
[[ $(realpath "$loaded") == $(realpath "$prefix/$libdir/libvfield.so.0") ]] ||
    fail "the installed vfield loads ${loaded:-no libvfield.so.0}, not $prefix/$libdir/libvfield.so.0"
version=$("$prefix/bin/vfield" --version)
grep -q '^vfield [0-9]' <<< "$version" || fail "vfield --version printed: $version"

work=$(mktemp -d /tmp/vfield-install-test.XXXXXX)
trap 'rm -rf "$work"' EXIT
"$prefix/bin/vfield" farm "$here/cloud_on_box.json" -o "$work/farm" --engine local --dry-run >/dev/null
grep -qF "'$prefix/libexec/vfield/make-sheet'" "$work/farm/farm/finish.sh" ||
    fail "the farm's finish job does not run the installed make-sheet: $(tail -1 "$work/farm/farm/finish.sh")"
echo "installed into $prefix; $(head -1 <<< "$version")"
