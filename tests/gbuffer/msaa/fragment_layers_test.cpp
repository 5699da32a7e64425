// FragmentLayers (gbuffer/msaa/FragmentLayers.h): the samples of each pixel are partitioned among
// its fragments and the background; the main fragment has the most samples; primitive detection
// marks every pixel whose samples show two triangles; discontinuity detection leaves the shared
// edges of a smooth mesh simple but keeps silhouettes complex; silhouettes against the far plane
// stay covered; sub-pixel triangles make complex pixels; the byte counts add up.
#include <gtest/gtest.h>

#include <bit>
#include <memory>
#include <set>

#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferPass.h"
#include "gbuffer/LayoutDerivation.h"
#include "gbuffer/msaa/FragmentLayers.h"
#include "raster/Rasterizer.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace gbuffer {
namespace {

struct Frame {
    scenes::Scene scene;
    SceneGeometry geometry;
    CameraView view;
    std::unique_ptr<GBuffer> target;
    MultisampleTarget multisample;
};

std::unique_ptr<Frame> render(const char* sceneName, int samples, ComplexDetection detection,
                              int width = 160, int height = 90) {
    auto frame = std::make_unique<Frame>();
    scenes::SceneRequest request;
    request.lightCount = 4;
    frame->scene = scenes::buildProceduralScene(sceneName, request);
    frame->geometry = SceneGeometry::build(frame->scene);
    frame->view = CameraView::fromCamera(frame->scene.cameras.front(), width, height);
    GBufferLayout layout = GBufferLayout::lossless(DepthConvention::Reversed);
    layout.materials = materialTable(frame->scene);
    frame->target = std::make_unique<GBuffer>(layout, frame->view);
    frame->multisample.samples = samples;
    frame->multisample.options.detection = detection;
    raster::Rasterizer rasterizer(width, height);
    GBufferPass pass(frame->scene, frame->geometry);
    pass.render(rasterizer, *frame->target, nullptr, &frame->multisample);
    return frame;
}

TEST(FragmentLayers, SamplesArePartitionedAndTheMainFragmentHasTheMost) {
    for (int samples : {2, 4, 8}) {
        const auto frame = render("atrium", samples, ComplexDetection::Primitive);
        const FragmentLayers& layers = frame->multisample.layers;
        ASSERT_EQ(layers.samples(), samples);
        for (size_t pixel = 0; pixel < layers.pixelCount(); ++pixel) {
            unsigned all = 0;
            int counted = 0;
            for (int k = 0; k < layers.layerCount(); ++k) {
                const uint8_t mask = layers.coverage(k)[pixel];
                EXPECT_EQ(all & mask, 0u) << "a sample in two fragments";
                all |= mask;
                counted += std::popcount(mask);
                if (k > 0)
                    EXPECT_LE(std::popcount(mask), std::popcount(layers.coverage(0)[pixel]));
                EXPECT_EQ(mask == 0, layers.codes(k)[pixel] == VisibilityPass::kNoTriangle);
            }
            EXPECT_EQ(counted + int(layers.backgroundWeight(pixel) * samples + 0.5f), samples);
            // Layer 0's G-buffer is covered exactly where some sample is.
            EXPECT_EQ(frame->target->covered(pixel), all != 0);
        }
        EXPECT_GT(layers.counts().complexPixels, 0u);
    }
}

TEST(FragmentLayers, SilhouettesAgainstTheFarPlaneStayCovered) {
    // A floor running past the far plane (clipped there) and a thin slanted wall whose far end
    // touches it: at the clip line pixels have covered samples while the triangle's depth plane,
    // extrapolated to the pixel centre, lies beyond the far plane (clamped to the clear value).
    // Layer 0 must still count them as covered, with a depth strictly nearer than the clear one.
    scenes::Scene scene;
    scene.name = "far-silhouette";
    scene.materials.push_back({});
    scene.meshes.emplace_back();
    scenes::Mesh& mesh = scene.meshes[0];
    auto quad = [&](glm::vec3 corner, glm::vec3 u, glm::vec3 v) {
        const uint32_t base = uint32_t(mesh.positions.size());
        const glm::vec3 normal = glm::normalize(glm::cross(u, v));
        for (const glm::vec3& p : {corner, corner + u, corner + u + v, corner + v}) {
            mesh.positions.push_back(p);
            mesh.normals.push_back(normal);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
            mesh.indices.push_back(base + i);
    };
    quad({-200, -2, 0}, {400, 0, 0}, {0, 0, -400});   // floor, far beyond 100 m
    quad({-30, -2, -60}, {0.3f, 0, -60}, {0, 30, 0}); // wall reaching 120 m
    scene.instances.push_back({});
    scenes::Camera camera;
    camera.name = "low";
    camera.forwardWorld = glm::normalize(glm::vec3(0, -0.02f, -1));
    camera.farMetres = 100.0f;
    scene.cameras.push_back(camera);
    const SceneGeometry geometry = SceneGeometry::build(scene);
    for (const DepthConvention convention :
         {DepthConvention::Reversed, DepthConvention::Standard}) {
        const CameraView view = CameraView::fromCamera(camera, 200, 120, convention);
        GBufferLayout layout = GBufferLayout::lossless(convention);
        layout.materials = materialTable(scene);
        GBuffer target(layout, view);
        MultisampleTarget multisample;
        multisample.samples = 8;
        raster::Rasterizer rasterizer(200, 120);
        GBufferPass pass(scene, geometry);
        pass.render(rasterizer, target, nullptr, &multisample);
        const FragmentLayers& layers = multisample.layers;
        size_t partial = 0;
        for (size_t pixel = 0; pixel < layers.pixelCount(); ++pixel) {
            const bool anySample = layers.coverage(0)[pixel] != 0;
            ASSERT_EQ(target.covered(pixel), anySample) << "pixel " << pixel;
            partial += anySample && layers.backgroundWeight(pixel) > 0.0f;
        }
        EXPECT_GT(partial, 100u) << "the far clip line crosses the image";
    }
}

TEST(FragmentLayers, UpperLayerGBuffersAreCoveredOnlyAtTheirFragments) {
    const auto frame = render("atrium", 4, ComplexDetection::Primitive);
    const FragmentLayers& layers = frame->multisample.layers;
    ASSERT_GE(layers.layerCount(), 2);
    for (int k = 1; k < layers.layerCount(); ++k) {
        const GBuffer& layer = frame->multisample.layer(*frame->target, k);
        for (size_t pixel = 0; pixel < layers.pixelCount(); ++pixel)
            ASSERT_EQ(layer.covered(pixel), layers.codes(k)[pixel] != VisibilityPass::kNoTriangle)
                << "layer " << k << " pixel " << pixel;
    }
}

TEST(FragmentLayers, DiscontinuityLeavesSmoothMeshEdgesSimple) {
    // The spheres are finely tessellated: primitive detection marks their shared edges, the depth
    // + normal test only the silhouettes (and the floor's creases). Every pixel complex under
    // discontinuity is complex under primitive too.
    const auto primitive = render("spheres", 4, ComplexDetection::Primitive);
    const auto smooth = render("spheres", 4, ComplexDetection::Discontinuity);
    const FragmentLayers& p = primitive->multisample.layers;
    const FragmentLayers& d = smooth->multisample.layers;
    EXPECT_GT(p.counts().complexPixels, 3 * d.counts().complexPixels)
        << "primitive " << p.counts().complexPixels << ", discontinuity "
        << d.counts().complexPixels;
    EXPECT_GT(d.counts().mergedFragments, 0u);
    for (size_t pixel = 0; pixel < p.pixelCount(); ++pixel)
        if (d.complex(pixel))
            EXPECT_TRUE(p.complex(pixel)) << pixel;
    // Silhouettes stay: pixels with background samples are complex either way.
    for (size_t pixel = 0; pixel < d.pixelCount(); ++pixel)
        if (d.backgroundWeight(pixel) > 0.0f && d.codes(0)[pixel] != VisibilityPass::kNoTriangle)
            EXPECT_TRUE(d.complex(pixel));
}

TEST(FragmentLayers, StoredBytesCountMainSurfacesAndExtraFragments) {
    const auto frame = render("atrium", 4, ComplexDetection::Primitive);
    const FragmentLayers& layers = frame->multisample.layers;
    const double bpp = 16.0;
    const double extra = double(layers.counts().fragments - layers.counts().coveredPixels);
    EXPECT_DOUBLE_EQ(layers.storedBytes(bpp), bpp * double(layers.pixelCount()) +
                                                  double(layers.pixelCount()) + extra * (bpp + 1));
    EXPECT_LT(layers.storedBytes(bpp), layers.allocatedBytes(bpp));
}

TEST(FragmentLayers, RefusesASingleSampleVisibilityPass) {
    scenes::SceneRequest request;
    request.lightCount = 1;
    scenes::Scene scene = scenes::buildProceduralScene("spheres", request);
    const SceneGeometry geometry = SceneGeometry::build(scene);
    const CameraView view = CameraView::fromCamera(scene.cameras.front(), 32, 32);
    VisibilityPass visibility;
    visibility.transform(scene, geometry, view);
    raster::Rasterizer rasterizer(32, 32);
    std::vector<float> depth(32 * 32);
    visibility.draw(rasterizer, depth);
    FragmentLayers layers;
    EXPECT_THROW(layers.build(visibility, {}), std::invalid_argument);
}

} // namespace
} // namespace gbuffer
