#include "experiments/output/PlotScript.h"

#include <cerrno>
#include <cstdio>
#include <stdexcept>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef TESTBED_SOURCE_DIR
#define TESTBED_SOURCE_DIR "."
#endif

namespace experiments {

namespace {

std::vector<std::string> pythonCandidates(const std::string& requested) {
    if (!requested.empty())
        return {requested};
    return {"/usr/bin/python3", "python3"};
}

} // namespace

std::filesystem::path sourceDirectory() {
    return TESTBED_SOURCE_DIR;
}

std::filesystem::path plotScriptPath(const std::string& fileName) {
    return std::filesystem::path(TESTBED_SOURCE_DIR) / "experiments" / "plots" / fileName;
}

std::filesystem::path requirePlotScript(const std::filesystem::path& requested,
                                        const std::string& fileName) {
    const std::filesystem::path script = requested.empty() ? plotScriptPath(fileName) : requested;
    if (!std::filesystem::is_regular_file(script))
        throw std::invalid_argument("plot script " + script.string() +
                                    " not found (--plots-script PATH)");
    return script;
}

namespace {

// Runs argv with stdout and stderr sent to `output` when it is not null (a file path).
int runChild(const std::vector<std::string>& argv, const char* output) {
    if (argv.empty())
        return 127;
    std::fflush(nullptr); // nothing buffered may be written twice by the child
    const pid_t child = fork();
    if (child < 0)
        return 127;
    if (child == 0) {
        if (output) {
            const int file = open(output, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
            if (file >= 0) {
                dup2(file, STDOUT_FILENO);
                dup2(file, STDERR_FILENO);
            }
        }
        std::vector<char*> args;
        for (const std::string& arg : argv)
            args.push_back(const_cast<char*>(arg.c_str()));
        args.push_back(nullptr);
        execvp(args[0], args.data());
        _exit(127);
    }
    int status = 0;
    while (waitpid(child, &status, 0) < 0)
        if (errno != EINTR)
            return 127;
    if (WIFEXITED(status))
        return WEXITSTATUS(status);
    if (WIFSIGNALED(status))
        return 128 + WTERMSIG(status);
    return 127;
}

} // namespace

int runProcess(const std::vector<std::string>& argv, bool quiet) {
    return runChild(argv, quiet ? "/dev/null" : nullptr);
}

int runProcessLogged(const std::vector<std::string>& argv, const std::filesystem::path& log) {
    return runChild(argv, log.c_str());
}

std::string findPythonWithMatplotlib(const std::string& requested) {
    for (const std::string& python : pythonCandidates(requested))
        if (runProcess({python, "-c", "import matplotlib, numpy"}, true) == 0)
            return python;
    return "";
}

std::string requirePythonWithMatplotlib(const std::string& requested) {
    const std::string python = findPythonWithMatplotlib(requested);
    if (!python.empty())
        return python;
    std::string tried;
    for (const std::string& candidate : pythonCandidates(requested))
        tried += (tried.empty() ? "" : ", ") + candidate;
    throw std::runtime_error("no Python 3 with matplotlib found (tried " + tried +
                             "); install Debian's python3-matplotlib, or pass --python PATH");
}

} // namespace experiments
