// NormalStudyOutputs: how the normal-encoding study (NormalStudy.h) writes what it measured:
// normals.csv (one line per codec x bits x data set, through CsvTable), normals.json (the same
// rows plus the scenes, the negative-z fractions, the maps, the configuration and the timings),
// the error grids (raw float32) and the summary table `testbed normals` prints. The CSV columns
// and the JSON row keys are one list (rowFields), so the two files cannot drift apart.
#pragma once

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/studies/NormalStudy.h"

namespace experiments::normal_study {

// normals.csv: header, then one line per row (numbers with 9 significant digits).
std::string normalStudyCsv(const std::vector<NormalStudyRow>& rows);

// What the study ran with and how long each step took, for normals.json.
struct StudyRecord {
    nlohmann::json config;
    std::vector<nlohmann::json> maps;                  // one entry per error map written
    nlohmann::json timings = nlohmann::json::object(); // seconds per step
    std::uint64_t directions = 0;
};

// normals.json's object.
nlohmann::json normalStudyJson(const NormalStudyResult& result, const StudyRecord& record);

// Writes `values` as raw native float32 (the error grids), atomically.
void writeFloats(const std::filesystem::path& path, const std::vector<float>& values);

// The table `testbed normals` prints: per codec the sphere and visible-60 errors, bound, occupancy
// and throughput; per scene the negative-z figures; the negative-z fractions.
void printSummary(const NormalStudyResult& result, std::ostream& out);

} // namespace experiments::normal_study
