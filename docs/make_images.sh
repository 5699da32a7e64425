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
# Anti-aliasing side by side (issue 28): glass with tiled at 1 sample, 4x MSAA and 1 sample +
# edge-blur, and the 16-spp reference they are measured against; top row the images, bottom row
# each one's HDR-FLIP map against the reference (the reference's own: black). A 160x100 crop
# around the fence posts and pane edges, enlarged 2x without filtering.
aa() { # NAME ARGS...
    name=$1
    shift
    echo "testbed render --scene glass --stage tiled $* --compare-reference --width 640 --height 360"
    "$testbed" render --scene glass --stage tiled "$@" --compare-reference --width 640 \
        --height 360 --threads 2 --out "$work/$name" >/dev/null
}
aa aa-1x
aa aa-4x --msaa 4
aa aa-edge-blur --post-aa edge-blur
crop="160x100+160+90"
tile() { # IN OUT LABEL
    oiiotool "$1" --cut "$crop" --resample 320x200 --text:x=6:y=22:size=18:color=1,1,1:font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf "$3" \
        -o "$2"
}
flipTile() { # FLIP_EXR_DIR OUT: the flip layer of render.exr, as a grey map (white = 1)
    oiiotool "$1/render.exr" --ch flip --chnames Y --ch Y,Y,Y --cut "$crop" --resample 320x200 \
        -o "$2"
}
tile "$work/aa-1x/preview.png" "$work/t1.png" "1 sample"
tile "$work/aa-4x/preview.png" "$work/t2.png" "4x MSAA"
tile "$work/aa-edge-blur/preview.png" "$work/t3.png" "1 sample + edge-blur"
tile "$work/aa-1x/reference.png" "$work/t4.png" "reference, 16 spp"
flipTile "$work/aa-1x" "$work/f1.png"
flipTile "$work/aa-4x" "$work/f2.png"
flipTile "$work/aa-edge-blur" "$work/f3.png"
oiiotool --create 320x200 3 -o "$work/f4.png"
oiiotool "$work/t1.png" "$work/t2.png" "$work/t3.png" "$work/t4.png" "$work/f1.png" \
    "$work/f2.png" "$work/f3.png" "$work/f4.png" --mosaic:pad=4 4x2 --ch R,G,B \
    -o "$images/glass-aa.png"
for name in aa-1x aa-4x aa-edge-blur; do
    python3 -c "import json,sys; e=json.load(open(sys.argv[1]))['error']; print(sys.argv[2], 'FLIP', e['flip'], 'relative RMSE', e['relative_rmse'])" \
        "$work/$name/stats.json" "$name"
done
# The edges: mean HDR-FLIP over a set of edge pixels, the same set for every mode. The sets are
# the complex pixels of a 4x frame (its render.exr layer msaa.complex, clamped to 0/1):
#   complex      `primitive` detection: every pixel whose samples show more than one triangle (the
#                silhouettes, and every shared edge of a tessellated mesh, where nothing aliases)
#   geometric    `discontinuity` detection: depth and normal breaks only (the fence's outline, the
#                box, the wall's foot), opaque surfaces only
#   fence+panes  geometric, plus the same detection on the scene with its panes drawn opaque
#                (--scene-option opaque_panes=1): the blended panes' silhouettes too
# The fence's cut-out stripes are alpha-tested per pixel, so no 4x set holds their edges (MSAA
# does not anti-alias them; alpha-to-coverage would).
aa aa-4x-discontinuity --msaa 4 --complex-detect discontinuity
aa aa-4x-opaque-panes --msaa 4 --complex-detect discontinuity --scene-option opaque_panes=1
oiiotool "$work/aa-4x/render.exr" --ch msaa.complex --clamp:min=0:max=1 -o "$work/complex.exr"
oiiotool "$work/aa-4x-discontinuity/render.exr" --ch msaa.complex --clamp:min=0:max=1 \
    -o "$work/geometric.exr"
oiiotool "$work/geometric.exr" "$work/aa-4x-opaque-panes/render.exr" --ch msaa.complex --add \
    --clamp:min=0:max=1 -o "$work/fence+panes.exr"
edgeFlip() { # MASK_EXR RUN_DIR: mean flip of RUN over the mask's pixels
    covered=$(oiiotool "$1" --printstats | awk '/Stats Avg/ {print $3}')
    masked=$(oiiotool "$2/render.exr" --ch flip "$1" --mul --printstats |
        awk '/Stats Avg/ {print $3}')
    python3 -c "import sys; print('%.5f' % (float(sys.argv[1]) / float(sys.argv[2])))" \
        "$masked" "$covered"
}
for edges in complex geometric fence+panes; do
    pixels=$(oiiotool "$work/$edges.exr" --printstats | awk '/Stats Avg/ {print int($3 * 640 * 360 + 0.5)}')
    for name in aa-1x aa-4x aa-edge-blur; do
        echo "$name HDR-FLIP over the $edges edges ($pixels pixels): $(edgeFlip "$work/$edges.exr" "$work/$name")"
    done
