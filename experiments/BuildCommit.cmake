# Run at every build (cmake -P): writes OUT, a C++ source defining experiments::kBuildCommit (see
# BuildCommit.h), from the git state of SOURCE_DIR. The file is rewritten only when its content
# changes, so an unchanged checkout rebuilds nothing.
execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse --short HEAD
    OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT commit)
    set(commit "unknown")
else()
    execute_process(COMMAND git -C "${SOURCE_DIR}" status --porcelain --untracked-files=no
        OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(changes)
        string(APPEND commit "-dirty")
    endif()
endif()
set(content "// Generated at build time by experiments/BuildCommit.cmake; do not edit.
#include \"experiments/BuildCommit.h\"

namespace experiments {
const char* const kBuildCommit = \"${commit}\";
}  // namespace experiments
")
set(previous "")
if(EXISTS "${OUT}")
    file(READ "${OUT}" previous)
endif()
if(NOT previous STREQUAL content)
    file(WRITE "${OUT}" "${content}")
endif()
