#!/usr/bin/env bash
# Runs libFuzzer targets of a build made with -DTESTBED_FUZZERS=ON (README "Sanitizers and
# fuzzers"):
#   run_fuzzers.sh BUILD_DIR SECONDS [NAME...]     NAME: gltf json_scene sweep exr (default: all)
# Each fuzzer runs SECONDS of wall time on one core, starting from a seed corpus assembled here
# from the repository's own inputs (tests/fuzz/corpus, experiments/sweeps, the glTF models of
# ../shared when present, EXRs rendered by the testbed itself) plus what earlier runs found
# (BUILD_DIR/fuzz-corpus/NAME keeps growing), with a dictionary of the format's keys. A crash,
# a sanitizer report, a leak, a timeout (30 s for one input) or one allocation over 2 GiB or a resident size over 8 GiB
# fails the run; the input is kept in BUILD_DIR/fuzz-artifacts/NAME/ and the log in
# BUILD_DIR/fuzz-logs/NAME.log. Exit status: 0 when every fuzzer ran clean.
set -euo pipefail

build=$(cd "$1" && pwd)
seconds=$2
shift 2
names=("$@")
((${#names[@]})) || names=(gltf json_scene sweep exr)
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
shared=${TESTBED_SHARED_DIR:-$source_dir/../shared}

seed_corpus() {
    local name=$1 corpus=$2
    case "$name" in
    gltf)
        if [ -d "$shared/scenes/gltf" ]; then
            # Small models only: a seed is mutated byte by byte, and big files are slow to load.
            find "$shared/scenes/gltf" \( -name '*.gltf' -o -name '*.glb' \) -size -2M \
                -exec cp -t "$corpus" {} + 2>/dev/null || true
        fi
        printf '{"asset":{"version":"2.0"}}' > "$corpus/minimal.gltf"
        # Issue 32, classes 1 and 2: values past float's range, overflowing node chains,
        # flattened camera transforms (tests/scenes/input/hostile-values).
        cp "$source_dir"/tests/scenes/input/hostile-values/*.gltf "$corpus/"
        ;;
    json_scene)
        cp "$here"/corpus/json_scene/*.json "$corpus/"
        cp "$source_dir"/tests/scenes/input/hostile-values/*.json "$corpus/"
        ;;
    sweep)
        # The first byte selects the format (odd: TOML, see sweep_fuzzer.cpp).
        for file in "$source_dir"/experiments/sweeps/*.json; do
            { printf '\x00'; cat "$file"; } > "$corpus/$(basename "$file")"
        done
        cp "$here"/corpus/sweep/* "$corpus/"
        ;;
    exr)
        # Renders of the testbed itself: the files `testbed diff` is made for.
        local out
        out=$(mktemp -d)
        for stage in brute tiled; do
            "$build/bin/testbed" render --scene spheres --stage "$stage" --lights 4 --width 16 \
                --height 8 --threads 1 --compare-reference --out "$out/$stage" > /dev/null
            cp "$out/$stage/render.exr" "$corpus/$stage.exr"
        done
        rm -rf "$out"
        ;;
    esac
}

status=0
for name in "${names[@]}"; do
    fuzzer="$build/fuzz/${name}_fuzzer"
    [ -x "$fuzzer" ] || { echo "run_fuzzers.sh: $fuzzer is not built" >&2; exit 2; }
    corpus="$build/fuzz-corpus/$name"
    artifacts="$build/fuzz-artifacts/$name"
    log="$build/fuzz-logs/$name.log"
    mkdir -p "$corpus" "$artifacts" "$(dirname "$log")"
    seed_corpus "$name" "$corpus"
    echo "run_fuzzers.sh: $name for ${seconds} s (corpus $corpus, log $log)"
    if ! ASAN_OPTIONS=detect_leaks=1 \
        "$fuzzer" "$corpus" -dict="$here/$name.dict" -max_total_time="$seconds" \
        -timeout=30 -rss_limit_mb=8192 -malloc_limit_mb=2048 -max_len=65536 \
        -artifact_prefix="$artifacts/" -print_final_stats=1 > "$log" 2>&1; then
        echo "run_fuzzers.sh: $name FAILED; the sanitizer's report and the last lines of $log:" >&2
        # The report's head (what, where, the stack) is what tells the bug; the log's tail is
        # shadow bytes and statistics. CI keeps only this output, not the build folder, so the
        # failing input is printed too (base64, when small) to reproduce it from the CI log:
        #   base64 -d > crash && build-asan/fuzz/NAME_fuzzer crash
        grep -m1 -A45 -E '^==[0-9]+==ERROR|^SUMMARY|runtime error' "$log" >&2 || true
        tail -n 12 "$log" >&2
        for input in "$artifacts"/*; do
            [ -f "$input" ] || continue
            if [ "$(stat -c %s "$input")" -le 32768 ]; then
                echo "run_fuzzers.sh: failing input $(basename "$input"), base64:" >&2
                base64 -w 0 "$input" >&2
                echo >&2
            fi
        done
        status=1
    fi
    grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb|^#[0-9]+.*DONE' "$log" || true
done
exit $status
