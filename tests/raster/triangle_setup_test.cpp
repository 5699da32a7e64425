// Triangle set-up's planes on SIMD lanes (raster/TriangleSetup.h, setUpPlanes) against the scalar
// oracle (setUpPlanesScalar, RasterState::scalarSetup):
// - the packets directly: seeded random triangles of every size from sub-pixel to beyond the
//   screen, w from 1e-3 to 1e4, degenerate before snapping but not after (the snapped fallback),
//   every packet count from 1 to kSetupPacketSize, with and without barycentrics, on every
//   instruction set Highway compiled that this CPU runs: the depth planes and the barycentric
//   planes must be bitwise equal;
// - whole draws: the rasterizer's seven kinds of random triangles (clipped, beyond the guard band,
//   degenerate, grazing, sub-pixel) and a fan, every cull mode, 1 and 4 samples, with the
//   barycentrics: the same fragments in the same order per tile (position, triangle, facing,
//   coverage, depth and barycentrics bitwise), the depth buffer bitwise and every statistic
//   equal, for 1 and 2 threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <hwy/targets.h>
#include <tbb/task_arena.h>

#include "raster/Rasterizer.h"
#include "raster/TriangleSetup.h"
#include "tests/raster/DrawRecording.h"
#include "tests/raster/TestMeshes.h"

namespace {

using raster::kSetupPacketSize;
using raster::SetupPacket;

template <class T> uint64_t bitsOf(T value) {
    uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof value);
    return bits;
}

// A random packet of `count` triangles as the rasterizer fills it: snapped coordinates consistent
// with the clip positions (8 sub-pixel bits) except for the degenerate kind, whose unsnapped
// vertices are collinear while the snapped ones are not.
SetupPacket randomPacket(std::mt19937& rng, int count, int width, int height) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    SetupPacket packet{};
    packet.count = count;
    for (int lane = 0; lane < count; ++lane) {
        // The rasterizer sets up only triangles whose snapped area is not zero: redraw others.
        auto snappedArea = [&] {
            return (packet.snappedX[1][lane] - packet.snappedX[0][lane]) *
                       (packet.snappedY[2][lane] - packet.snappedY[0][lane]) -
                   (packet.snappedY[1][lane] - packet.snappedY[0][lane]) *
                       (packet.snappedX[2][lane] - packet.snappedX[0][lane]);
        };
        do {
            const int kind = int(rng() % 4);
            const double size = kind == 0 ? 1e-3 : kind == 1 ? 0.05 : 2.5; // NDC extent
            const double centreX = unit(rng) * 2.0 - 1.0, centreY = unit(rng) * 2.0 - 1.0;
            double minX = 1e30, minY = 1e30;
            for (int i = 0; i < 3; ++i) {
                const double w = std::pow(10.0, unit(rng) * 7.0 - 3.0);
                double ndcX = centreX + size * (unit(rng) - 0.5);
                double ndcY = centreY + size * (unit(rng) - 0.5);
                if (kind == 3 && i == 2) { // on the line through the first two vertices
                    const double t = unit(rng);
                    ndcX = (1.0 - t) * (packet.clipX[0][lane] / packet.clipW[0][lane]) +
                           t * (packet.clipX[1][lane] / packet.clipW[1][lane]);
                    ndcY = (1.0 - t) * (packet.clipY[0][lane] / packet.clipW[0][lane]) +
                           t * (packet.clipY[1][lane] / packet.clipW[1][lane]);
                }
                packet.clipW[i][lane] = double(float(w));
                packet.clipX[i][lane] = double(float(ndcX * w));
                packet.clipY[i][lane] = double(float(ndcY * w));
                packet.clipZ[i][lane] = double(float(unit(rng) * w));
                const double screenX = (ndcX + 1.0) * 0.5 * width;
                const double screenY = (1.0 - ndcY) * 0.5 * height;
                // The degenerate kind's snapped vertex 2 is moved off the line by a sub-pixel step.
                packet.snappedX[i][lane] =
                    std::round(screenX * 256.0) + (kind == 3 && i == 2 ? 3 : 0);
                packet.snappedY[i][lane] = std::round(screenY * 256.0);
                minX = std::min(minX, std::floor(screenX));
                minY = std::min(minY, std::floor(screenY));
            }
            packet.minX[lane] = std::max(0.0, minX);
            packet.minY[lane] = std::max(0.0, minY);
        } while (snappedArea() == 0.0);
    }
    return packet;
}

// Whether a lane is degenerate before snapping, so that its planes come from the snapped
// positions (the condition of TriangleSetup.cpp): counted only, to show the branch is exercised.
bool takesSnappedPositions(const SetupPacket& p, int lane, const raster::SetupViewport& viewport) {
    double x[3], y[3];
    for (int i = 0; i < 3; ++i) {
        x[i] = (p.clipX[i][lane] / p.clipW[i][lane] + 1.0) * 0.5 * viewport.width;
        y[i] = (1.0 - p.clipY[i][lane] / p.clipW[i][lane]) * 0.5 * viewport.height;
    }
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    const double snapped =
        ((p.snappedX[1][lane] - p.snappedX[0][lane]) * (p.snappedY[2][lane] - p.snappedY[0][lane]) -
         (p.snappedY[1][lane] - p.snappedY[0][lane]) *
             (p.snappedX[2][lane] - p.snappedX[0][lane])) /
        65536.0;
    return !(area > 1e-6 * snapped);
}

