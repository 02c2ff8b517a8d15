#!/usr/bin/env bash
# `vfield golden check --report` opened in a real browser, as a person opens a
# CI artifact: two recorded cases, one of whose goldens is tinted so that it
# fails. Chromium (headless) must show the failing case's golden, new and
# difference images (find_images looks for each in its screenshot, pixel for
# pixel), and list the failing case first in the page it built (--dump-dom).
# Exit 77 (skipped) when chromium is not installed.
#   report_opens_in_chromium.sh VFIELD FIND_IMAGES SCENE WORK
set -euo pipefail
vfield=$1 find_images=$2 scene=$3 work=$4
command -v chromium >/dev/null || { echo "chromium is not installed (tools/setup installs it): skipped"; exit 77; }
rm -rf "$work"
mkdir -p "$work"
cd "$work"

for name in passing failing; do
    "$vfield" golden record "$scene" --frames 1 -o "cases/$name" --resolution 96x54 --spp 1 --quiet
done
oiiotool cases/failing/frame.0001.png --mulc 0.8,1,1 -o cases/failing/frame.0001.png

status=0
"$vfield" golden check cases --work out --report report.html --junit junit.xml --quiet || status=$?
[[ $status -eq 1 ]] || { echo "golden check exited $status, expected 1 (one case fails)"; exit 1; }

browser=(chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --force-device-scale-factor=1
         --force-color-profile=srgb --user-data-dir="$work/profile")
"${browser[@]}" --window-size=1000,800 --screenshot="$work/screenshot.png" "file://$work/report.html" 2>/dev/null
"$find_images" screenshot.png cases/failing/frame.0001.png out/failing/images/frame.0001.png out/failing/frame.0001.diff.png
echo "the failing case's golden, new and difference images are on the screen"

"${browser[@]}" --dump-dom "file://$work/report.html" 2>/dev/null > dom.html
first=$(grep -o 'data-verdict="[a-z]*" data-name="[a-z]*"' dom.html | head -n 1)
[[ $first == 'data-verdict="fail" data-name="failing"' ]] || { echo "the page lists first: $first"; exit 1; }
[[ $(grep -c 'class="wipe"' dom.html) -eq 2 ]] || { echo "expected a golden | new slider per image"; exit 1; }
echo "the failing case is listed first"
