// FragmentLayers (gbuffer/msaa/FragmentLayers.h): the samples of each pixel are partitioned among
// its fragments and the background; the main fragment has the most samples; primitive detection
// marks every pixel whose samples show two triangles; discontinuity detection leaves the shared
// edges of a smooth mesh simple but keeps silhouettes complex; silhouettes against the far plane
// stay covered; sub-pixel triangles make complex pixels; the byte counts add up; and every layer
// is bitwise what the definition gives pixel by pixel (an oracle written here from the header's
// description, without the build's shortcuts).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <vector>

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

// The layers by their definition (FragmentLayers.h), pixel by pixel: the distinct codes of the
// pixel's samples in order of their first sample, each with its coverage and the centre depth its
// first sample recorded (one float step nearer when it is the clear value); the one with the most
// samples first (ties to the earliest), the others after it in their order; with discontinuity
// detection, each other fragment merged into the main one when its view depth, normal and
// material are close (surfaceAt, one call per fragment).
struct OracleFragment {
    uint32_t code;
    uint8_t mask;
    float depth;
};
std::vector<OracleFragment> oracleFragments(const VisibilityPass& visibility, int x, int y,
                                            const FragmentLayerOptions& options) {
    const CameraView& view = visibility.view();
    const size_t samples = size_t(visibility.sampleCount());
    const size_t first = (size_t(y) * size_t(view.width) + size_t(x)) * samples;
    std::vector<OracleFragment> fragments;
    for (size_t s = 0; s < samples; ++s) {
        const uint32_t code = visibility.codes()[first + s];
        if (code == VisibilityPass::kNoTriangle)
            continue;
        auto it = std::find_if(fragments.begin(), fragments.end(),
                               [&](const OracleFragment& f) { return f.code == code; });
        if (it == fragments.end()) {
            float depth = visibility.centreDepths()[first + s];
            if (depth == view.clearDepth())
                depth = std::nextafter(view.clearDepth(), view.reversedZ() ? 1.0f : 0.0f);
            fragments.push_back({code, 0, depth});
            it = fragments.end() - 1;
        }
        it->mask = uint8_t(it->mask | 1u << s);
    }
    if (fragments.empty())
        return fragments;
    size_t main = 0;
    for (size_t k = 1; k < fragments.size(); ++k)
        if (std::popcount(fragments[k].mask) > std::popcount(fragments[main].mask))
            main = k;
    std::rotate(fragments.begin(), fragments.begin() + long(main),
                fragments.begin() + long(main) + 1);
    if (options.detection == ComplexDetection::Primitive)
        return fragments;
    auto viewDepth = [&](float depth) {
        const glm::vec2 ndc = view.ndcOfPixel(x, y);
        const glm::vec4 p = view.viewFromClip * glm::vec4(ndc.x, ndc.y, depth, 1.0f);
        return -p.z / p.w;
    };
    const Surface mainSurface = visibility.surfaceAt(fragments[0].code, x, y);
    const float mainDepth = viewDepth(fragments[0].depth);
    std::vector<OracleFragment> kept{fragments[0]};
    for (size_t k = 1; k < fragments.size(); ++k) {
        const Surface other = visibility.surfaceAt(fragments[k].code, x, y);
        if (std::abs(viewDepth(fragments[k].depth) - mainDepth) <=
                options.depthTolerance * mainDepth &&
            glm::dot(other.normalView, mainSurface.normalView) >= options.normalCosine &&
            other.material == mainSurface.material)
            kept[0].mask = uint8_t(kept[0].mask | fragments[k].mask);
        else
            kept.push_back(fragments[k]);
    }
    return kept;
}

