#!/usr/bin/env bash
# One command for everything on a fresh Debian 12 machine (as root):
#   ./run.sh main   install what is missing, build Release, render the default scene
#   ./run.sh test   install what is missing, build Release, run the whole test suite (ctest)
#   ./run.sh asan   the whole suite under AddressSanitizer + UndefinedBehaviorSanitizer
#                   (build-asan/, clang; CI runs it)
#   ./run.sh sanitize  the same, then the threaded suites under ThreadSanitizer
#                   (build-tsan/, against a oneTBB built with ThreadSanitizer from Debian's source
#                   package, because Debian's libtbb is not instrumented: see tests/tsan.supp)
#   ./run.sh fuzz [SECONDS]  every libFuzzer target for SECONDS each (default 600) in build-asan/
# Only missing Debian packages (and, for sanitize, Debian's oneTBB source package) are
# installed; nothing else is downloaded (ꟻLIP is the testbed's own, experiments/compare/Flip.h).
set -euo pipefail
cd "$(dirname "$0")"

mode=${1:-main}
case "$mode" in main|test|asan|sanitize|fuzz) ;; *) echo "usage: $0 main|test|asan|sanitize|fuzz [SECONDS]" >&2; exit 2 ;; esac

packages=(
    g++ cmake make git pkg-config clang-format
    libglm-dev libtbb-dev libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev
    libtinygltf-dev libcli11-dev nlohmann-json3-dev libgtest-dev libbenchmark-dev libhwy-dev
    libembree-dev # the reference's shadow rays (lighting/shadows/RayVisibility.h)
    fonts-dejavu-core
    libtomlplusplus-dev libstb-dev
    clang-14 libclang-rt-14-dev ccache
    python3-matplotlib chromium
    slurm-wlm munge parallel # the sweep recipes run for real (tests/experiments/cluster_*_test.sh)
)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "run.sh: installing ${missing[*]}" >&2
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

# ccache, when installed (run.sh installs it), keeps every build's objects keyed by their inputs,
# with paths below this folder made relative: a rebuild, another clone (CI's) or the fuzzers'
# subset of build-asan/ recompiles only what changed.
launcher=()
if command -v ccache > /dev/null; then
    export CCACHE_BASEDIR="$(pwd)" CCACHE_NOHASHDIR=1
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

# The sanitizer builds optimise at -O2 -g (asserts on): every memory access is still
# instrumented, and the suite runs in a fraction of -O1's time (at -O1 the whole ASan suite took
# more than two hours here; single rendering tests up to 494 s).
sanitizer_flags="-O2 -g"

# The ASan + UBSan build, shared by the sanitizer suite and the fuzzers (libFuzzer coverage
# instrumentation is compiled in; the test binaries do not link libFuzzer).
# Arguments, when given, are the only targets built (the fuzzers need only themselves and the
# testbed, which renders their EXR seeds).
build_asan() {
    CC=clang-14 CXX=clang++-14 cmake -S . -B build-asan "${launcher[@]}" \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$sanitizer_flags" \
        -DTESTBED_SANITIZER=address -DTESTBED_FUZZERS=ON
    local targets=()
    (($#)) && targets=(--target "$@")
    cmake --build build-asan -j"$(nproc)" "${targets[@]}"
}

# oneTBB 2021.8 (Debian's version) from Debian's source package, built with ThreadSanitizer into
# build-tsan/tbb-install: ThreadSanitizer cannot see the synchronisation inside an uninstrumented
# libtbb (its work stealing and waits), and reports every hand-over between TBB threads as a race.
build_tsan_tbb() {
    local root=build-tsan/tbb
    [ -f "$root/install/lib/cmake/TBB/TBBConfig.cmake" ] && return 0
    mkdir -p "$root/src"
    if ! ls "$root"/src/onetbb_*.orig.tar.* > /dev/null 2>&1; then
        if ! apt-cache showsrc onetbb > /dev/null 2>&1 || [ -z "$(apt-cache showsrc onetbb)" ]; then
            # Debian's own archive, as a source list: the same registry the packages come from.
            printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: bookworm bookworm-updates\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
                > /etc/apt/sources.list.d/testbed-debian-src.sources
            apt-get update
        fi
        (cd "$root/src" && apt-get source --download-only "onetbb=$(dpkg-query -W -f='${Version}' libtbb-dev)")
    fi
    rm -rf "$root/src/oneTBB-"*
    tar -C "$root/src" -xf "$root"/src/onetbb_*.orig.tar.*
    # tbbmalloc is left out: the testbed does not use it (and its races are real but its own).
    CC=clang-14 CXX=clang++-14 cmake -S "$root"/src/oneTBB-* -B "$root/build" \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTBB_SANITIZE=thread -DTBB_TEST=OFF \
        -DTBBMALLOC_BUILD=OFF -DTBB_STRICT=OFF -DCMAKE_INSTALL_PREFIX="$(pwd)/$root/install"
    cmake --build "$root/build" -j"$(nproc)"
    cmake --install "$root/build"
}

if [ "$mode" = asan ] || [ "$mode" = sanitize ]; then
    start=$(date +%s)
    build_asan
    # The whole suite except the fuzzers' own runs (./run.sh fuzz) and the source-only style
    # checks (the Release suite runs them); any ASan or UBSan report aborts its test. The
    # exhaustive raster sweeps run a sample of their states here (tests/raster/SanitizerBuild.h).
    (cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
        UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j"$(nproc)" -LE 'fuzz|style')
    asan_done=$(date +%s)
    if [ "$mode" = asan ]; then
        echo "run.sh: ASan+UBSan suite passed in $((asan_done - start)) s"
        exit 0
    fi
    build_tsan_tbb
    CC=clang-14 CXX=clang++-14 cmake -S . -B build-tsan "${launcher[@]}" \
        -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$sanitizer_flags" \
        -DTESTBED_SANITIZER=thread \
        -DTBB_DIR="$(pwd)/build-tsan/tbb/install/lib/cmake/TBB"
    cmake --build build-tsan -j"$(nproc)" \
        --target raster_tests gbuffer_tests lighting_tests experiments_tests testbed
    # The threaded parts: the rasterizer, the G-buffer pass, the stages, renders and the sweep
    # runner (which also runs testbed processes).
    export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$(pwd)/tests/tsan.supp"
    (cd build-tsan && ctest --output-on-failure -j"$(nproc)" -L '^(raster|lighting)$' &&
        ctest --output-on-failure -j"$(nproc)" \
            -R '^(GBufferPass|SweepRunner|SweepKill|RenderJob|RenderCommand)\.')
    end=$(date +%s)
    echo "run.sh: sanitize passed: ASan+UBSan $((asan_done - start)) s, TSan $((end - asan_done)) s"
    exit 0
fi

if [ "$mode" = fuzz ]; then
    build_asan testbed gltf_fuzzer json_scene_fuzzer sweep_fuzzer exr_fuzzer
    exec tests/fuzz/run_fuzzers.sh build-asan "${2:-600}"
fi

cmake -S . -B build "${launcher[@]}" -DCMAKE_BUILD_TYPE=Release

if [ "$mode" = test ]; then
    # Every target: the tests, the benchmarks and the testbed the end-to-end tests run.
    cmake --build build -j"$(nproc)"
    cd build
    exec ctest --output-on-failure -j"$(nproc)"
fi

# The main job needs only the testbed: the tests and benchmarks are built by ./run.sh test (in
# the same build/, so either command may run first).
cmake --build build -j"$(nproc)" --target testbed

out=out/default
build/bin/testbed render --compare-reference --out "$out"
echo "run.sh: outputs of the default job are in $(pwd)/$out"
