// Starting build/bin/testbed as a child process, for the tests that signal or lock against a
// running sweep (sweep_kill_test, sweep_isolation_test).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/types.h>
#include <unistd.h>

namespace experimentstest {

inline const std::filesystem::path kTestbedBinary =
    std::filesystem::path(TESTBED_BINARY_DIR) / "bin" / "testbed";

enum class LogMode { Truncate, Append };

// Starts testbed with args, stdout and stderr to `log`; returns the child's pid.
inline pid_t spawnTestbed(const std::vector<std::string>& args, const std::filesystem::path& log,
                          LogMode mode) {
    const pid_t pid = fork();
    if (pid == 0) {
        const int flags = O_WRONLY | O_CREAT | (mode == LogMode::Append ? O_APPEND : O_TRUNC);
        const int fd = open(log.c_str(), flags, 0644);
        if (fd >= 0) {
            dup2(fd, STDOUT_FILENO);
            dup2(fd, STDERR_FILENO);
        }
        std::vector<char*> argv = {const_cast<char*>(kTestbedBinary.c_str())};
        for (const std::string& arg : args)
            argv.push_back(const_cast<char*>(arg.c_str()));
        argv.push_back(nullptr);
        execv(kTestbedBinary.c_str(), argv.data());
        _exit(127);
    }
    return pid;
}

} // namespace experimentstest
