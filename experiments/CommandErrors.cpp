// CommandErrors.h: the two printers. The whole message is escaped here, once, because its parts
// come from everywhere (file names, field values, library messages quoting the input).
#include "experiments/CommandErrors.h"

#include <iostream>

#include "scenes/input/MessageText.h"

namespace experiments {

int reportError(const std::string& message, int exitCode) {
    std::cerr << "testbed: error: " << scenes::escapeControlCharacters(message) << "\n";
    return exitCode;
}

int reportError(const std::exception& error, int exitCode) {
    return reportError(std::string(error.what()), exitCode);
}

void reportWarning(const std::string& message, std::ostream& out) {
    out << "testbed: warning: " << scenes::escapeControlCharacters(message) << "\n";
}

} // namespace experiments
