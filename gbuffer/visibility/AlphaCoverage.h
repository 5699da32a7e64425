// AlphaCoverage: which fragments of a scene's opaque draws exist, given the materials' glTF
// alphaMode (scenes::Material::alphaMode). It is part of coverage, decided once in the
// visibility draw (VisibilityPass::draw, and the forward stages' draws through ForwardGeometry)
// before the depth write, so every stage, and the reference, which takes its covering triangle
// from the same draw (ExactSurface.h), sees through the same fragments:
// - Opaque: kept (alpha ignored);
// - Mask: kept when alpha >= alphaCutoff, discarded otherwise (glTF 2.0, "Alpha Coverage");
// - Blend: always discarded from the opaque draws: blended surfaces are shaded and composited
//   afterwards (lighting/passes/BlendedPass.h).
// alpha = baseColorFactor.a * base colour texture alpha (linear) at the pixel centre, the uv found
// with the same perspective-correct weights as the G-buffer resolve (TriangleCorners.h). The
// loaders read no vertex colours, so there is no vertex-colour alpha.
//
// Cost: only a scene with a Mask or Blend material pays anything (active() decides per draw which
// fragment function the rasterizer gets); there, opaque materials cost one table lookup per
// fragment, Blend one more, and Mask materials a uv interpolation and one texture lookup (none
// when the material is untextured: its alpha is the factor's, decided per material).
// Thread safety: build() is not reentrant; the const queries are thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "scenes/Scene.h"

namespace gbuffer {

class AlphaCoverage {
public:
    // What the opaque draws do with a material's fragments.
    enum class Rule : uint8_t {
        Keep,        // Opaque, or Mask with a constant alpha >= cutoff
        Discard,     // Blend, or Mask with a constant alpha < cutoff
        TestTexture, // Mask with a base colour texture: alpha per fragment
    };

    // One rule per material of `scene`. Cost O(materials).
    void build(const scenes::Scene& scene);
    // True when some material is Mask or Blend: the draws then test every fragment.
    bool active() const { return mActive; }
    // True when some material is Blend (lighting/passes/BlendedPass.h has work).
    bool anyBlend() const { return mAnyBlend; }
    Rule rule(uint32_t material) const { return mRules[material]; }

    // The base colour alpha of `triangle` at pixel (x, y)'s centre: the factor times the
    // texture's alpha. clipPositions are the frame's (VisibilityPass::clipPositions()).
    static float alphaAt(const scenes::Scene& scene, const SceneGeometry& geometry,
                         std::span<const glm::vec4> clipPositions, const CameraView& view,
                         uint32_t triangle, int x, int y);

    // Whether the opaque draws keep `triangle`'s fragment at (x, y).
    bool keeps(const scenes::Scene& scene, const SceneGeometry& geometry,
               std::span<const glm::vec4> clipPositions, const CameraView& view, uint32_t triangle,
               int x, int y) const {
        const uint32_t material = geometry.triangleMaterial[triangle];
        switch (mRules[material]) {
        case Rule::Keep:
            return true;
        case Rule::Discard:
            return false;
        case Rule::TestTexture:
            return alphaAt(scene, geometry, clipPositions, view, triangle, x, y) >=
                   scene.materials[material].alphaCutoff;
        }
        return true;
    }

private:
    std::vector<Rule> mRules;
    bool mActive = false;
    bool mAnyBlend = false;
};

} // namespace gbuffer
