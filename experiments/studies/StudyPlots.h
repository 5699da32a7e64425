// StudyPlots: how the studies (`testbed normals`, `testbed depth`) draw their plots: the
// matplotlib script of experiments/plots/ (or --plots-script; PlotScript.h requirePlotScript
// finds it before any work), run by the Python that PlotScript.h finds, after the study's CSV and
// JSON files are written. A missing matplotlib or a failing script is an error that says which
// data files are already there.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace experiments {

// Runs `python script arguments...` with the Python of `requestedPython` (PlotScript.h). Throws
// std::runtime_error naming what to install, or the command and its exit status, followed by
// `written` (what the study has written so far, e.g. "depth.csv and depth.json are in DIR").
void runStudyPlots(const std::string& requestedPython, const std::filesystem::path& script,
                   const std::vector<std::string>& arguments, const std::string& written);

} // namespace experiments
