#!/bin/sh
# Regenerates the renders of the top README (docs/images/*.png) from a build of the testbed.
# Usage (from the source tree, after building): docs/make_images.sh [BUILD_DIR] [SHARED_DIR]
#   BUILD_DIR  default build (the testbed is BUILD_DIR/bin/testbed)
#   SHARED_DIR default ../shared (the glTF models: ../shared/scenes/gltf)
# Each image is one `testbed render` at 640x360 on 2 threads; the PNGs are the testbed's own
# outputs (preview.png: ACES tone map, sRGB; heatmap.png and error.png: Turbo false colour with
# a legend), copied under the names below. The EXRs and stats.json stay in a temporary folder.
set -eu
build=${1:-build}
shared=${2:-../shared}
testbed="$build/bin/testbed"
here=$(dirname "$0")
images="$here/images"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$images"

render() { # NAME PNG ARGS...: one render, its PNG copied to images/NAME.png
    name=$1
    png=$2
    shift 2
    echo "testbed render $* --width 640 --height 360 --threads 2"
    "$testbed" render "$@" --width 640 --height 360 --threads 2 --out "$work/$name" >/dev/null
    cp "$work/$name/$png" "$images/$name.png"
}

gltf="$shared/scenes/gltf"
render helmet preview.png --scene "$gltf/DamagedHelmet/DamagedHelmet.gltf" --lights 64
render boombox preview.png --scene "$gltf/BoomBox/BoomBox.gltf" --lights 64
render glass preview.png --scene glass
render atrium-tiled-heatmap heatmap.png --scene atrium --stage tiled --lights 1000
render atrium-inferred-error error.png --scene atrium --stage inferred --lights 256 \
    --compare-reference --error-scale log
ls -l "$images"
