// LayoutDerivation: builds the GBufferLayout of a render from what the scene's materials use and
// what the stage reads ("model only what a scene needs"), or from a named preset, then applies
// the user's overrides (normal encoding, depth format, position method).
//
// Derived layout (the default), channel by channel, each with its reason (--explain-layout):
//   depth     always stored (coverage and position): f32-reversed, inverse projection
//   normal    float32 when the stage reads normals, else absent
//   albedo    absent when the stage does not read it; else `constant` when every used material
//             has one colour and none is textured; `material` (8/16-bit index into the material
//             table) when no used material is textured; f32 when textures make it vary per pixel
//   specular  absent when not read; `constant` when all used materials share intensity and power;
//             else `material` (specular never varies inside a material here)
// The derived layout is lossless with respect to what the rasterizer computes: brute on it gives
// bitwise the image of brute on `reference`. Lossy choices are opt-in (overrides, presets).
//
// Presets: reference, compact, and the thesis' historical layouts stalker, clear-sky, killzone2,
// bf3, thesis (see presetLayout in the .cpp for each one's mapping and where it departs from the
// published layout; the notes say so in --explain-layout).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "gbuffer/GBufferLayout.h"
#include "scenes/Scene.h"

namespace gbuffer {

struct LayoutRequest {
    std::string preset;                     // "" = derived from scene and stage
    std::optional<NormalCodecSpec> normals; // overrides
    std::optional<DepthFormatSpec> depth;
    std::optional<PositionMethod> position;
    std::optional<NormalSpace> normalSpace;
};

std::vector<std::string> layoutPresetNames();

// Albedo and specular of every scene material, as the G-buffer pass would write them untextured.
std::vector<MaterialConstants> materialTable(const scenes::Scene& scene);

GBufferLayout deriveLayout(const scenes::Scene& scene, const std::vector<Channel>& stageReads);
// Throws std::invalid_argument for an unknown name, listing the valid ones.
GBufferLayout presetLayout(const std::string& name, const scenes::Scene& scene);

// Preset or derived layout, overrides applied, checked: every channel in `stageReads` must be
// provided, else std::invalid_argument naming the stage, the channel and the layout. An override
// of a channel the stage does not read is not stored and is reported in the layout's notes.
GBufferLayout makeLayout(const scenes::Scene& scene, const std::vector<Channel>& stageReads,
                         const std::string& stageName, const LayoutRequest& request);

} // namespace gbuffer
