// Blended surfaces in multisampled frames (lighting/passes/BlendedPass.h, "Multisampling"): a
// blended triangle covers and depth-tests each sample, as a GPU blends into a multisampled
// target, so a pane's own silhouette is anti-aliased, not only the opaque edges behind it.
//
// Checked in closed form without lights: every surface shows its emission only, so each sample
// is one of three colours, the wall W, the pane composited over the wall P = a E + (1 - a) W, or
// an opaque occluder C in front of part of the pane, and every resolved pixel must be
// (n_C C + n_P P + n_W W) / N for whole sample counts summing to N. The pane is turned about the
// view axis, so its silhouette crosses pixels at every offset: pixels with some but not all pane
// samples and no occluder sample are the pane's own anti-aliased edge (compositing at the pixel
// centre, as before this was built, leaves none); pixels with both occluder and pane samples are
// the per-sample depth test against the occluder's edge. Every stage that takes multisampled
// frames, layered (G-buffer stages) and native (forward stages), and 1 and 2 threads alike, at 4
// samples; brute, tiled and forward at 2 and 8 too.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/MultisampleShading.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/passes/BlendedPass.h"
#include "tests/lighting/StageTestName.h"

namespace {

constexpr int kWidth = 96;
constexpr int kHeight = 64;
constexpr float kPaneAlpha = 0.375f; // exact in binary
const glm::vec3 kWall(0.2f, 0.1f, 0.05f);
const glm::vec3 kPaneEmission(0.2f, 1.0f, 2.0f);
const glm::vec3 kOccluder(1.0f, 0.2f, 0.1f);

// A quad of half extents (hx, hy) centred at (cx, cy) at depth z, turned by `turn` radians about
// the view axis.
scenes::Mesh quad(float cx, float cy, float hx, float hy, float z, float turn, uint32_t material) {
    scenes::Mesh mesh;
    const float c = std::cos(turn), s = std::sin(turn);
    const float corners[4][2] = {{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}};
    for (const auto& corner : corners)
        mesh.positions.push_back(
            {cx + c * corner[0] - s * corner[1], cy + s * corner[0] + c * corner[1], z});
    mesh.normals.assign(4, glm::vec3(0, 0, 1));
    mesh.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    mesh.material = material;
    return mesh;
}

scenes::Scene paneScene() {
    scenes::Scene scene;
    scene.name = "pane-edges";
    scenes::Material wall, pane, occluder;
    wall.emissiveFactor = kWall;
    pane.emissiveFactor = kPaneEmission;
    pane.baseColorFactor.a = kPaneAlpha;
    pane.alphaMode = scenes::AlphaMode::Blend;
    occluder.emissiveFactor = kOccluder;
    scene.materials = {wall, pane, occluder};
    scene.meshes = {quad(0.0f, 0.0f, 12.0f, 8.0f, -4.0f, 0.0f, 0),
                    quad(0.0f, 0.0f, 0.8f, 0.5f, -3.0f, 0.35f, 1),
                    quad(0.55f, 0.35f, 0.3f, 0.25f, -2.5f, -0.6f, 2)};
    for (uint32_t i = 0; i < 3; ++i)
        scene.instances.push_back({i, glm::mat4(1.0f)});
    scene.cameras.push_back(scenes::Camera{});
    scenes::validate(scene);
    return scene;
}

struct Counts {
    int occluder = 0, pane = 0, wall = 0;
};

// The sample counts whose mix is `rgb`, or false when no mix of `samples` samples is within
// tolerance. The mix is unique: red gives the occluder's count, then green the pane's.
bool mixOf(const glm::vec3& rgb, int samples, Counts& counts) {
    const glm::vec3 overWall = kPaneAlpha * kPaneEmission + (1.0f - kPaneAlpha) * kWall;
    for (int c = 0; c <= samples; ++c)
        for (int p = 0; c + p <= samples; ++p) {
            const int w = samples - c - p;
            const glm::vec3 mix =
                (float(c) * kOccluder + float(p) * overWall + float(w) * kWall) / float(samples);
            bool close = true;
            for (int ch = 0; ch < 3; ++ch)
                close = close && std::abs(rgb[ch] - mix[ch]) <= 2e-5f * std::max(mix[ch], 0.05f);
            if (close) {
                counts = {c, p, w};
                return true;
            }
        }
    return false;
}

std::vector<std::string> multisampledStages() {
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        if (info.msaaRefusal.empty())
            names.push_back(info.name);
    return names;
}

// The frame of `stageName` at `samples` samples, checked as the file comment says; returns the
// pixels of the pane's own edge and of the occluder's edge over the pane.
void checkPaneEdges(const std::string& stageName, int samples, int& paneEdge, int& occludedPane) {
    const scenes::Scene scene = paneScene();
    const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(stageName);
    const gbuffer::GBufferLayout layout =
        gbuffer::makeLayout(scene, stage->requirements().channels, stageName, {});
    lighting::Multisampling multisampling;
    multisampling.samples = samples;
    lighting::StageResult resolved[2];
    for (int threads = 1; threads <= 2; ++threads) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            lighting::PreparedScene frame(scene, kWidth, kHeight, false, layout, multisampling);
            lighting::MultisampleShading shading;
            shading.shade(*stage, frame, resolved[threads - 1]);
        });
    }
    paneEdge = 0, occludedPane = 0;
    int failures = 0;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            const size_t pixel = size_t(y) * kWidth + size_t(x);
            const lighting::StageResult& image = resolved[0];
            const glm::vec3 rgb(image.radiance[0][pixel], image.radiance[1][pixel],
                                image.radiance[2][pixel]);
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_EQ(image.radiance[ch][pixel], resolved[1].radiance[ch][pixel])
                    << stageName << ": 1 and 2 threads differ at " << x << "," << y;
            Counts counts;
            if (!mixOf(rgb, samples, counts)) {
                if (failures++ < 5)
                    ADD_FAILURE() << stageName << " pixel (" << x << ", " << y << "): " << rgb.r
                                  << " " << rgb.g << " " << rgb.b << " is no mix of " << samples
                                  << " wall, pane and occluder samples";
                continue;
            }
            paneEdge += counts.occluder == 0 && counts.pane > 0 && counts.pane < samples;
            occludedPane += counts.occluder > 0 && counts.pane > 0;
        }
    EXPECT_EQ(failures, 0) << stageName << ", " << samples << " samples";
}

