// CameraView's sub-pixel jitter (pixelOffset, the supersampled reference's sub-frames): a zero
// offset leaves every matrix bitwise as it was; with an offset the point that was (dx, dy) pixels
// from a pixel's centre lands on it; and every reader of the jittered view agrees on that sample
// point: the rasterized depth decoded by the DepthDecoder (inverse projection and view ray) and
// the exact surface both lie on the geometry, on the ray through the jittered sample. And
// viewDepthOfNdc is bitwise glm's whole product.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferLayout.h"
#include "gbuffer/GBufferPass.h"
#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/ExactSurface.h"
#include "gbuffer/visibility/SceneGeometry.h"

namespace {

constexpr int kWidth = 64;
constexpr int kHeight = 48;
const glm::dvec2 kOffset(0.3125, -0.4375); // D3D 16x samples 5 and (0, -7) mixed: x right, y down

scenes::Camera camera() {
    scenes::Camera c;
    c.positionWorld = {0.5f, 1.0f, 2.0f};
    c.forwardWorld = glm::normalize(glm::vec3(0.1f, -0.2f, -1.0f));
    c.verticalFovRadians = 1.0f;
    return c;
}

// Pixel coordinates (x right, y down, pixel (i, j) spanning [i, i + 1) x [j, j + 1)) of a view-
// space point under the view's own matrices, in double.
glm::dvec2 pixelOf(const gbuffer::CameraView& view, const glm::dvec3& positionView) {
    const glm::dvec4 clip = glm::inverse(view.viewFromClipExact) * glm::dvec4(positionView, 1.0);
    const glm::dvec2 ndc = glm::dvec2(clip) / clip.w;
    return {(ndc.x + 1.0) / 2.0 * view.width, (1.0 - ndc.y) / 2.0 * view.height};
}

bool sameBits(const glm::mat4& a, const glm::mat4& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}
bool sameBits(const glm::dmat4& a, const glm::dmat4& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(CameraViewJitter, ZeroOffsetIsBitwiseTheUnjitteredView) {
    for (const bool reversed : {true, false})
        for (const bool infinite : {false, true}) {
            const auto convention =
                reversed ? gbuffer::DepthConvention::Reversed : gbuffer::DepthConvention::Standard;
            const gbuffer::CameraView plain =
                gbuffer::CameraView::fromCamera(camera(), kWidth, kHeight, convention, infinite);
            const gbuffer::CameraView zero = gbuffer::CameraView::fromCamera(
                camera(), kWidth, kHeight, convention, infinite, glm::dvec2(0.0));
            EXPECT_TRUE(sameBits(plain.clipFromView, zero.clipFromView));
            EXPECT_TRUE(sameBits(plain.viewFromClip, zero.viewFromClip));
            EXPECT_TRUE(sameBits(plain.viewFromClipExact, zero.viewFromClipExact));
            EXPECT_EQ(plain.clipFromView[2][0], 0.0f);
            EXPECT_EQ(plain.clipFromView[2][1], 0.0f);
        }
}

TEST(CameraViewJitter, TheOffsetPointLandsOnThePixelCentre) {
    const gbuffer::CameraView plain = gbuffer::CameraView::fromCamera(camera(), kWidth, kHeight);
    const gbuffer::CameraView jittered = gbuffer::CameraView::fromCamera(
        camera(), kWidth, kHeight, gbuffer::DepthConvention::Reversed, false, kOffset);
    EXPECT_EQ(jittered.pixelOffset, kOffset);
    EXPECT_TRUE(sameBits(plain.viewFromWorld, jittered.viewFromWorld)); // only the projection
    for (const glm::dvec3 p :
         {glm::dvec3(0.2, -0.1, -3.0), glm::dvec3(-1.5, 0.7, -9.0), glm::dvec3(2.0, 1.0, -40.0)}) {
        const glm::dvec2 before = pixelOf(plain, p), after = pixelOf(jittered, p);
        EXPECT_NEAR(after.x, before.x - kOffset.x, 1e-9);
        EXPECT_NEAR(after.y, before.y - kOffset.y, 1e-9);
        // The float matrices agree with the exact ones.
        const glm::vec4 clip = jittered.clipFromView * glm::vec4(glm::vec3(p), 1.0f);
        EXPECT_NEAR((clip.x / clip.w + 1.0f) / 2.0f * kWidth, after.x, 1e-3);
    }
}

// A tilted plane, rendered through a jittered view: every covered pixel's decoded position (both
// position methods) and exact position lie on the plane and on the ray through the pixel's
// jittered sample (pixel centre + offset under the unjittered camera).
TEST(CameraViewJitter, DecodedAndExactPositionsLieOnTheGeometryAtTheJitteredSample) {
    scenes::Scene scene;
    scene.name = "tilted-plane";
    scenes::Mesh mesh;
    mesh.positions = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}};
    mesh.normals.assign(4, glm::vec3(0, 0, 1));
    mesh.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    scene.meshes.push_back(mesh);
    scene.materials.emplace_back();
    glm::mat4 worldFromObject = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -8));
    worldFromObject = glm::rotate(worldFromObject, glm::radians(-60.0f), glm::vec3(1, 0, 0));
    scene.instances.push_back({0, worldFromObject});
    scene.cameras.push_back(camera());
    scenes::validate(scene);
    const gbuffer::SceneGeometry geometry = gbuffer::SceneGeometry::build(scene);

    const gbuffer::CameraView plain = gbuffer::CameraView::fromCamera(camera(), kWidth, kHeight);
    const glm::dvec3 pointView(plain.viewFromWorldExact * glm::dvec4(0, 0, -8, 1));
    const glm::dvec3 normalView = glm::normalize(
        glm::dmat3(plain.viewFromWorldExact) * glm::dvec3(worldFromObject * glm::vec4(0, 0, 1, 0)));
    for (const gbuffer::PositionMethod method :
         {gbuffer::PositionMethod::InverseProjection, gbuffer::PositionMethod::ViewRay}) {
        const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(
            camera(), kWidth, kHeight, gbuffer::DepthConvention::Reversed, false, kOffset);
        gbuffer::GBufferLayout layout =
            gbuffer::GBufferLayout::lossless(gbuffer::DepthConvention::Reversed);
        layout.position = method;
        gbuffer::GBuffer target(layout, view);
        gbuffer::ExactSurface exact;
        raster::Rasterizer rasterizer(kWidth, kHeight);
        gbuffer::GBufferPass pass(scene, geometry);
        pass.render(rasterizer, target, &exact);
        int covered = 0;
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) {
                const size_t pixel = size_t(y) * kWidth + x;
                if (!target.covered(pixel))
                    continue;
                ++covered;
                const glm::dvec2 sample(x + 0.5 + kOffset.x, y + 0.5 + kOffset.y);
                const glm::dvec3 decoded(target.decode(x, y).positionView);
                // The float decode within float precision, the exact surface within double's.
                const glm::dvec3 positions[2] = {decoded, exact.positionView[pixel]};
                const double planeTolerance[2] = {2e-5, 1e-9}, pixelTolerance[2] = {5e-3, 1e-7};
                for (int i = 0; i < 2; ++i) {
                    const glm::dvec3& p = positions[i];
                    EXPECT_NEAR(glm::dot(p - pointView, normalView), 0.0,
                                planeTolerance[i] * glm::length(p))
                        << x << "," << y;
                    // Under the unjittered camera it projects to the jittered sample.
                    const glm::dvec2 at = pixelOf(plain, p);
                    EXPECT_NEAR(at.x, sample.x, pixelTolerance[i]) << x << "," << y;
                    EXPECT_NEAR(at.y, sample.y, pixelTolerance[i]) << x << "," << y;
                }
            }
        EXPECT_GT(covered, kWidth * kHeight / 4);
    }
}

