#include "experiments/studies/StudyPlots.h"

#include <stdexcept>

#include "experiments/output/PlotScript.h"

namespace experiments {

void runStudyPlots(const std::string& requestedPython, const std::filesystem::path& script,
                   const std::vector<std::string>& arguments, const std::string& written) {
    std::string python;
    try {
        python = requirePythonWithMatplotlib(requestedPython);
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(std::string("plots: ") + e.what() + "; " + written);
    }
    std::vector<std::string> command = {python, script.string()};
    command.insert(command.end(), arguments.begin(), arguments.end());
    const int status = runProcess(command);
    if (status != 0) {
        std::string text;
        for (const std::string& part : command)
            text += (text.empty() ? "" : " ") + part;
        throw std::runtime_error("plots: " + text + " failed with exit status " +
                                 std::to_string(status) + "; " + written);
    }
}

} // namespace experiments
