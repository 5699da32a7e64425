// The supersampled reference (lighting/SupersampledReference.h): its sample positions (the D3D
// 16x pattern, stratified grids: distinct, inside the pixel, fixed), 1 sample bitwise the
// `reference` stage's image, a half-plane edge against the background anti-aliased to its
// analytic coverage while the flat interior keeps the 1-sample value, and 1 thread bitwise 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <utility>

#include <tbb/task_arena.h>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/SupersampledReference.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

bool sameImage(const lighting::StageResult& a, const lighting::StageResult& b) {
    if (a.width != b.width || a.height != b.height)
        return false;
    for (int c = 0; c < 3; ++c)
        if (a.radiance[c].size() != b.radiance[c].size() ||
            std::memcmp(a.radiance[c].data(), b.radiance[c].data(),
                        a.radiance[c].size() * sizeof(float)) != 0)
            return false;
    return a.lightsEvaluated == b.lightsEvaluated && a.lightsOracle == b.lightsOracle;
}

scenes::Scene atrium(int lightCount) {
    scenes::SceneRequest request;
    request.lightCount = lightCount;
    request.seed = 3;
    return scenes::buildProceduralScene("atrium", request);
}

TEST(ReferenceSampleOffsets, SixteenIsTheD3dStandardPattern) {
    const int d3d[16][2] = {{1, 1},  {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5},
                            {5, 3},  {3, -5},  {-2, 6}, {0, -7}, {-4, -6}, {-6, 4},
                            {-8, 0}, {7, -4},  {6, 7},  {-7, -8}};
    const std::vector<glm::dvec2> offsets = lighting::referenceSampleOffsets(16);
    ASSERT_EQ(offsets.size(), 16u);
    for (size_t i = 0; i < 16; ++i) {
        EXPECT_EQ(offsets[i].x, d3d[i][0] / 16.0) << i;
        EXPECT_EQ(offsets[i].y, d3d[i][1] / 16.0) << i;
    }
    EXPECT_EQ(lighting::referenceSamplePattern(16), "d3d16");
}

TEST(ReferenceSampleOffsets, DistinctInsideThePixelStratifiedAndFixed) {
    for (int k = 1; k * k <= lighting::kMaxReferenceSpp; ++k) {
        const int n = k * k;
        SCOPED_TRACE(n);
        EXPECT_EQ(lighting::referenceSppProblem(n), "");
        const std::vector<glm::dvec2> offsets = lighting::referenceSampleOffsets(n);
        ASSERT_EQ(offsets.size(), size_t(n));
        EXPECT_EQ(offsets, lighting::referenceSampleOffsets(n)); // deterministic
        std::set<std::pair<double, double>> distinct;
        std::set<std::pair<int, int>> cells;
        for (const glm::dvec2& o : offsets) {
            EXPECT_GE(o.x, -0.5);
            EXPECT_LT(o.x, 0.5);
            EXPECT_GE(o.y, -0.5);
            EXPECT_LT(o.y, 0.5);
            distinct.insert({o.x, o.y});
            cells.insert({int(std::floor((o.x + 0.5) * k)), int(std::floor((o.y + 0.5) * k))});
        }
        EXPECT_EQ(distinct.size(), size_t(n));
        if (n != 16) // a stratified grid: one sample in each of the k x k cells
            EXPECT_EQ(cells.size(), size_t(n));
    }
    EXPECT_EQ(lighting::referenceSampleOffsets(1), std::vector<glm::dvec2>{glm::dvec2(0.0)});
}

TEST(ReferenceSampleOffsets, OtherCountsAreRefused) {
    for (const int n : {0, -4, 2, 8, 15, 17, 257, 289, 1024}) {
        EXPECT_NE(lighting::referenceSppProblem(n), "") << n;
        EXPECT_THROW(lighting::referenceSampleOffsets(n), std::invalid_argument) << n;
    }
}

TEST(SupersampledReference, OneSampleIsBitwiseTheReferenceStage) {
    const scenes::Scene scene = atrium(64);
    lighting::StageResult direct;
    {
        lighting::PreparedScene frame(scene, 96, 54, true);
        lighting::makeStage("reference")->shade(frame.inputs, direct);
    }
    const lighting::StageResult one = lighting::renderSupersampledReference(scene, 96, 54, 1);
    EXPECT_TRUE(sameImage(direct, one));
    const lighting::StageResult four = lighting::renderSupersampledReference(scene, 96, 54, 4);
    EXPECT_FALSE(sameImage(direct, four)); // the jitter reaches the image
    EXPECT_EQ(four.parameters.at("reference_spp"), "4");
}

TEST(SupersampledReference, OneThreadIsBitwiseTwo) {
    const scenes::Scene scene = atrium(32);
    lighting::StageResult results[2];
    for (int i = 0; i < 2; ++i)
        tbb::task_arena(i + 1).execute(
            [&] { results[i] = lighting::renderSupersampledReference(scene, 64, 36, 16); });
    EXPECT_TRUE(sameImage(results[0], results[1]));
}

// A flat Lambertian plane facing the camera (one directional light: the same radiance at every
// point), bounded on the left by a slanted edge against the background.
class HalfPlaneEdge : public ::testing::Test {
protected:
    static constexpr int kWidth = 64;
    static constexpr int kHeight = 48;
    static constexpr double kDepth = -4.0;
    // The edge, view space, in the plane z = kDepth: the plane covers x >= the line through these.
    const glm::dvec2 kEdgeBottom{-0.35, -10.0}, kEdgeTop{0.55, 10.0};