TEST(TriangleSetup, VectorPlanesAreBitwiseTheScalarOnesOnEveryTarget) {
    const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
    ASSERT_FALSE(targets.empty());
    for (int64_t target : targets) {
        // Dispatch to this target only (the mock is lifted at the end of the loop).
        hwy::SetSupportedTargetsForTest(target);
        SCOPED_TRACE(hwy::TargetName(target));
        std::mt19937 rng(7);
        int lanesChecked = 0, degenerateLanes = 0;
        for (int round = 0; round < 400; ++round) {
            const int count = 1 + round % kSetupPacketSize;
            const raster::SetupViewport viewport{1280 - round % 3, 720 + round % 5, round % 2 == 0};
            SetupPacket vector = randomPacket(rng, count, viewport.width, viewport.height);
            SetupPacket scalar = vector;
            raster::setUpPlanes(vector, viewport);
            raster::setUpPlanesScalar(scalar, viewport);
            for (int lane = 0; lane < count; ++lane) {
                const std::string where =
                    "round " + std::to_string(round) + ", lane " + std::to_string(lane);
                for (int k = 0; k < 3; ++k) {
                    ASSERT_EQ(bitsOf(vector.z[k][lane]), bitsOf(scalar.z[k][lane]))
                        << where << ", z[" << k << "] " << vector.z[k][lane] << " against "
                        << scalar.z[k][lane];
                    if (!viewport.barycentrics)
                        continue;
                    ASSERT_EQ(bitsOf(vector.l1[k][lane]), bitsOf(scalar.l1[k][lane]))
                        << where << ", l1[" << k << "]";
                    ASSERT_EQ(bitsOf(vector.l2[k][lane]), bitsOf(scalar.l2[k][lane]))
                        << where << ", l2[" << k << "]";
                }
                EXPECT_TRUE(std::isfinite(vector.z[0][lane]) && std::isfinite(vector.z[1][lane]) &&
                            std::isfinite(vector.z[2][lane]))
                    << where;
                degenerateLanes += takesSnappedPositions(vector, lane, viewport);
                ++lanesChecked;
            }
        }
        EXPECT_EQ(lanesChecked, 400 * (kSetupPacketSize + 1) / 2);
        // The snapped fallback was exercised (the degenerate kind is a quarter of the lanes).
        EXPECT_GT(degenerateLanes, lanesChecked / 8);
    }
    hwy::SetSupportedTargetsForTest(0);
}

constexpr int kWidth = 301, kHeight = 203; // several tiles, partial ones at the edges

raster_test::RecordedDraw draw(const raster_test::Mesh& mesh, const raster::RasterState& state,
                               int threads) {
    raster_test::RecordedDraw drawn;
    drawn.depth.assign(size_t(kWidth) * kHeight * size_t(state.samples), 1.0f);
    tbb::task_arena(threads).execute([&] {
        raster::Rasterizer rasterizer(kWidth, kHeight);
        drawn.fragmentsPerTile.resize(size_t(rasterizer.tileCountX() * rasterizer.tileCountY()));
        rasterizer.draw(raster::TriangleList{mesh.positions, mesh.indices}, state,
                        drawn.depth.data(), [&](const raster::Fragment& f) {
                            drawn.fragmentsPerTile[size_t(rasterizer.tileOf(f.x, f.y))].push_back(
                                raster_test::RecordedFragment::of(f));
                        });
        drawn.stats = rasterizer.lastStats();
    });
    return drawn;
}

TEST(TriangleSetup, DrawsAreBitwiseTheScalarSetUpsForEveryCullModeSampleCountAndThreadCount) {
    const raster_test::Mesh mesh = raster_test::randomMesh(41, 1500);
    for (raster::CullMode cull :
         {raster::CullMode::None, raster::CullMode::Back, raster::CullMode::Front})
        for (int samples : {1, 4}) {
            raster::RasterState state;
            state.cullMode = cull;
            state.samples = samples;
            state.scalarSetup = true;
            const raster_test::RecordedDraw reference = draw(mesh, state, 1);
            state.scalarSetup = false;
            const std::string name =
                "cull " + std::to_string(int(cull)) + ", " + std::to_string(samples) + " samples";
            EXPECT_GT(reference.stats.trianglesClipped, 50u) << name;
            EXPECT_GT(reference.stats.trianglesSetUp, 300u) << name;
            for (int threads : {1, 2})
                raster_test::expectSameDraw(draw(mesh, state, threads), reference,
                                            name + ", " + std::to_string(threads) + " threads");
        }
}

} // namespace