class BlendedMsaa : public ::testing::TestWithParam<std::string> {};

TEST_P(BlendedMsaa, PaneEdgesAreCoveredAndDepthTestedPerSample) {
    int paneEdge = 0, occludedPane = 0;
    checkPaneEdges(GetParam(), 4, paneEdge, occludedPane);
    // Measured: 65 pixels of the pane's own edge, 20 of the occluder's edge over the pane.
    EXPECT_GT(paneEdge, 40) << GetParam() << ": the pane's own edges are not anti-aliased";
    EXPECT_GT(occludedPane, 10) << GetParam();
}

// 2 and 8 samples (8: every bit of the coverage byte), layered and native.
TEST(BlendedMsaaSamples, TwoAndEightSamplesMixWholeSamples) {
    for (const char* stageName : {"brute", "tiled", "forward"})
        for (int samples : {2, 8}) {
            int paneEdge = 0, occludedPane = 0;
            checkPaneEdges(stageName, samples, paneEdge, occludedPane);
            EXPECT_GT(paneEdge, 30) << stageName << ", " << samples << " samples";
            EXPECT_GT(occludedPane, 5) << stageName << ", " << samples << " samples";
        }
}

INSTANTIATE_TEST_SUITE_P(EveryStage, BlendedMsaa, ::testing::ValuesIn(multisampledStages()),
                         stagecheck::stageTestName);

