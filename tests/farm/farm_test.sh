#!/usr/bin/env bash
# ctest label "farm": a small scene, the same in two particle shards, and a
# two-value wedge through a real one-node Slurm cluster (tools/slurm-local);
# the farm's frames must equal a local `vfield run` of the same scene, and
# every job's product must exist.
# Usage: farm_test.sh VFIELD
set -euo pipefail
vfield=$(realpath "$1")
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d /tmp/vfield-farm-test.XXXXXX)
chmod 755 "$work"
trap '"$root/tools/slurm-local" stop >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
fail() { echo "farm test: $*" >&2; exit 1; }

"$root/tools/slurm-local" start
eval "$("$root/tools/slurm-local" env)"

scene=$root/scenes/cloud_over_terrain.json
small=(--set /clouds/0/count=3000 --set '/render/resolution=[160,90]' --set /render/samplesPerPixel=1 --set /frames/end=6)
"$vfield" farm "$scene" -o "$work/farm" --chunk 2 --cpus-per-task 1 "${small[@]}"
"$vfield" farm "$scene" -o "$work/wedge" --frames 5-6 --chunk 1 --cpus-per-task 1 \
    --wedge /clouds/0/drag=0.4,0.8 "${small[@]}"
"$vfield" farm "$scene" -o "$work/sharded" --shards 2 --chunk 3 --cpus-per-task 1 "${small[@]}"

# Wait for both: every frame rendered and no job left (the sheets come last).
finished() {
    local status
    status=$("$vfield" farm status "$1")
    grep -q '^no job queued or running' <<< "$status" && grep -q '^done' <<< "$status"
}
for _ in $(seq 1 300); do
    finished "$work/farm" && finished "$work/wedge" && finished "$work/sharded" && break
    sleep 2
done
"$vfield" farm status "$work/farm"
"$vfield" farm status "$work/wedge"
finished "$work/farm" || fail "the farm did not finish (logs in $work/farm/farm/)"
finished "$work/wedge" || fail "the wedge did not finish (logs in $work/wedge/*/farm/)"
finished "$work/sharded" || fail "the sharded farm did not finish (logs in $work/sharded/farm/)"

# The farm's frames are a local run's, pixel for pixel.
"$vfield" run "$scene" -o "$work/local" --quiet "${small[@]}"
for frame in 1 2 3 4 5 6; do
    name=frame.$(printf %04d $frame).png
    "$vfield" compare "$work/farm/$name" "$work/local/$name" >/dev/null || fail "$name differs from the local run"
    "$vfield" compare "$work/sharded/$name" "$work/local/$name" >/dev/null || fail "the sharded farm's $name differs from the local run"
    # Its density sums the same particles in another order: equal to the
    # 16-bit floats it is stored in.
    density=sim/density.$(printf %04d $frame).vdb
    "$vfield" compare --tolerance 1e-4 "$work/sharded/$density" "$work/local/$density" >/dev/null ||
        fail "the sharded farm's $density differs from the local run's"
done
for part in objects 0-of-2 1-of-2; do
    [[ -s $work/sharded/sim/shards/$part/stats.json ]] || fail "no shard $part"
done
for product in farm/contact.jpg farm/preview.mp4 wedge/wedges.jpg wedge/wedges.json \
               wedge/wedge-01/contact.jpg wedge/wedge-02/frame.0006.png; do
    [[ -s $work/$product ]] || fail "no $product"
done
[[ $(grep -c '"name": "wedge-' "$work/wedge/wedges.json") -eq 2 ]] || fail "wedges.json does not list 2 variants"
# Each variant is its own simulation: the first has the scene's own drag, the
# second not (its density differs voxel by voxel; 6 frames move too little to show).
"$vfield" compare "$work/wedge/wedge-01/frame.0006.png" "$work/local/frame.0006.png" >/dev/null ||
    fail "wedge-01 (the scene's own drag) differs from the local run"
"$vfield" compare "$work/wedge/wedge-01/sim/density.0006.vdb" "$work/local/sim/density.0006.vdb" >/dev/null ||
    fail "wedge-01's density differs from the local run's"
if "$vfield" compare "$work/wedge/wedge-02/sim/density.0006.vdb" "$work/local/sim/density.0006.vdb" >/dev/null; then
    fail "wedge-02 (drag 0.8) simulated the scene's own drag"
fi
echo "farm test: 6 frames equal a local run, whole and in 2 shards; a 2-variant wedge made its sheet" >&2
