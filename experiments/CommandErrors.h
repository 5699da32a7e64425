// CommandErrors: how every `testbed` command reports a failure: one line
// "testbed: error: <message>" on stderr and a non-zero exit code (STYLE.md: one clear message,
// never a crash or a half-written output). The exceptions of the layers below (UsageError,
// lighting::StageError, scenes::SceneError, SweepError, std::runtime_error from the outputs) all
// carry their full message in what(), so one conversion serves them all.
//
// Messages quote input files (field values, light types, keys, paths), so both printers escape
// control characters and invalid UTF-8 in the whole message (scenes/input/MessageText.h): a file
// cannot print a second "testbed: error:" line or send escape sequences to the terminal.
#pragma once

#include <exception>
#include <iostream>
#include <string>

namespace experiments {

// Prints "testbed: error: <message>" to stderr; returns exitCode (for `return reportError(...)`).
int reportError(const std::string& message, int exitCode = 1);
int reportError(const std::exception& error, int exitCode = 1);

// Prints "testbed: warning: <message>" (escaped the same way) to out, stderr by default.
void reportWarning(const std::string& message, std::ostream& out = std::cerr);

} // namespace experiments
