// The source commit every output records (stats.json, EXR header, study JSON), stamped at BUILD
// time by experiments/BuildCommit.cmake: `git rev-parse --short HEAD`, with "-dirty" when tracked
// files had uncommitted changes, or "unknown" outside a git checkout. Stamping at configure time
// would keep reporting the commit the build folder was configured at.
#pragma once

namespace experiments {
extern const char* const kBuildCommit;
} // namespace experiments
