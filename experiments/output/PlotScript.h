// PlotScript: how the C++ commands run the matplotlib scripts of experiments/plots/ (report,
// diff, normals, depth): which Python, where the scripts are, and starting a process without a
// shell (arguments are passed as they are, never re-parsed, so paths with spaces or quotes work).
//
// Python: Debian's /usr/bin/python3 first (where python3-matplotlib installs), then python3 on
// PATH (which may be a pyenv or venv without matplotlib). Thread-safe; each call forks.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace experiments {

// The source tree this binary was built from (fixed at build time).
std::filesystem::path sourceDirectory();
// experiments/plots/<fileName> of the source tree this binary was built from.
std::filesystem::path plotScriptPath(const std::string& fileName);
// The script a command runs: `requested` (--plots-script) when not empty, else
// plotScriptPath(fileName). Throws std::invalid_argument("plot script <path> not found
// (--plots-script PATH)") when it is no file, so that commands check it before any work.
std::filesystem::path requirePlotScript(const std::filesystem::path& requested,
                                        const std::string& fileName);

// Runs argv[0] (searched on PATH) with the arguments, waits, and returns its exit status (127
// when it cannot be started, 128 + signal when killed). Its stdout and stderr are this process'.
// With quiet, both go to /dev/null.
int runProcess(const std::vector<std::string>& argv, bool quiet = false);
// The same with the child's stdout and stderr written to the file `log` (created or truncated).
int runProcessLogged(const std::vector<std::string>& argv, const std::filesystem::path& log);

// `requested` if it imports matplotlib (when given, nothing else is tried), else the first of
// /usr/bin/python3 and python3 that does; "" when none does.
std::string findPythonWithMatplotlib(const std::string& requested);
// The same, but throws std::runtime_error naming what was tried and what to install.
std::string requirePythonWithMatplotlib(const std::string& requested);

} // namespace experiments
