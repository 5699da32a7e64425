// ExplicitClusters (lighting/culling/ExplicitClusters.h) on hand-made samples: the unique-cluster
// finder (two surfaces of one tile at different depths are two clusters; one depth with two
// normal directions is one cluster without normal clustering and two with it), tight boxes that
// hold every sample and touch the extreme ones, normal cones that hold every sample normal, and
// the per-cluster light test (sphere vs box, back-face culling by the cone).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lighting/culling/ExplicitClusters.h"

namespace {

using lighting::ClusterKeying;
using lighting::ExplicitCluster;
using lighting::ExplicitClusters;

// 60-degree vertical field of view, 4 tile rows: slices grow by 1 + 2 tan(30 deg) / 4 ~ 1.29.
ClusterKeying keying(int normalDivisions) {
    ClusterKeying k;
    k.nearMetres = 0.1f;
    k.slicesPerLogDepth = float(1.0 / std::log(1.0 + 2.0 * std::tan(0.5235988) / 4.0));
    k.normalDivisions = normalDivisions;
    return k;
}

// A 16x16 image of one 16-pixel tile: the left half a wall facing the camera at depth 2 m, the
// right half one at depth `rightDepth` (facing the camera, or tilted to face +x when `tilted`).
struct TwoSurfaces {
    float rightDepth = 8.0f;
    bool tilted = false;
    bool operator()(int x, int y, glm::vec3& position, glm::vec3& normal) const {
        const bool right = x >= 8;
        const float depth = right ? rightDepth : 2.0f;
        position = {0.01f * float(x - 8) * depth, 0.01f * float(8 - y) * depth, -depth};
        normal = right && tilted ? glm::normalize(glm::vec3(1.0f, 0.0f, 0.2f))
                                 : glm::vec3(0.0f, 0.0f, 1.0f);
        return true;
    }
};

// Every sample lies in its pixel's cluster's box, and each box face touches a sample.
void expectTightBoxes(const ExplicitClusters& clusters, int width, int height,
                      const auto& sampleAt) {
    std::vector<glm::vec3> lo(clusters.clusterCount(), glm::vec3(INFINITY));
    std::vector<glm::vec3> hi(clusters.clusterCount(), glm::vec3(-INFINITY));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            glm::vec3 p, n;
            if (!sampleAt(x, y, p, n)) {
                EXPECT_EQ(clusters.clusterOfPixel(x, y), lighting::kNoCluster);
                continue;
            }
            const uint32_t c = clusters.clusterOfPixel(x, y);
            ASSERT_LT(c, clusters.clusterCount()) << x << ", " << y;
            lo[c] = glm::min(lo[c], p);
            hi[c] = glm::max(hi[c], p);
        }
    for (size_t c = 0; c < clusters.clusterCount(); ++c)
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_EQ(clusters.cluster(c).boundsView.lo[axis], lo[c][axis]) << c << " " << axis;
            EXPECT_EQ(clusters.cluster(c).boundsView.hi[axis], hi[c][axis]) << c << " " << axis;
        }
}

TEST(ExplicitClusters, TwoDepthsInOneTileAreTwoClusters) {
    const TwoSurfaces samples{8.0f, false};
    ExplicitClusters clusters;
    clusters.find(16, 16, keying(0), 16, samples);
    ASSERT_EQ(clusters.grid().tileCount(), 1);
    ASSERT_EQ(clusters.clusterCount(), 2u);
    EXPECT_NE(clusters.clusterOfPixel(0, 0), clusters.clusterOfPixel(15, 15));
    // Ascending keys: the nearer slice first.
    EXPECT_EQ(clusters.clusterOfPixel(3, 5), 0u);
    EXPECT_EQ(clusters.clusterOfPixel(12, 5), 1u);
    EXPECT_EQ(clusters.cluster(0).sampleCount, 128u);
    EXPECT_EQ(clusters.cluster(1).sampleCount, 128u);
    EXPECT_EQ(clusters.cluster(0).boundsView.lo.z, -2.0f);
    EXPECT_EQ(clusters.cluster(0).boundsView.hi.z, -2.0f);
    expectTightBoxes(clusters, 16, 16, samples);
    // Two depths within one slice stay one cluster.
    ExplicitClusters near;
    near.find(16, 16, keying(0), 16, TwoSurfaces{2.05f, false});
    EXPECT_EQ(near.clusterCount(), 1u);
}

