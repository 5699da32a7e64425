// Shared set-up for the benchmarks: every benchmark renders its frame through
// lighting::PreparedScene at 1280x720 with seed 1, so their figures compare like for like.
#pragma once

#include <map>
#include <string>

#include "lighting/PreparedScene.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace bench {

inline constexpr int kWidth = 1280;
inline constexpr int kHeight = 720;

inline scenes::Scene proceduralScene(const std::string& name, int lightCount,
                                     std::map<std::string, std::string> options = {}) {
    scenes::SceneRequest request;
    request.lightCount = lightCount;
    request.seed = 1;
    request.options = std::move(options);
    return scenes::buildProceduralScene(name, request);
}

// A benchmark frame: the prepared frame of a built-in scene at 1280x720.
struct BenchScene : lighting::PreparedScene {
    BenchScene(const std::string& name, int lightCount,
               std::map<std::string, std::string> options = {})
        : lighting::PreparedScene(proceduralScene(name, lightCount, std::move(options)), kWidth,
                                  kHeight) {}
};

} // namespace bench
