// CommandErrors: how every `testbed` command reports a failure: one line
// "testbed: error: <message>" on stderr and a non-zero exit code (STYLE.md: one clear message,
// never a crash or a half-written output). The exceptions of the layers below (UsageError,
// lighting::StageError, scenes::SceneError, SweepError, std::runtime_error from the outputs) all
// carry their full message in what(), so one conversion serves them all.
#pragma once

#include <exception>
#include <string>

namespace experiments {

// Prints "testbed: error: <message>" to stderr; returns exitCode (for `return reportError(...)`).
int reportError(const std::string& message, int exitCode = 1);
int reportError(const std::exception& error, int exitCode = 1);

} // namespace experiments