TEST(ExplicitClusters, OneDepthTwoNormalsSplitOnlyWithNormalClustering) {
    const TwoSurfaces samples{2.0f, true};
    ExplicitClusters plain;
    plain.find(16, 16, keying(0), 16, samples);
    EXPECT_EQ(plain.clusterCount(), 1u);
    ExplicitClusters byNormal;
    byNormal.find(16, 16, keying(3), 16, samples);
    ASSERT_EQ(byNormal.clusterCount(), 2u);
    EXPECT_NE(byNormal.clusterOfPixel(0, 0), byNormal.clusterOfPixel(15, 0));
    // Each normal cluster holds one direction: a closed cone around it.
    for (size_t c = 0; c < 2; ++c)
        EXPECT_LT(byNormal.cluster(c).normalHalfAngle, 1e-3f) << c;
    // Together they need a cone of about the angle between the normals.
    EXPECT_GT(plain.cluster(0).normalHalfAngle, 0.5f);
    expectTightBoxes(byNormal, 16, 16, samples);
}

TEST(ExplicitClusters, TilesAndUncoveredPixels) {
    // 40x20 pixels, tiles of 16: 3x2 tiles, the last column and row clipped; a hole of
    // background pixels and one surface everywhere else: one cluster per covered tile.
    const auto samples = [](int x, int y, glm::vec3& p, glm::vec3& n) {
        if (x >= 16 && x < 32 && y < 16)
            return false; // tile (1, 0) wholly background
        p = {0.01f * float(x), -0.01f * float(y), -3.0f};
        n = {0.0f, 0.0f, 1.0f};
        return true;
    };
    ExplicitClusters clusters;
    clusters.find(40, 20, keying(3), 16, samples);
    EXPECT_EQ(clusters.grid().tileCount(), 6);
    EXPECT_EQ(clusters.clusterCount(), 5u);
    EXPECT_EQ(clusters.tileFirstCluster(1), 1u);
    EXPECT_EQ(clusters.tileFirstCluster(2), 1u); // tile 1 has none
    const uint32_t tiles[] = {0, 2, 3, 4, 5};    // tile by tile, row-major, tile 1 skipped
    for (size_t c = 0; c < clusters.clusterCount(); ++c)
        EXPECT_EQ(clusters.cluster(c).tile, tiles[c]) << c;
    expectTightBoxes(clusters, 40, 20, samples);
}

TEST(ExplicitClusters, NormalConeHoldsEverySampleNormal) {
    // Random normals spread over a hemisphere (and wider), positions on a rough surface.
    std::mt19937 random(11);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    for (float spread : {0.05f, 0.4f, 1.0f, 3.0f}) {
        std::vector<glm::vec3> positions(64 * 64), normals(64 * 64);
        for (size_t i = 0; i < positions.size(); ++i) {
            positions[i] = {uniform(random), uniform(random), -4.0f + uniform(random)};
            normals[i] =
                glm::normalize(glm::vec3(spread * uniform(random), spread * uniform(random), 1.0f));
            normals[i] *= 0.5f + 0.5f * std::abs(uniform(random)); // not unit: still inside
        }
        const auto samples = [&](int x, int y, glm::vec3& p, glm::vec3& n) {
            p = positions[size_t(y) * 64 + size_t(x)];
            n = normals[size_t(y) * 64 + size_t(x)];
            return true;
        };
        for (int divisions : {0, 3}) {
            ExplicitClusters clusters;
            clusters.find(64, 64, keying(divisions), 32, samples);
            ASSERT_GT(clusters.clusterCount(), 0u);
            int tested = 0;
            for (int y = 0; y < 64; ++y)
                for (int x = 0; x < 64; ++x) {
                    const ExplicitCluster& c = clusters.cluster(clusters.clusterOfPixel(x, y));
                    if (c.normalHalfAngle >= 3.0f)
                        continue; // open cone: holds everything
                    // The exact angle (double, atan2: well conditioned near 0, unlike acos of
                    // a float dot) is within the cone widened by half the back-face test's
                    // angular slack: the float error of the cone's acos (~3e-4 rad at worst,
                    // near 0) stays inside the slack the test adds, with room for the light's.
                    const glm::dvec3 axis(c.normalAxisView);
                    const glm::dvec3 n =
                        glm::normalize(glm::dvec3(normals[size_t(y) * 64 + size_t(x)]));
                    const double angle =
                        std::atan2(glm::length(glm::cross(axis, n)), glm::dot(axis, n));
                    EXPECT_LE(angle, double(c.normalHalfAngle) +
                                         0.5 * double(lighting::kBackfaceSlackRadians))
                        << "spread " << spread << " divisions " << divisions << " pixel " << x
                        << ", " << y;
                    ++tested;
                }
            EXPECT_GT(tested, 0) << spread;
            expectTightBoxes(clusters, 64, 64, samples);
        }
    }
}