TEST(CameraView, ViewDepthOfNdcIsBitwiseTheWholeProduct) {
    // Both conventions, finite and infinite far planes, jittered and not; depths across [0, 1]
    // with the ends, at every pixel centre of a small view.
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    int compared = 0;
    for (const auto convention :
         {gbuffer::DepthConvention::Reversed, gbuffer::DepthConvention::Standard})
        for (const bool infiniteFar : {false, true})
            for (const glm::dvec2 offset : {glm::dvec2(0.0), kOffset}) {
                gbuffer::CameraView view = gbuffer::CameraView::fromCamera(
                    camera(), kWidth, kHeight, convention, infiniteFar, offset);
                // A projection's inverse has zeros where the sums' order would show; a dense
                // matrix (the last case) has none.
                if (infiniteFar && offset != glm::dvec2(0.0) &&
                    convention == gbuffer::DepthConvention::Standard)
                    for (int c = 0; c < 4; ++c)
                        for (int r = 0; r < 4; ++r)
                            view.viewFromClip[c][r] = unit(random) * 2.0f - 0.5f;
                for (int y = 0; y < kHeight; ++y)
                    for (int x = 0; x < kWidth; ++x) {
                        const float depth = x == 0 ? 0.0f : x == 1 ? 1.0f : unit(random);
                        const glm::vec2 ndc = view.ndcOfPixel(x, y);
                        const glm::vec4 p =
                            view.viewFromClip * glm::vec4(ndc.x, ndc.y, depth, 1.0f);
                        const float expected = -p.z / p.w;
                        const float got = view.viewDepthOfNdc(ndc.x, ndc.y, depth);
                        ASSERT_EQ(std::bit_cast<uint32_t>(got), std::bit_cast<uint32_t>(expected))
                            << x << ", " << y << ", depth " << depth;
                        ++compared;
                    }
            }
    EXPECT_EQ(compared, 8 * kWidth * kHeight);
}

} // namespace
