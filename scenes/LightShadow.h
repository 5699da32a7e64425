// LightShadow: what a scene may say about one light's shadow maps (a JSON scene's per-light
// "shadow" object, scenes/json), each setting overriding for that light alone the global one the
// renderer was given (lighting::ShadowSettings, the CLI's --shadow-map-size, --shadow-bias,
// --shadow-filter). Here rather than in lighting/shadows because the scene loaders fill it and
// scenes/ includes nothing of lighting/; lighting/shadows/ShadowSettings.h takes ShadowFilter
// from here under its own name. Units as ShadowSettings.h: metres for the constant bias, texels
// for the slope bias and the normal offset. Plain data.
#pragma once

#include <optional>
#include <string_view>

namespace scenes {

// Percentage-closer filtering: None = the nearest texel; Pcf3 / Pcf5 = box of 3x3 / 5x5 texels
// around it; Poisson = 16 taps of a fixed Poisson disk of radius 2.5 texels (no per-pixel
// rotation: the result depends on nothing but the inputs).
enum class ShadowFilter { None, Pcf3, Pcf5, Poisson };

// The names parseShadowFilter accepts, for error messages.
inline constexpr const char* kShadowFilterNames = "none|pcf3|pcf5|poisson";

// "none", "pcf3", "pcf5", "poisson" (the CLI, sweep and JSON names); nullopt for anything else.
inline std::optional<ShadowFilter> parseShadowFilter(std::string_view name) {
    if (name == "none")
        return ShadowFilter::None;
    if (name == "pcf3")
        return ShadowFilter::Pcf3;
    if (name == "pcf5")
        return ShadowFilter::Pcf5;
    if (name == "poisson")
        return ShadowFilter::Poisson;
    return std::nullopt;
}

inline const char* formatShadowFilter(ShadowFilter filter) {
    switch (filter) {
    case ShadowFilter::None:
        return "none";
    case ShadowFilter::Pcf3:
        return "pcf3";
    case ShadowFilter::Pcf5:
        return "pcf5";
    case ShadowFilter::Poisson:
        return "poisson";
    }
    return "none";
}

// The ranges the loaders accept, the same as the CLI's (experiments/render/RenderOptions.cpp).
inline constexpr int kMinShadowMapSize = 16;
inline constexpr int kMaxShadowMapSize = 8192; // a cube map of 8192^2 faces is 1.5 GB
inline constexpr float kMaxShadowBias = 100.0f;

// One light's own settings; an empty field: the global setting.
struct LightShadow {
    std::optional<int> mapSize;        // texels per face side
    std::optional<float> biasConstant; // metres
    std::optional<float> biasSlope;    // texels
    std::optional<ShadowFilter> filter;
    std::optional<float> normalOffset; // texels

    bool any() const { return mapSize || biasConstant || biasSlope || filter || normalOffset; }
};

} // namespace scenes