// The tiled stages' blended lists (BlendedPass.h, "Tile lists"): a blended fragment that passes
// at a sample is shaded at its centre depth, which at a steep pane's edge is extrapolated past the
// opaque surface behind. Panes recede towards a wall and end 5 mm in front of it (about 0.04 m of
// depth per pixel there), and thousands of small lights sit just behind the wall: lights that
// reach only the extrapolated centres. Bounded by the sample depths alone, the lists drop them
// and the image differs from brute's; with the fragments' centre depths it is bitwise brute's.
scenes::Scene steepPanesBeforeLights() {
    scenes::Scene scene;
    scene.name = "steep-panes";
    scenes::Material wall, pane;
    wall.baseColorFactor = glm::vec4(0.6f, 0.5f, 0.4f, 1.0f);
    pane.baseColorFactor = glm::vec4(0.3f, 0.7f, 0.5f, 0.5f);
    pane.alphaMode = scenes::AlphaMode::Blend;
    scene.materials = {wall, pane};
    scene.meshes.push_back(quad(0.0f, 0.0f, 12.0f, 8.0f, -4.0f, 0.0f, 0));
    scenes::Mesh panes;
    for (int i = 0; i < 6; ++i) {
        const float x0 = -1.5f + 0.5f * float(i), x1 = x0 + 0.4f;
        const uint32_t base = uint32_t(panes.positions.size());
        // The near edge slants, so that it crosses pixels at every sub-pixel offset.
        panes.positions.insert(
            panes.positions.end(),
            {{x0, -0.4f, -3.995f}, {x1, -0.46f, -3.995f}, {x1, 0.6f, -2.5f}, {x0, 0.6f, -2.5f}});
        panes.normals.insert(panes.normals.end(), 4, glm::normalize(glm::vec3(0, -1.495f, 1.0f)));
        panes.uvs.insert(panes.uvs.end(), {{0, 1}, {1, 1}, {1, 0}, {0, 0}});
        for (uint32_t index : {0u, 1u, 2u, 0u, 2u, 3u})
            panes.indices.push_back(base + index);
    }
    panes.material = 1;
    scene.meshes.push_back(panes);
    scene.instances = {{0, glm::mat4(1.0f)}, {1, glm::mat4(1.0f)}};
    scene.cameras.push_back(scenes::Camera{});
    std::mt19937 random(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int i = 0; i < 3000; ++i) {
        scenes::Light light;
        light.type = scenes::LightType::Point;
        light.positionWorld = {-1.6f + 3.2f * unit(random), -0.5f + 0.2f * unit(random),
                               -4.06f + 0.06f * unit(random)};
        light.color = glm::vec3(1.0f);
        light.intensity = 1.0f;
        light.rangeMetres = 0.01f + 0.04f * unit(random);
        scene.lights.push_back(light);
    }
    scenes::validate(scene);
    return scene;
}

TEST(BlendedMsaaTileLists, StayConservativeWhereEdgeFragmentsAreShadedBehindTheOpaqueSamples) {
    const scenes::Scene scene = steepPanesBeforeLights();
    lighting::Multisampling multisampling;
    multisampling.samples = 4;
    lighting::PreparedScene frame(
        scene, kWidth, kHeight, false,
        gbuffer::GBufferLayout::lossless(gbuffer::DepthConvention::Reversed), multisampling);
    // The case exists: layer 0 shades blended fragments behind every sample of their pixel
    // (measured: 12, the farthest 3 cm behind the wall).
    lighting::BlendedPass blended;
    ASSERT_TRUE(blended.prepare(frame.inputs));
    int behind = 0;
    const std::vector<float>& sampleDepths = *frame.inputs.sampleDepths;
    blended.forEachFragment(frame.inputs.gbuffer->depth(), [&](const raster::Fragment& fragment,
                                                               uint32_t, const gbuffer::Surface&,
                                                               float) {
        const float* sample = sampleDepths.data() + (size_t(fragment.y) * kWidth + fragment.x) * 4;
        behind += fragment.depth < *std::min_element(sample, sample + 4); // reversed Z
    });
    EXPECT_GT(behind, 5);
    lighting::StageResult brute;
    lighting::MultisampleShading bruteShading;
    bruteShading.shade(*lighting::makeStage("brute"), frame, brute);
    for (const char* stageName : {"tiled", "tiled-backface", "clustered-explicit"}) {
        lighting::StageResult result;
        lighting::MultisampleShading shading;
        shading.shade(*lighting::makeStage(stageName), frame, result);
        int differing = 0;
        for (int ch = 0; ch < 3; ++ch)
            for (size_t pixel = 0; pixel < result.radiance[ch].size(); ++pixel)
                differing += result.radiance[ch][pixel] != brute.radiance[ch][pixel];
        EXPECT_EQ(differing, 0) << stageName;
    }
}

} // namespace
