// Test helper: runs the built testbed binary with arguments through the shell and returns its
// exit code and its combined stdout and stderr, for the CLI-level tests of tests/experiments/.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>

namespace clitest {

inline const std::filesystem::path kTestbed =
    std::filesystem::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

struct CliRun {
    int exitCode = -1;
    std::string output; // stdout and stderr
};

// `testbed ARGUMENTS 2>&1`; exitCode -1 when the process did not exit normally.
inline CliRun run(const std::string& arguments) {
    CliRun result;
    const std::string command = kTestbed.string() + " " + arguments + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe)
        return result;
    std::array<char, 4096> buffer{};
    for (size_t n; (n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0;)
        result.output.append(buffer.data(), n);
    const int status = pclose(pipe);
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

} // namespace clitest
