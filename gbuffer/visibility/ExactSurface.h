// ExactSurface: the unquantised surface behind every pixel, for the double-precision reference.
// The rasterizer records which triangle covers each pixel; position and normal are then
// recomputed in double by intersecting the pixel centre's view ray with that triangle's
// unrounded world-space vertices, so no float rounding of depth, interpolation or G-buffer
// encoding reaches the reference. Material values (albedo, specular, model, roughness, metallic,
// emission)
// come straight from the material and texture lookup, never through a G-buffer encoding. Normal
// maps are applied here again, in double (NormalMapping.h, the resolve's formula), at the uv of
// the double-precision intersection.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/Surface.h"
#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "scenes/Scene.h"

namespace gbuffer {

struct ExactSurface {
    static constexpr uint32_t kNoTriangle = UINT32_MAX;

    int width = 0;
    int height = 0;
    std::vector<uint32_t> triangle;  // covering triangle per pixel, kNoTriangle for background
    std::vector<uint8_t> backFacing; // 1 where the visible side is the back face (normal flipped)
    std::vector<glm::vec3> albedo;
    std::vector<glm::vec2> specular; // intensity, power
    std::vector<glm::vec2> roughnessMetallic;
    std::vector<scenes::MaterialModel> model;
    std::vector<float> occlusion;
    std::vector<glm::vec3> emissive; // the resolve's emitted radiance (factor x texture)
    std::vector<glm::dvec3> positionView;
    std::vector<glm::dvec3> normalView;

    void resize(int w, int h);
    bool covered(size_t pixel) const { return triangle[pixel] != kNoTriangle; }
    // The exact surface at pixel (x, y), in double (material index left 0); false for
    // background.
    bool surfaceAt(int x, int y, BasicSurface<double>& s) const {
        const size_t pixel = size_t(y) * width + x;
        if (!covered(pixel))
            return false;
        s.positionView = positionView[pixel];
        s.normalView = normalView[pixel];
        s.albedo = glm::dvec3(albedo[pixel]);
        s.specularIntensity = double(specular[pixel].x);
        s.specularPower = double(specular[pixel].y);
        s.roughness = double(roughnessMetallic[pixel].x);
        s.metallic = double(roughnessMetallic[pixel].y);
        s.model = model[pixel];
        s.occlusion = double(occlusion[pixel]);
        s.emissive = glm::dvec3(emissive[pixel]);
        return true;
    }
    // Fills positionView and normalView from `triangle` (parallel over rows, deterministic),
    // normal mapped where the triangle's material has a normal texture.
    void computeGeometry(const scenes::Scene& scene, const SceneGeometry& geometry,
                         const CameraView& view);
    // The exact hit of pixel (x, y)'s view ray with triangle t (computeGeometry's per-pixel
    // work, also what the reference's blended composite uses, lighting/passes/BlendedPass.h):
    // view-space position and shading normal in double, the normal negated for a back face and
    // normal mapped. False (outputs untouched) when the ray is parallel to the triangle's plane.
    static bool hit(const scenes::Scene& scene, const SceneGeometry& geometry,
                    const CameraView& view, uint32_t t, bool backFace, int x, int y,
                    glm::dvec3& positionView, glm::dvec3& normalView);
};

} // namespace gbuffer
