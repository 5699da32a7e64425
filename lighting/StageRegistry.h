// StageRegistry: shading stages by name. A spec is NAME or NAME:key=value,key=value; a stage
// rejects option keys it does not know. Unknown names are errors that list the valid ones.
#pragma once

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "lighting/ShadingStage.h"

namespace lighting {

struct StageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct StageSpec {
    std::string name;
    std::map<std::string, std::string> options;
    static StageSpec parse(const std::string& spec); // throws StageError on malformed text
};

// What a stage promises about its image, which decides how tests check it:
//   Reference  the double-precision truth
//   Exact      the same image as `brute` up to float summation order, and at every pixel at
//              least as many lights evaluated as contribute (culling never drops a light)
//   Approximate an approximation by design (e.g. lower-resolution lighting); its error against
//              the reference is measured and bounded, not required to vanish
enum class StageKind { Reference, Exact, Approximate };

struct StageInfo {
    std::string name;
    std::string description;
    StageKind kind = StageKind::Exact;
    // Exact stages: every pixel sums its lights in ascending light index, starting from zero, so
    // the image is BITWISE `brute`'s (skipped lights add exactly +0) and the tests compare it so.
    // A stage that reorders the sum (e.g. per-light partial sums merged later) sets false and is
    // compared within 1e-5 of the image's peak instead.
    bool ascendingLightOrder = true;
};

std::vector<StageInfo> stageInfos();
// Throws StageError for an unknown name or option.
std::unique_ptr<ShadingStage> makeStage(const std::string& spec);

} // namespace lighting
