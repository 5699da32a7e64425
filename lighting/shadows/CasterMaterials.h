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
//   (gbuffer/visibility/AlphaCoverage.h), with the same alpha (gbuffer/visibility/MaterialAlpha.h).
//   A material without a base colour texture has one alpha (baseColorFactor.a): it casts wholly
//   or not at all, decided per material. A textured one is alpha-tested per point
//   (CasterAlphaTest): the maps test each texel's centre in a depth-only draw of their own after
//   the opaque casters (ShadowMaps.cpp), the rays each hit at its barycentrics (an Embree
//   occlusion filter, RayVisibility.cpp; the exact oracle likewise, ExactRayCast.h), so a
//   cut-out's holes let the light through in maps and rays alike.
// Pure functions, O(materials); CasterAlphaTest's queries are thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/MaterialAlpha.h"
#include "gbuffer/visibility/SceneGeometry.h"
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

// Whether a material's casters are alpha-tested per point (a textured Mask material).
inline bool materialAlphaTested(const scenes::Material& material) {
    return material.alphaMode == scenes::AlphaMode::Mask && material.baseColorTexture >= 0;
}

// The per-point alpha test of the casters of alpha-tested materials. Holds `scene` and
// `geometry` by reference: both must outlive it.
class CasterAlphaTest {
public:
    CasterAlphaTest(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry)
        : mScene(&scene), mGeometry(&geometry) {
        mTested.reserve(scene.materials.size());
        for (const scenes::Material& material : scene.materials) {
            mTested.push_back(materialAlphaTested(material) ? 1 : 0);
            mAny = mAny || mTested.back();
        }
    }
    // True when some material is alpha-tested (only then does any caster pay for the test).
    bool any() const { return mAny; }
    // Whether `triangle` (of the geometry) is alpha-tested.
    bool tested(uint32_t triangle) const {
        return mAny && mTested[mGeometry->triangleMaterial[triangle]] != 0;
    }
    // Whether `triangle` casts at the point with `weights` of its corners (index order): its
    // alpha there is at least the material's cutoff. True for a triangle that is not tested.
    bool casts(uint32_t triangle, const glm::vec3& weights) const {
        if (!tested(triangle))
            return true;
        const uint32_t material = mGeometry->triangleMaterial[triangle];
        return castsAtUv(material, uvAt(triangle, weights));
    }
    // The same in two steps, for a draw that interpolates uvs itself: the uv at `weights` of
    // (tested) `triangle`, and whether `material` casts at a uv.
    glm::vec2 uvAt(uint32_t triangle, const glm::vec3& weights) const {
        return gbuffer::baseColorUv(mScene->materials[mGeometry->triangleMaterial[triangle]],
                                    *mGeometry, triangle, weights);
    }
    bool castsAtUv(uint32_t material, glm::vec2 uv) const {
        const scenes::Material& m = mScene->materials[material];
        return gbuffer::baseColorAlphaAtUv(*mScene, m, uv) >= m.alphaCutoff;
    }

private:
    const scenes::Scene* mScene;
    const gbuffer::SceneGeometry* mGeometry;
    std::vector<uint8_t> mTested; // per material
    bool mAny = false;
};

} // namespace lighting::shadows
