#include "experiments/CommandErrors.h"

#include <iostream>

namespace experiments {

int reportError(const std::string& message, int exitCode) {
    std::cerr << "testbed: error: " << message << "\n";
    return exitCode;
}

int reportError(const std::exception& error, int exitCode) {
    return reportError(std::string(error.what()), exitCode);
}

} // namespace experiments