done

# Alpha-to-coverage (issue 28): foliage with tiled at 4x MSAA, alpha-tested and with
# alpha-to-coverage, and the 16-spp reference; HDR-FLIP maps below, a 160x100 crop of the leaves
# enlarged 2x.
a2c() { # NAME ARGS...
    name=$1
    shift
    echo "testbed render --scene foliage --stage tiled --msaa 4 $* --compare-reference --width 640 --height 360"
    "$testbed" render --scene foliage --stage tiled --msaa 4 "$@" --compare-reference --width 640 \
        --height 360 --threads 2 --out "$work/$name" >/dev/null
}
a2c a2c-off
a2c a2c-on --alpha-to-coverage on
crop="160x100+230+100"
tile "$work/a2c-off/preview.png" "$work/a1.png" "4x MSAA, alpha test"
tile "$work/a2c-on/preview.png" "$work/a2.png" "4x MSAA + alpha-to-coverage"
tile "$work/a2c-off/reference.png" "$work/a3.png" "reference, 16 spp"
flipTile "$work/a2c-off" "$work/b1.png"
flipTile "$work/a2c-on" "$work/b2.png"
oiiotool --create 320x200 3 -o "$work/b3.png"
oiiotool "$work/a1.png" "$work/a2.png" "$work/a3.png" "$work/b1.png" "$work/b2.png" \
    "$work/b3.png" --mosaic:pad=4 3x2 --ch R,G,B -o "$images/foliage-a2c.png"
for name in a2c-off a2c-on; do
    python3 -c "import json,sys; e=json.load(open(sys.argv[1]))['error']; print(sys.argv[2], 'FLIP', e['flip'], 'relative RMSE', e['relative_rmse'])" \
        "$work/$name/stats.json" "$name"
done

# Shadows (issue 29): atrium with tiled, 256 lights of which the 16 that matter most cast
# (cube maps of 1024^2, pcf3, default bias): without shadows, with shadow maps, the reference
# (the same 16 lights ray-traced) and shadow-error.png (red: lit but should be shadowed, blue:
# shadowed but should be lit, over the dimmed render).
shadows() { # NAME ARGS...
    name=$1
    shift
    echo "testbed render --scene atrium --stage tiled --lights 256 $* --width 640 --height 360"
    "$testbed" render --scene atrium --stage tiled --lights 256 "$@" --width 640 --height 360 \
        --threads 2 --out "$work/$name" >/dev/null
}
shadows shadows-off
shadows shadows-maps --shadows maps --shadow-lights 16 --shadow-map-size 1024 \
    --compare-reference --reference-spp 1
label() { # IN OUT LABEL
    oiiotool "$1" --text:x=8:y=26:size=22:color=1,1,1:font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf "$3" \
        -o "$2"
}
label "$work/shadows-off/preview.png" "$work/s1.png" "no shadows"
label "$work/shadows-maps/preview.png" "$work/s2.png" "shadow maps (16 lights)"
label "$work/shadows-maps/reference.png" "$work/s3.png" "reference: ray-traced"
label "$work/shadows-maps/shadow-error.png" "$work/s4.png" "shadow-error.png"
oiiotool "$work/s1.png" "$work/s2.png" "$work/s3.png" "$work/s4.png" --mosaic:pad=4 2x2 \
    --ch R,G,B -o "$images/atrium-shadows.png"
python3 -c "import json,sys; s=json.load(open(sys.argv[1])); m=s['shadows']; print('shadows', 'FLIP', s['error']['flip'], 'relative RMSE', s['error']['relative_rmse'], 'misclassified', m['misclassification'], 'maps ms', m['render_ms'], 'bytes', m['shadow_map_bytes'])" \
    "$work/shadows-maps/stats.json"

# Alpha-tested casters: foliage with tiled, 16 lights and the sun all casting (cube maps of
# 1024^2, pcf3): the leaf cards cast only where their texture's alpha passes, in the maps and in
# the ray-traced reference alike.
"$testbed" render --scene foliage --stage tiled --lights 16 --shadows maps --compare-reference \
    --width 640 --height 360 --threads 2 --out "$work/foliage-shadows" >/dev/null
label "$work/foliage-shadows/preview.png" "$work/c1.png" "shadow maps, cut-outs alpha-tested"
label "$work/foliage-shadows/reference.png" "$work/c2.png" "reference: ray-traced, 16 spp"
label "$work/foliage-shadows/shadow-error.png" "$work/c3.png" "shadow-error.png"
oiiotool "$work/c1.png" "$work/c2.png" "$work/c3.png" --mosaic:pad=4 3x1 --ch R,G,B \
    --resample 1284x240 -o "$images/foliage-shadows.png"

ls -l "$images"
