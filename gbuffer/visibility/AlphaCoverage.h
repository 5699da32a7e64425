// AlphaCoverage: which fragments of a scene's opaque draws exist, given the materials' glTF
// alphaMode (scenes::Material::alphaMode). It is part of coverage, decided once in the
// visibility draw (VisibilityPass::draw, and the forward stages' draws through ForwardGeometry)
// before the depth write, so every stage, and the reference, which takes its covering triangle
// from the same draw (ExactSurface.h), sees through the same fragments:
// - Opaque: kept (alpha ignored);
// - Mask: kept when alpha >= alphaCutoff, discarded otherwise (glTF 2.0, "Alpha Coverage");
//   with alpha-to-coverage on (build(scene, true), `--alpha-to-coverage on`) and more than one
//   sample per pixel, instead kept at the samples raster::alphaToCoverageMask(alpha, N, x, y)
//   selects (round(alpha * N) of the N, a fixed 2x2-dithered pattern, raster/AlphaToCoverage.h)
//   ANDed with the fragment's geometric coverage, as MSAA hardware does: alphaCutoff is then not
//   used (alpha >= 1 keeps the whole coverage, alpha 0 nothing). At one sample per pixel there is
//   no coverage to dither and the alpha test applies unchanged (the CLI refuses the combination,
//   experiments/render/RenderOptions.cpp, so that no output claims alpha-to-coverage at 1x);
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
#include "raster/AlphaToCoverage.h"
#include "scenes/Scene.h"

namespace gbuffer {

class AlphaCoverage {
public:
    // What the opaque draws do with a material's fragments.
    enum class Rule : uint8_t {
        Keep,        // Opaque, or Mask with a constant alpha >= cutoff
        Discard,     // Blend, or Mask with a constant alpha < cutoff
        TestTexture, // Mask with a base colour texture: alpha per fragment
        ToCoverage,  // Mask with alpha-to-coverage: alpha per fragment becomes a sample mask
    };

    // One rule per material of `scene`; `alphaToCoverage` turns every Mask material's rule into
    // ToCoverage. Cost O(materials).
    void build(const scenes::Scene& scene, bool alphaToCoverage = false);
    bool alphaToCoverage() const { return mAlphaToCoverage; }
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
        case Rule::ToCoverage: // one sample: the alpha test (see the file comment)
            return alphaAt(scene, geometry, clipPositions, view, triangle, x, y) >=
                   scene.materials[material].alphaCutoff;
        }
        return true;
    }

    // The samples of `coverage` (a fragment's geometric coverage at `samples` samples per pixel,
    // raster::Fragment::coverage) the opaque draws keep for `triangle`'s fragment at (x, y): all
    // or none by keeps(), except that a ToCoverage material at samples > 1 keeps
    // coverage & raster::alphaToCoverageMask(alpha, samples, x, y). Pure: every draw of the same
    // frame keeps the same samples.
    uint8_t keptSamples(const scenes::Scene& scene, const SceneGeometry& geometry,
                        std::span<const glm::vec4> clipPositions, const CameraView& view,
                        uint32_t triangle, int x, int y, int samples, uint8_t coverage) const {
        if (samples > 1 && mRules[geometry.triangleMaterial[triangle]] == Rule::ToCoverage)
            return uint8_t(
                coverage &
                raster::alphaToCoverageMask(
                    alphaAt(scene, geometry, clipPositions, view, triangle, x, y), samples, x, y));
        return keeps(scene, geometry, clipPositions, view, triangle, x, y) ? coverage : 0;
    }

private:
    std::vector<Rule> mRules;
    bool mActive = false;
    bool mAnyBlend = false;
    bool mAlphaToCoverage = false;
};

} // namespace gbuffer