    scenes::Scene scene() const {
        scenes::Scene s;
        s.name = "half-plane";
        scenes::Mesh mesh;
        const float z = float(kDepth);
        mesh.positions = {{float(kEdgeBottom.x), float(kEdgeBottom.y), z},
                          {20.0f, -10.0f, z},
                          {20.0f, 10.0f, z},
                          {float(kEdgeTop.x), float(kEdgeTop.y), z}};
        mesh.normals.assign(4, glm::vec3(0, 0, 1));
        mesh.indices = {0, 1, 2, 0, 2, 3};
        s.meshes.push_back(mesh);
        scenes::Material material;
        material.baseColorFactor = {0.8f, 0.6f, 0.4f, 1.0f};
        material.specularIntensity = 0.0f; // Lambert only: uniform over the plane
        s.materials.push_back(material);
        s.instances.push_back({0, glm::mat4(1.0f)});
        scenes::Camera camera; // at the origin, looking down -Z
        camera.verticalFovRadians = 1.0f;
        s.cameras.push_back(camera);
        scenes::Light sun;
        sun.type = scenes::LightType::Directional;
        sun.directionWorld = glm::normalize(glm::vec3(0.2f, -0.3f, -1.0f));
        sun.intensity = 2.0f;
        s.lights.push_back(sun);
        scenes::validate(s);
        return s;
    }

    // The plane's share of pixel (x, y), by a 128 x 128 grid of points inside it: the line is
    // projected (same depth, so it stays a line) with the camera's exact matrices.
    double coverage(const gbuffer::CameraView& view, int x, int y) const {
        auto pixelOf = [&view](glm::dvec2 p) {
            const glm::dvec4 clip =
                glm::inverse(view.viewFromClipExact) * glm::dvec4(p, kDepth, 1.0);
            return glm::dvec2((clip.x / clip.w + 1.0) / 2.0 * view.width,
                              (1.0 - clip.y / clip.w) / 2.0 * view.height);
        };
        const glm::dvec2 a = pixelOf(kEdgeBottom), b = pixelOf(kEdgeTop);
        const glm::dvec2 inside = pixelOf({10.0, 0.0});
        auto side = [&](glm::dvec2 p) {
            return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
        };
        const bool insidePositive = side(inside) > 0.0;
        constexpr int kGrid = 128;
        int hits = 0;
        for (int j = 0; j < kGrid; ++j)
            for (int i = 0; i < kGrid; ++i) {
                const glm::dvec2 p(x + (i + 0.5) / kGrid, y + (j + 0.5) / kGrid);
                hits += (side(p) > 0.0) == insidePositive ? 1 : 0;
            }
        return double(hits) / (kGrid * kGrid);
    }
};

TEST_F(HalfPlaneEdge, EdgePixelsGetTheirCoverageAndTheInteriorKeepsItsValue) {
    const scenes::Scene s = scene();
    const lighting::StageResult one = lighting::renderSupersampledReference(s, kWidth, kHeight, 1);
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(s.cameras[0], kWidth, kHeight);
    // The 1-sample value of the lit plane, at a pixel far from the edge.
    const size_t interiorPixel = size_t(kHeight / 2) * kWidth + kWidth - 4;
    const float lit = one.radiance[0][interiorPixel];
    ASSERT_GT(lit, 0.0f);
    for (const int spp : {16, 64}) {
        SCOPED_TRACE(spp);
        const lighting::StageResult many =
            lighting::renderSupersampledReference(s, kWidth, kHeight, spp);
        int edgePixels = 0;
        double sumError = 0.0, maxError = 0.0;
        for (int y = 0; y < kHeight; ++y)
            for (int x = 0; x < kWidth; ++x) {
                const size_t pixel = size_t(y) * kWidth + x;
                const double share = coverage(view, x, y);
                for (int c = 0; c < 3; ++c) {
                    const float value = many.radiance[c][pixel], centre = one.radiance[c][pixel];
                    if (share == 0.0) {
                        EXPECT_EQ(value, 0.0f) << x << "," << y;
                    } else if (share == 1.0) {
                        // Every sample sees the same flat, uniformly lit surface.
                        EXPECT_NEAR(value, centre, 1e-6f * centre) << x << "," << y;
                    }
                }
                if (share == 0.0 || share == 1.0)
                    continue;
                ++edgePixels;
                const double estimate = many.radiance[0][pixel] / double(lit);
                const double error = std::abs(estimate - share);
                sumError += error;
                maxError = std::max(maxError, error);
                if (share > 0.15 && share < 0.85) { // strictly between background and surface
                    EXPECT_GT(estimate, 0.0) << x << "," << y;
                    EXPECT_LT(estimate, 1.0) << x << "," << y;
                }
                // The centre sample alone sees all or nothing.
                EXPECT_TRUE(one.radiance[0][pixel] == 0.0f || one.radiance[0][pixel] == lit);
            }
        ASSERT_GE(edgePixels, kHeight);
        const double meanError = sumError / edgePixels;
        std::printf("spp %d: %d edge pixels, coverage error mean %.4f max %.4f\n", spp, edgePixels,
                    meanError, maxError);
        EXPECT_LT(maxError, spp == 16 ? 0.125 : 0.07);
        EXPECT_LT(meanError, spp == 16 ? 0.04 : 0.025);
    }
}

} // namespace
