// ShadingStage: the interface every lighting pipeline implements (one stage per file under
// lighting/stages/, registered by name in StageRegistry.cpp).
//
// Declare, then run: requirements() says what the stage reads (G-buffer channels, the exact
// surface); it is cheap and may be called any number of times. shade() runs the stage on one
// frame and fills a StageResult. Stages are parallel inside (TBB, under the caller's task_arena)
// and must be deterministic: the same frame gives bitwise the same result for any thread count.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gbuffer/CameraView.h"
#include "gbuffer/ExactSurface.h"
#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferLayout.h"
#include "gbuffer/SceneGeometry.h"
#include "lighting/LightList.h"
#include "scenes/Scene.h"

namespace lighting {

struct StageRequirements {
    std::vector<gbuffer::Channel> channels; // G-buffer channels the stage reads
    bool exactSurface = false;              // reads gbuffer::ExactSurface (the reference)
};

// The inputs of a stage for one frame: everything it may read. Pointers are null when not
// required.
struct StageInputs {
    const scenes::Scene* scene = nullptr;
    const gbuffer::SceneGeometry* geometry = nullptr;
    const gbuffer::CameraView* view = nullptr;
    const gbuffer::GBuffer* gbuffer = nullptr;
    const gbuffer::ExactSurface* exact = nullptr;
    const LightList* lights = nullptr;
};

struct StageResult {
    int width = 0;
    int height = 0;
    std::vector<float> radiance[3];        // linear HDR R, G, B
    std::vector<uint32_t> lightsEvaluated; // per pixel: lights the stage evaluated
    std::vector<uint32_t> lightsOracle;    // per pixel: lights that contribute; empty when the
                                           // stage cannot know (the runner then computes it)
    std::vector<std::pair<std::string, double>> timingsMs; // per pass, in execution order
    std::map<std::string, std::string> parameters;         // the stage's effective options

    void resize(int w, int h, bool withOracle);
};

// Milliseconds since `start` on the steady clock: how stages time their passes.
inline double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

class ShadingStage {
public:
    virtual ~ShadingStage() = default;
    virtual std::string name() const = 0;
    virtual StageRequirements requirements() const = 0;
    virtual void shade(const StageInputs& inputs, StageResult& result) = 0;
};

} // namespace lighting
