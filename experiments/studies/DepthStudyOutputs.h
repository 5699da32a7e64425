// DepthStudyOutputs: how the depth study (DepthStudy.h) writes what it measured: depth.csv and
// depth_steps.csv (through CsvTable, numbers with 9 significant digits, "nan" where a sample is
// lost), depth.json (rows, steps, per-series summary, options, commit, machine, time) and the
// summary table `testbed depth` prints.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "experiments/studies/DepthStudy.h"

namespace experiments {

std::string depthStudyCsv(const DepthStudyResult& result);
std::string depthStepsCsv(const DepthStudyResult& result);
nlohmann::json depthStudyJson(const DepthStudyResult& result);
// The summary table printed by `testbed depth`.
std::string depthSummaryTable(const DepthStudyResult& result);

} // namespace experiments
