#!/usr/bin/env bash
# One command for everything on a fresh Debian 12 machine (as root):
#   ./run.sh main   install what is missing, build Release, render the default scene
#   ./run.sh test   install what is missing, build Release, run the whole test suite (ctest)
# Only missing Debian packages are installed. The one download from elsewhere is NVIDIA's ꟻLIP
# (the Python package flip-evaluator, from the Python package index) into the project-local
# virtual environment .venv/; when the index cannot be reached, ꟻLIP is reported unavailable in
# every output (experiments/FlipMetric.h) and nothing else changes.
set -euo pipefail
cd "$(dirname "$0")"

mode=${1:-main}
case "$mode" in main|test) ;; *) echo "usage: $0 main|test" >&2; exit 2 ;; esac

packages=(
    g++ cmake make git pkg-config clang-format
    libglm-dev libtbb-dev libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev
    libtinygltf-dev libcli11-dev nlohmann-json3-dev libgtest-dev libbenchmark-dev libhwy-dev
    fonts-dejavu-core
    libtomlplusplus-dev
    python3-matplotlib chromium
    python3-venv python3-pip
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

# ꟻLIP: a venv that sees Debian's numpy; a failed install (offline machine) is not an error.
flip_version=1.6.0.1 # experiments/FlipMetric.h kFlipEvaluatorVersion
if ! .venv/bin/python3 -c "import flip_evaluator" 2>/dev/null; then
    python3 -m venv --system-site-packages .venv
    .venv/bin/python3 -m pip install --quiet --timeout 20 --retries 1 \
        "flip-evaluator==$flip_version" \
        || echo "run.sh: cannot install flip-evaluator==$flip_version (no access to the Python" \
                "package index?): FLIP will be reported unavailable" >&2
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"

if [ "$mode" = test ]; then
    cd build
    exec ctest --output-on-failure -j"$(nproc)"
fi

out=out/default
build/bin/testbed render --compare-reference --out "$out"
echo "run.sh: outputs of the default job are in $(pwd)/$out"
