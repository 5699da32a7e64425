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
    static StageSpec parse(const std::string& spec);  // throws StageError on malformed text
};

struct StageInfo {
    std::string name;
    std::string description;
};

std::vector<StageInfo> stageInfos();
// Throws StageError for an unknown name or option.
std::unique_ptr<ShadingStage> makeStage(const std::string& spec);

}  // namespace lighting
