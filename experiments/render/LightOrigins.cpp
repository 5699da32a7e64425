#include "experiments/render/LightOrigins.h"

#include "scenes/procedural/ProceduralScenes.h"

namespace experiments {

LightOrigins lightOrigins(const RenderOptions& options, const scenes::Scene& scene) {
    LightOrigins origins;
    origins.total = scene.lights.size();
    origins.generated = scene.generatedLightCount;
    origins.asked = requestedLights(options);
    origins.generatedBy = options.lights  ? "--lights"
                          : origins.asked ? "--lights default"
                                          : "lightGenerator";
    origins.ownLightsFrom =
        scenes::isProceduralScene(options.scene) ? "the built-in scene" : "the file";
    // Generated lights are point lights; the scene's own are the rest, whatever their order.
    int points = 0;
    for (const scenes::Light& light : scene.lights) {
        switch (light.type) {
        case scenes::LightType::Point:
            ++points;
            break;
        case scenes::LightType::Spot:
            ++origins.spot;
            break;
        case scenes::LightType::Directional:
            ++origins.directional;
            break;
        case scenes::LightType::Ambient:
            ++origins.ambient;
            break;
        }
    }
    origins.point = points - origins.generated;
    return origins;
}

std::string LightOrigins::summary() const {
    std::string text = std::to_string(total) + " =";
    std::string terms;
    auto add = [&](const std::string& term) { terms += (terms.empty() ? " " : " + ") + term; };
    const std::string by = generatedBy != "lightGenerator"
                               ? generatedBy + " " + std::to_string(asked.value_or(0))
                           : generated > 0 ? "the file's lightGenerator"
                                           : "the file has no lightGenerator";
    add(std::to_string(generated) + " generated (" + by + ")");
    std::string own;
    auto addOwn = [&](int count, const char* type) {
        if (count > 0)
            own += (own.empty() ? "" : " + ") + std::to_string(count) + " " + type;
    };
    addOwn(point, "point");
    addOwn(spot, "spot");
    addOwn(directional, "directional");
    addOwn(ambient, "ambient");
    if (!own.empty())
        add(own + " (" + ownLightsFrom + "'s own)");
    text += terms;
    if (asked && *asked > generated)
        text += "; " + std::to_string(*asked - generated) +
                " asked-for generated lights were not added (the file has lights of its own)";
    return text;
}

nlohmann::json LightOrigins::toJson() const {
    return {{"total", total},
            {"generated", generated},
            {"generated_asked", asked ? nlohmann::json(*asked) : nlohmann::json(nullptr)},
            {"generated_by", generatedBy},
            {"own",
             {{"point", point},
              {"spot", spot},
              {"directional", directional},
              {"ambient", ambient},
              {"from", ownLightsFrom}}},
            {"summary", summary()}};
}

} // namespace experiments
