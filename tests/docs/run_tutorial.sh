#!/usr/bin/env bash
# Runs the shell blocks of a Markdown page that are marked runnable (the line
# `<!-- runnable -->` right before a ```sh fence), in order, as a reader
# would: in a fresh folder holding `scenes` (the project's scene files), with
# the vfield under test first on PATH. Fails on the first block that fails,
# naming its line in the page.
#   run_tutorial.sh VFIELD PAGE.md SCENES_DIR WORK_DIR
set -euo pipefail
vfield=$1 page=$2 scenes=$3 work=$4

rm -rf "$work"
mkdir -p "$work/bin" "$work/shot"
ln -s "$(realpath "$vfield")" "$work/bin/vfield"
ln -s "$(realpath "$scenes")" "$work/shot/scenes"

# Each runnable block into its own script, named for the line it starts on.
awk -v out="$work" '
    /^<!-- runnable -->[[:space:]]*$/ { marked = NR; next }
    marked == NR - 1 && /^```(sh|bash)[[:space:]]*$/ { script = sprintf("%s/block-%05d.sh", out, NR + 1); inside = 1; next }
    inside && /^```[[:space:]]*$/ { inside = 0; close(script); next }
    inside { print > script }
' "$page"

shopt -s nullglob
blocks=("$work"/block-*.sh)
if [[ ${#blocks[@]} -eq 0 ]]; then
    echo "$page: no runnable blocks (a line <!-- runnable --> before a \`\`\`sh fence)" >&2
    exit 1
fi
for block in "${blocks[@]}"; do
    line=$(basename "$block" .sh)
    line=$((10#${line#block-}))
    echo "--- $page:$line" >&2
    if ! (cd "$work/shot" && PATH="$work/bin:$PATH" bash -euo pipefail "$block"); then
        echo "$page:$line: this runnable block failed" >&2
        exit 1
    fi
done
echo "${#blocks[@]} runnable blocks of $page ran" >&2
