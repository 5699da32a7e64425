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
//   specular  absent when not read; Blinn-Phong intensity and power (when some used material is
//             Blinn-Phong): `constant` when all used materials share intensity and power, else
//             `material` (they never vary inside a material); metallic-roughness roughness and
//             metallic (when some used material is metallic-roughness, addMaterialModels): f32
//             when a metallic-roughness texture makes them vary per pixel, `constant` when every
//             used material has the same factors, else `material`
//   model     a constant when every used material has one model, else from the material index
//   emission  absent when the stage does not read it (forward stages and the material passes add
//             the emission of their own surfaces) or no used non-blended material emits (the
//             blended pass adds blended surfaces' own); f32 RGB when an
//             emissive texture varies it per pixel, else the material index
// The derived layout is lossless with respect to what the rasterizer computes: brute on it gives
// bitwise the image of brute on `reference`. Lossy choices are opt-in (overrides, presets).
//
// Presets: reference, compact, the visibility buffer (depth + triangle code, every channel fetched
// where it is decoded: GBufferLayout.h), and the thesis' historical layouts stalker, clear-sky,
// killzone2, bf3, thesis, ue4 (see presetLayout in the .cpp for each one's mapping and where it
// departs from the published layout; the notes say so in --explain-layout).
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

// Sets what the metallic-roughness model needs in `layout` (whose `materials` must be the scene's
// materialTable): the material model's source (constant or per material) and, when the stage
// reads specular and some used material is metallic-roughness, the roughness-metallic encoding
// (f32, or unorm8 when `eightBitPlanes`, where textures vary it per pixel; else constant or
// material). Blinn-Phong-only scenes leave the layout as it was. Called by deriveLayout and
// presetLayout, and by whoever builds a lossless layout for a scene.
void addMaterialModels(GBufferLayout& layout, const scenes::Scene& scene, bool readsSpecular,
                       bool eightBitPlanes);

// Sets the emission channel of `layout` (whose `materials` must be the scene's materialTable):
// none when the stage does not read it or no used material emits (BLEND materials never reach the
// G-buffer: lighting/BlendedPass adds their emission), f32 planes when an emitting
// material has an emissive texture (emission varies per pixel), else `material`. Called by
// deriveLayout and presetLayout, and by whoever builds a lossless layout for a scene.
void addEmission(GBufferLayout& layout, const scenes::Scene& scene, bool readsEmission);

GBufferLayout deriveLayout(const scenes::Scene& scene, const std::vector<Channel>& stageReads);
// Throws std::invalid_argument for an unknown name, listing the valid ones.
GBufferLayout presetLayout(const std::string& name, const scenes::Scene& scene);

// Preset or derived layout, overrides applied, checked: every channel in `stageReads` must be
// provided, else std::invalid_argument naming the stage, the channel and the layout. An override
// of a channel the stage does not read is not stored and is reported in the layout's notes.
GBufferLayout makeLayout(const scenes::Scene& scene, const std::vector<Channel>& stageReads,
                         const std::string& stageName, const LayoutRequest& request);

} // namespace gbuffer