TEST(ExplicitClusters, ClusterTestCullsBackFacingLightsAndKeepsFrontLights) {
    // A 1 m square wall at z = -5 facing the camera (+z); lights behind it, in front of it, one
    // beside it grazing, one unbounded.
    const std::vector<glm::vec3> positions = {
        {-0.5f, -0.5f, -5.0f}, {0.5f, 0.5f, -5.0f}, {0.5f, -0.5f, -5.0f}, {-0.5f, 0.5f, -5.0f}};
    const std::vector<glm::vec3> normals(4, glm::vec3(0.0f, 0.0f, 1.0f));
    const ExplicitCluster cluster = lighting::clusterOfSamples(positions, normals);
    EXPECT_EQ(cluster.normalHalfAngle, 0.0f);
    std::vector<lighting::LightSphere> spheres(5);
    const auto at = [](lighting::LightSphere& s, glm::vec3 p, float r) {
        s.centreView = s.positionView = p;
        s.radius = r;
    };
    at(spheres[0], {0.0f, 0.0f, -5.5f}, 2.0f); // behind: lights no sample facing +z
    at(spheres[1], {0.0f, 0.0f, -4.5f}, 2.0f); // in front
    at(spheres[2], {0.0f, 0.0f, -9.0f}, 1.0f); // behind and out of reach
    at(spheres[3], {2.0f, 0.0f, -5.0f}, 3.0f); // in the wall's plane: grazing, kept
    spheres[4].unbounded = true;
    const std::vector<uint32_t> candidates = {0, 1, 2, 3, 4};
    const lighting::ClusterCone cone = lighting::backfaceClusterCone(cluster);
    std::vector<uint32_t> list;
    EXPECT_EQ(lighting::appendClusterLights(cluster, &cone, spheres, candidates, list), 1u);
    EXPECT_EQ(list, (std::vector<uint32_t>{1, 3, 4}));
    list.clear();
    EXPECT_EQ(lighting::appendClusterLights(cluster, nullptr, spheres, candidates, list), 0u);
    EXPECT_EQ(list, (std::vector<uint32_t>{0, 1, 3, 4}));
}

// The cone's float arc cosine can be narrower than the true cone: two unit normals 1.5e-4 rad
// either side of +z have float dot 1 with the axis, so the cone's half-angle is 0. A light
// 1e-4 rad behind the samples' plane (seen from them) still lights the sample whose normal
// leans towards it (dot > 0, checked in double); the back-face test's angular slack
// (kBackfaceSlackRadians) is what keeps it.
TEST(ExplicitClusters, ConeSlackKeepsAGrazingLightTheFloatConeMisses) {
    const double tilt = 1.5e-4;
    const std::vector<glm::vec3> positions(2, glm::vec3(0.0f, 0.0f, -5.0f));
    const std::vector<glm::vec3> normals = {
        glm::vec3(float(-std::sin(tilt)), 0.0f, float(std::cos(tilt))),
        glm::vec3(float(std::sin(tilt)), 0.0f, float(std::cos(tilt)))};
    const ExplicitCluster cluster = lighting::clusterOfSamples(positions, normals);
    ASSERT_EQ(cluster.normalHalfAngle, 0.0f); // the float cone, narrower than the true one
    lighting::LightSphere light;
    light.centreView = light.positionView = {1.0f, 0.0f, -5.0f - 1e-4f};
    light.radius = 2.0f;
    const glm::dvec3 toLight = glm::dvec3(light.positionView) - glm::dvec3(positions[1]);
    ASSERT_GT(glm::dot(glm::dvec3(normals[1]), toLight), 0.0); // it lights sample 1
    const lighting::ClusterCone cone = lighting::backfaceClusterCone(cluster);
    std::vector<uint32_t> list;
    const std::vector<lighting::LightSphere> spheres = {light};
    const std::vector<uint32_t> candidates = {0};
    EXPECT_EQ(lighting::appendClusterLights(cluster, &cone, spheres, candidates, list), 0u);
    EXPECT_EQ(list, std::vector<uint32_t>{0});
}

TEST(ExplicitClusters, KeysFollowThePapersSlices) {
    const ClusterKeying k = keying(0);
    // Slice k starts at near * (1 + 2 tan(theta) / S_y)^k.
    const double ratio = 1.0 + 2.0 * std::tan(0.5235988) / 4.0;
    for (int slice : {0, 1, 5, 20}) {
        const double start = 0.1 * std::pow(ratio, slice);
        EXPECT_EQ(k.sliceOfDepth(float(start * 1.001)), uint32_t(slice));
        EXPECT_EQ(k.sliceOfDepth(float(start * ratio * 0.999)), uint32_t(slice));
    }
    EXPECT_EQ(k.sliceOfDepth(0.01f), 0u); // in front of near
    EXPECT_EQ(k.sliceOfDepth(INFINITY), lighting::kMaxExplicitSlice);
    const ClusterKeying n = keying(3);
    EXPECT_EQ(n.normalBins(), 55u);
    EXPECT_NE(n.normalBin({0, 0, 1}), n.normalBin({0, 0, -1}));
    EXPECT_NE(n.normalBin({0, 0, 1}), n.normalBin({1, 0, 0}));
    EXPECT_EQ(n.normalBin({0, 0, 1}), n.normalBin({0.01f, -0.01f, 1}));
    EXPECT_EQ(n.normalBin({0, 0, 0}), 54u);
}

} // namespace