// One FragmentLayers object per sample count builds the three scenes in turn, so every build
// but the first reuses planes whose upper layers the last build wrote elsewhere (FragmentLayers
// resets only those entries): each must still be the definition everywhere.
TEST(FragmentLayers, EveryLayerIsBitwiseTheDefinitionPixelByPixel) {
    for (int samples : {2, 4, 8}) {
        FragmentLayers layers;
        for (const char* sceneName : {"glass", "atrium", "spheres"})
            for (ComplexDetection detection :
                 {ComplexDetection::Primitive, ComplexDetection::Discontinuity}) {
                const std::string name = std::string(sceneName) + ", " + std::to_string(samples) +
                                         " samples, " + complexDetectionName(detection);
                scenes::SceneRequest request;
                request.lightCount = 1;
                const scenes::Scene scene = scenes::buildProceduralScene(sceneName, request);
                const SceneGeometry geometry = SceneGeometry::build(scene);
                const int width = 200, height = 120;
                const CameraView view =
                    CameraView::fromCamera(scene.cameras.front(), width, height);
                VisibilityPass visibility;
                visibility.transform(scene, geometry, view);
                raster::Rasterizer rasterizer(width, height);
                std::vector<float> depth(size_t(width) * height * size_t(samples));
                visibility.draw(rasterizer, depth, samples);
                FragmentLayerOptions options;
                options.detection = detection;
                layers.build(visibility, options);
                uint64_t complexPixels = 0, fragments = 0;
                for (int y = 0; y < height; ++y) {
                    std::vector<uint32_t> upperColumns;
                    for (int x = 0; x < width; ++x)
                        if (oracleFragments(visibility, x, y, options).size() > 1)
                            upperColumns.push_back(uint32_t(x));
                    const std::span<const uint32_t> got = layers.upperColumns(y);
                    ASSERT_EQ(std::vector<uint32_t>(got.begin(), got.end()), upperColumns)
                        << name << ", row " << y;
                }
                for (int y = 0; y < height; ++y)
                    for (int x = 0; x < width; ++x) {
                        const size_t pixel = size_t(y) * width + size_t(x);
                        const std::vector<OracleFragment> expected =
                            oracleFragments(visibility, x, y, options);
                        fragments += expected.size();
                        int covered = 0;
                        for (const OracleFragment& f : expected)
                            covered += std::popcount(f.mask);
                        const bool complex =
                            !expected.empty() && (expected.size() > 1 || covered < samples);
                        complexPixels += complex;
                        ASSERT_EQ(layers.complex(pixel), complex) << name << ", pixel " << pixel;
                        ASSERT_EQ(layers.backgroundWeight(pixel),
                                  float(samples - covered) / float(samples))
                            << name << ", pixel " << pixel;
                        for (int k = 0; k < layers.layerCount(); ++k) {
                            const bool present = size_t(k) < expected.size();
                            ASSERT_EQ(layers.codes(k)[pixel], present ? expected[size_t(k)].code
                                                                      : VisibilityPass::kNoTriangle)
                                << name << ", layer " << k << ", pixel " << pixel;
                            ASSERT_EQ(layers.coverage(k)[pixel],
                                      present ? expected[size_t(k)].mask : 0)
                                << name << ", layer " << k << ", pixel " << pixel;
                            const float want =
                                present ? expected[size_t(k)].depth : view.clearDepth();
                            const float got = layers.depths(k)[pixel];
                            ASSERT_EQ(std::memcmp(&got, &want, sizeof got), 0)
                                << name << ", layer " << k << ", pixel " << pixel;
                        }
                    }
                EXPECT_EQ(layers.counts().complexPixels, complexPixels) << name;
                EXPECT_EQ(layers.counts().fragments, fragments) << name;
                EXPECT_GT(complexPixels, 100u) << name;
            }
    }
}

// Bitwise equality of two surfaces, field by field.
void expectSameSurface(const Surface& a, const Surface& b, const std::string& where) {
    auto same = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    EXPECT_TRUE(same(a.positionView, b.positionView) && same(a.normalView, b.normalView) &&
                same(a.albedo, b.albedo) && same(a.specularIntensity, b.specularIntensity) &&
                same(a.specularPower, b.specularPower) && same(a.roughness, b.roughness) &&
                same(a.metallic, b.metallic) && same(a.occlusion, b.occlusion) &&
                same(a.emissive, b.emissive) && a.model == b.model && a.material == b.material)
        << where;
}

