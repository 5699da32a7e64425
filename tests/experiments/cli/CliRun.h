// Test helper: runs the built testbed binary with arguments through the shell and returns its
// exit code and its combined stdout and stderr (or both apart: runSeparately), for the CLI-level
// tests of tests/experiments/.
#pragma once

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
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

// A run with stdout and stderr apart, for tests that check which stream a line goes to.
struct SeparateRun {
    int exitCode = -1; // 128 + signal when killed
    std::string stdoutText;
    std::string stderrText;
};

// `testbed ARGUMENTS` with no stdin, killed after timeoutSeconds (a hang detector, not a timing);
// its streams go through files in `dir`.
inline SeparateRun runSeparately(const std::string& arguments, const std::filesystem::path& dir,
                                 int timeoutSeconds = 20) {
    const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string command = "timeout -s KILL " + std::to_string(timeoutSeconds) + " " +
                                kTestbed.string() + " " + arguments + " > '" + out.string() +
                                "' 2> '" + err.string() + "' < /dev/null";
    const int status = std::system(command.c_str());
    auto read = [](const std::filesystem::path& path) {
        std::ifstream file(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(file), {});
    };
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), read(out), read(err)};
}

// Lines in `text` (newline characters).
inline int lineCount(const std::string& text) {
    int count = 0;
    for (char c : text)
        count += c == '\n';
    return count;
}

} // namespace clitest
