#include "gbuffer/visibility/AlphaCoverage.h"

#include "gbuffer/visibility/MaterialAlpha.h"
#include "gbuffer/visibility/TriangleCorners.h"

namespace gbuffer {

void AlphaCoverage::build(const scenes::Scene& scene, bool alphaToCoverage) {
    mRules.assign(scene.materials.size(), Rule::Keep);
    mActive = false;
    mAnyBlend = false;
    mAlphaToCoverage = alphaToCoverage;
    for (size_t m = 0; m < scene.materials.size(); ++m) {
        const scenes::Material& material = scene.materials[m];
        switch (material.alphaMode) {
        case scenes::AlphaMode::Opaque:
            break;
        case scenes::AlphaMode::Blend:
            mRules[m] = Rule::Discard;
            mActive = mAnyBlend = true;
            break;
        case scenes::AlphaMode::Mask:
            mActive = true;
            if (alphaToCoverage)
                mRules[m] = Rule::ToCoverage; // even a constant alpha: its coverage is partial
            else if (material.baseColorTexture >= 0)
                mRules[m] = Rule::TestTexture;
            else if (!(material.baseColorFactor.a >= material.alphaCutoff))
                mRules[m] = Rule::Discard;
            break;
        }
    }
}

float AlphaCoverage::alphaAt(const scenes::Scene& scene, const SceneGeometry& geometry,
                             std::span<const glm::vec4> clipPositions, const CameraView& view,
                             uint32_t triangle, int x, int y) {
    const scenes::Material& material = scene.materials[geometry.triangleMaterial[triangle]];
    if (material.baseColorTexture < 0)
        return material.baseColorFactor.a;
    // The resolve's weights (TriangleCorners.h: RowWeights, then the normalised sum), so the
    // alpha test reads the uv the G-buffer's albedo reads.
    const uint32_t* index = geometry.indices.data() + 3 * size_t(triangle);
    TriangleCorners corners;
    for (int i = 0; i < 3; ++i) {
        const glm::vec4& clip = clipPositions[index[i]];
        corners.clipX[i] = clip.x;
        corners.clipY[i] = clip.y;
        corners.clipW[i] = clip.w;
    }
    const glm::vec2 ndc = view.ndcOfPixel(x, y);
    const RowWeights row = RowWeights::of(corners, ndc.y);
    glm::vec3 b = row.constant - ndc.x * row.slope;
    float sum = b.x + b.y + b.z;
    if (sum == 0.0f) {
        b = glm::vec3(1.0f);
        sum = 3.0f;
    }
    return baseColorAlpha(scene, geometry, triangle, b * (1.0f / sum));
}

} // namespace gbuffer