// The multisampled G-buffer pass keeps its fragment layers and upper-layer G-buffers between
// frames and rewrites an upper layer only where this frame or the last has an extra fragment
// (GBufferPass::resolveUpperLayer). A sequence of frames through one pass and MultisampleTarget,
// whose complex pixels change under one view (the detection switched) and then with the view (a
// jittered camera: new G-buffers), equals a fresh pass rendering each frame alone: the layers,
// and every upper layer's depth plane and decoded surfaces, bitwise; for a lossless depth format
// and a quantised one (f16-linear: the depths stored through the format).
TEST(FragmentLayers, KeptLayersEqualAFreshRenderFrameAfterFrame) {
    scenes::SceneRequest request;
    request.lightCount = 4;
    const scenes::Scene scene = scenes::buildProceduralScene("atrium", request);
    const SceneGeometry geometry = SceneGeometry::build(scene);
    const int height = 90;
    struct Step {
        glm::dvec2 pixelOffset;
        ComplexDetection detection;
        int width;
    };
    // The last two frames are narrower at the same height: the columns kept for the reset
    // belong to the wider frame and must not be reused.
    const Step steps[] = {{{0.0, 0.0}, ComplexDetection::Primitive, 160},
                          {{0.0, 0.0}, ComplexDetection::Discontinuity, 160},
                          {{0.0, 0.0}, ComplexDetection::Primitive, 160},
                          {{0.3, -0.2}, ComplexDetection::Primitive, 160},
                          {{0.3, -0.2}, ComplexDetection::Discontinuity, 160},
                          {{0.0, 0.0}, ComplexDetection::Primitive, 120},
                          {{0.0, 0.0}, ComplexDetection::Discontinuity, 120}};
    for (DepthFormatKind depthKind : {DepthFormatKind::F32Reversed, DepthFormatKind::F16Linear}) {
        GBufferLayout layout = GBufferLayout::lossless(DepthConvention::Reversed);
        layout.depth.kind = depthKind;
        layout.materials = materialTable(scene);
        GBufferPass keptPass(scene, geometry);
        MultisampleTarget kept;
        kept.samples = 4;
        std::unique_ptr<GBuffer> keptTarget;
        int layersSeen = 0;
        for (size_t step = 0; step < std::size(steps); ++step) {
            const std::string name =
                "depth " + std::to_string(int(depthKind)) + ", frame " + std::to_string(step);
            const int width = steps[step].width;
            raster::Rasterizer rasterizer(width, height);
            const CameraView view =
                CameraView::fromCamera(scene.cameras.front(), width, height,
                                       DepthConvention::Reversed, false, steps[step].pixelOffset);
            if (!keptTarget || keptTarget->view().pixelOffset != view.pixelOffset ||
                keptTarget->width() != width)
                keptTarget = std::make_unique<GBuffer>(layout, view);
            kept.options.detection = steps[step].detection;
            keptPass.render(rasterizer, *keptTarget, nullptr, &kept);

            GBufferPass freshPass(scene, geometry);
            MultisampleTarget fresh;
            fresh.samples = 4;
            fresh.options.detection = steps[step].detection;
            GBuffer freshTarget(layout, view);
            freshPass.render(rasterizer, freshTarget, nullptr, &fresh);

            const FragmentLayers& a = kept.layers;
            const FragmentLayers& b = fresh.layers;
            ASSERT_EQ(a.layerCount(), b.layerCount()) << name;
            layersSeen = std::max(layersSeen, a.layerCount());
            for (int k = 0; k < a.layerCount(); ++k) {
                ASSERT_TRUE(std::equal(a.codes(k).begin(), a.codes(k).end(), b.codes(k).begin()))
                    << name << ", layer " << k;
                ASSERT_TRUE(
                    std::equal(a.coverage(k).begin(), a.coverage(k).end(), b.coverage(k).begin()))
                    << name << ", layer " << k;
                const GBuffer& got = kept.layer(*keptTarget, k);
                const GBuffer& want = fresh.layer(freshTarget, k);
                ASSERT_EQ(0, std::memcmp(got.depth().data(), want.depth().data(),
                                         got.depth().size() * sizeof(float)))
                    << name << ", layer " << k;
                for (int y = 0; y < height; ++y)
                    for (int x = 0; x < width; ++x)
                        if (want.covered(size_t(y) * width + size_t(x)))
                            expectSameSurface(got.decode(x, y), want.decode(x, y),
                                              name + ", layer " + std::to_string(k) + ", pixel " +
                                                  std::to_string(x) + " " + std::to_string(y));
            }
        }
        EXPECT_GE(layersSeen, 3); // upper layers to keep and reset
    }
}

} // namespace
} // namespace gbuffer
