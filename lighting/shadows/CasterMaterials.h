// CasterMaterials: which materials cast shadows, the one policy both the shadow maps
// (ShadowMaps.h: the triangles a light's faces draw) and the ray-traced reference (RayVisibility:
// the triangles in its BVH) apply, so that maps and rays are measured against the same truth.
//
// By glTF alphaMode (scenes::Material):
// - Opaque: casts.
// - Blend: casts no shadow. The testbed does not model light transmitted through a blended
//   surface; of the two policies a rasterizer can apply per material (a full shadow, or none),
//   none is nearer a clear pane (glass's panes, alpha 0.25-0.4), and it leaves the panes'
//   own shading (BlendedPass) as the only place their alpha acts.
// - Mask: casts where alpha >= alphaCutoff, as the G-buffer keeps its fragments
//   (gbuffer/visibility/AlphaCoverage.h). Decided per material only: a material without a base
//   colour texture has one alpha (baseColorFactor.a), so it casts wholly or not at all; a
//   textured one casts wholly (its per-texel alpha test, an alpha-testing depth-only draw and an
//   Embree filter function at the hit's barycentrics, is not built: its holes cast shadow).
// Pure functions, O(materials).
#pragma once

#include <cstdint>
#include <vector>

#include "scenes/Scene.h"

namespace lighting::shadows {

inline bool materialCastsShadow(const scenes::Material& material) {
    switch (material.alphaMode) {
    case scenes::AlphaMode::Opaque:
        return true;
    case scenes::AlphaMode::Blend:
        return false;
    case scenes::AlphaMode::Mask:
        return material.baseColorTexture >= 0 || material.baseColorFactor.a >= material.alphaCutoff;
    }
    return true;
}

// One flag per material of `scene` (1 = casts).
inline std::vector<uint8_t> castingMaterials(const scenes::Scene& scene) {
    std::vector<uint8_t> casts;
    casts.reserve(scene.materials.size());
    for (const scenes::Material& material : scene.materials)
        casts.push_back(materialCastsShadow(material) ? 1 : 0);
    return casts;
}

} // namespace lighting::shadows
