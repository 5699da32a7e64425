#!/usr/bin/env bash
# Fails when a C++ file of the repository differs from what the root .clang-format makes of it.
# Run by ctest (tests/CMakeLists.txt), so CI (./run.sh test) fails on unformatted files.
# Usage: format_check.sh SOURCE_DIR. Fix with: git ls-files '*.cpp' '*.h' | xargs clang-format -i
set -euo pipefail
cd "$1"
command -v clang-format >/dev/null || { echo "format_check: clang-format is not installed (run.sh installs it)" >&2; exit 1; }
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    mapfile -t files < <(git ls-files '*.cpp' '*.h')
else
    mapfile -t files < <(find raster gbuffer lighting scenes experiments tests -name '*.cpp' -o -name '*.h')
fi
bad=()
for f in "${files[@]}"; do
    [ -f "$f" ] || continue
    clang-format --style=file "$f" | cmp -s - "$f" || bad+=("$f")
done
if ((${#bad[@]})); then
    echo "format_check: ${#bad[@]} file(s) differ from .clang-format ($(clang-format --version)):" >&2
    printf '  %s\n' "${bad[@]}" >&2
    echo "fix: git ls-files '*.cpp' '*.h' | xargs clang-format -i" >&2
    exit 1
fi
echo "format_check: ${#files[@]} files formatted"
