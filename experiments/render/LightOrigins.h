// LightOrigins: where the lights of a render came from, for the printed summary and stats.json
// (`light_origins`): how many a light generator placed and what set their number (--lights, its
// default, or a JSON scene's lightGenerator), and the scene's own lights by type (a built-in
// scene's ambient and sun, a file's explicit or KHR_lights_punctual lights). Issue 16: a JSON
// scene's lightGenerator.count is not silently replaced by the --lights default, and the output
// says which number was used.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "experiments/render/RenderOptions.h"
#include "scenes/Scene.h"

namespace experiments {

struct LightOrigins {
    size_t total = 0;
    int generated = 0;        // placed by a generator (Scene::generatedLightCount)
    std::optional<int> asked; // generated lights asked for (requestedLights); unset: the file's
    std::string generatedBy;  // "--lights", "--lights default" or "lightGenerator" (the file's)
    int point = 0, spot = 0, directional = 0, ambient = 0; // the scene's own lights, by type
    std::string ownLightsFrom;                             // "the built-in scene" or "the file"

    // E.g. "258 = 256 generated (--lights default) + 1 ambient + 1 directional (the built-in
    // scene's)", or "12 = 8 generated (the file's lightGenerator) + 3 point + 1 directional (the
    // file's)"; says when asked-for lights were not added (a glTF file with its own lights).
    std::string summary() const;
    nlohmann::json toJson() const;
};

LightOrigins lightOrigins(const RenderOptions& options, const scenes::Scene& scene);

} // namespace experiments
