// The kernel's vector shadow lookup (lighting/kernel/VectorShadows-inl.h) against its oracle, the
// scalar ShadowMaps::visibility: bitwise equal on every lane, on every compiled vector target this
// CPU runs, for maps rendered from a small scene (a ground, boxes, a pole) with
//   - a spot light, a point light (cube map; also points placed exactly on the cube's seams, where
//     two or three world axes tie and the lanes of one vector fall on different faces), and a
//     directional light with 1 and 4 cascades (points spread over the view depth range, so lanes
//     fall on different cascades);
//   - every filter (none, pcf3, pcf5, poisson), normal offset 0 and 1.5 texels;
//   - random points (on the ground, on box tops and in the air) with unit, non-unit, zero and
//     grazing normals, random lane masks (lanes outside them read 1), and non-finite inputs (1).
// Each case must also see shadowed, lit and partly lit lanes, so that the comparison is not
// between two constant answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/kernel/VectorTargets.h"
#include "lighting/shadows/ShadowMaps.h"
#include "scenes/Scene.h"
#include "scenes/mesh/MeshBuilder.h"

namespace {

using lighting::ShadowFilter;
using lighting::ShadowMaps;
using lighting::ShadowSettings;
using lighting::kernel::kPacketLanes;
using lighting::kernel::ShadingPacket;
using lighting::kernel::ShadowVisibilityArgs;
using scenes::Light;
using scenes::LightType;

// Camera at kCamera looking down world -Z with +Y up: view space is world space shifted by
// -kCamera, with no rotation, so a point whose view-space offset from a light has two equal
// components lies exactly on a cube seam in world space too.
const glm::vec3 kCamera(0.0f, 3.0f, 14.0f);
const glm::vec3 kPointLight(1.0f, 4.0f, -1.0f);

scenes::Scene makeScene(const Light& light) {
    scenes::Scene scene;
    scene.name = "vector-shadows";
    scene.materials.emplace_back();
    auto mesh = [&]() -> scenes::Mesh& {
        scene.meshes.emplace_back();
        scene.instances.push_back({uint32_t(scene.meshes.size() - 1), glm::mat4(1.0f)});
        return scene.meshes.back();
    };
    scenes::appendQuad(mesh(), {-10.0f, 0.0f, 10.0f}, {20.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -20.0f}, 4,
                       4);
    auto box = [&](const glm::vec3& lo, const glm::vec3& hi) {
        scenes::Aabb b;
        b.min = lo;
        b.max = hi;
        scenes::appendBox(mesh(), b, 1e6f);
    };
    box({-1.0f, 0.0f, -2.0f}, {0.5f, 1.5f, 0.0f});
    box({2.0f, 0.0f, 1.0f}, {3.0f, 2.5f, 2.0f});
    box({-4.0f, 0.0f, 3.0f}, {-3.8f, 3.0f, 3.2f});   // a pole
    box({-3.0f, 2.0f, -4.0f}, {-1.5f, 2.3f, -2.5f}); // a floating slab
    scenes::Camera camera;
    camera.positionWorld = kCamera;
    camera.forwardWorld = {0.0f, 0.0f, -1.0f};
    camera.upWorld = {0.0f, 1.0f, 0.0f};
    camera.verticalFovRadians = glm::radians(60.0f);
    camera.nearMetres = 0.1f;
    camera.farMetres = 60.0f;
    scene.cameras = {camera};
    Light copy = light;
    copy.castsShadows = true;
    scene.lights = {copy};
    return scene;
}

Light pointLight() {
    Light l;
    l.type = LightType::Point;
    l.positionWorld = kPointLight;
    l.rangeMetres = 12.0f;
    return l;
}

Light spotLight() {
    Light l;
    l.type = LightType::Spot;
    l.positionWorld = {-2.0f, 6.0f, 4.0f};
    l.directionWorld = glm::normalize(glm::vec3(0.3f, -1.0f, -0.5f));
    l.rangeMetres = 15.0f;
    l.spotOuterCos = std::cos(glm::radians(50.0f));
    l.spotInnerCos = std::cos(glm::radians(40.0f));
    return l;
}

Light directionalLight() {
    Light l;
    l.type = LightType::Directional;
    l.directionWorld = glm::normalize(glm::vec3(0.4f, -1.0f, -0.3f));
    return l;
}

struct Frame {
    scenes::Scene scene;
    gbuffer::SceneGeometry geometry;
    gbuffer::CameraView view;
    ShadowMaps maps;
    Frame(const Light& light, const ShadowSettings& settings)
        : scene(makeScene(light)), geometry(gbuffer::SceneGeometry::build(scene)),
          view(gbuffer::CameraView::fromCamera(scene.cameras[0], 320, 240)),
          maps(ShadowMaps::render(scene, geometry, view, settings)) {}
};

struct Lane {
    glm::vec3 positionView;
    glm::vec3 normalView;
};

// Random receivers in view space: on the ground (normal up), on box tops and sides, in the air,
// with unit, non-unit, zero, grazing and random normals; a few non-finite ones.
std::vector<Lane> randomLanes(std::mt19937& random, size_t count) {
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), u01(0.0f, 1.0f);
    std::vector<Lane> lanes;
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (size_t i = 0; i < count; ++i) {
        glm::vec3 world(8.0f * unit(random), 0.0f, 8.0f * unit(random));
        glm::vec3 normal(0.0f, 1.0f, 0.0f);
        switch (random() % 10) {
        case 0: // in the air, random normal
            world.y = 4.0f * u01(random);
            normal = glm::vec3(unit(random), unit(random), unit(random));
            break;
        case 1: // a box top
            world = {-1.0f + 1.5f * u01(random), 1.5f, -2.0f + 2.0f * u01(random)};
            break;
        case 2: // a box side, facing +X
            world = {3.0f, 2.5f * u01(random), 1.0f + u01(random)};
            normal = {1.0f, 0.0f, 0.0f};
            break;
        case 3: // non-unit normal
            normal = glm::vec3(0.2f * unit(random), 3.0f, 0.2f * unit(random));
            break;
        case 4: // no normal
            normal = glm::vec3(0.0f);
            break;
        case 5: // grazing: the normal almost in the ground plane
            normal = glm::normalize(glm::vec3(unit(random), 0.02f, unit(random)));
            break;
        case 6: // far away (directional cascades, outside a point light's range)
            world.z = -40.0f * u01(random);
            world.x *= 2.0f;
            break;
        case 7: // a non-finite component now and then
            if (random() % 4 == 0)
                (random() % 2 ? world.x : normal.z) = random() % 2 ? nan : inf;
            break;
        default:
            break;
        }
        lanes.push_back({world - kCamera, normal});
    }
    return lanes;
}

// Points on the point light's cube seams: offsets from the light with two or three components
// of equal magnitude (exact in float and double, view = world rotation), normals random.
std::vector<Lane> seamLanes(std::mt19937& random, size_t count) {
    std::uniform_int_distribution<int> eighths(1, 40), sign(0, 1);
    std::vector<Lane> lanes;
    const glm::vec3 lightView = kPointLight - kCamera;
    for (size_t i = 0; i < count; ++i) {
        const float s = float(eighths(random)) / 8.0f;
        const float t = float(eighths(random) % int(s * 8.0f + 1.0f)) / 8.0f; // |t| <= s
        glm::vec3 offset;
        switch (random() % 4) {
        case 0:
            offset = {s, s, t};
            break;
        case 1:
            offset = {s, t, s};
            break;
        case 2:
            offset = {t, s, s};
            break;
        default:
            offset = {s, s, s};
            break;
        }
        for (int k = 0; k < 3; ++k)
            offset[k] *= sign(random) ? -1.0f : 1.0f;
        const glm::vec3 normal = random() % 3 == 0 ? glm::vec3(0.0f, 1.0f, 0.0f)
                                                   : glm::vec3(float(sign(random)) - 0.5f, 1.0f,
                                                               0.25f * float(eighths(random)));
        lanes.push_back({lightView + offset, normal});
    }
    return lanes;
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

struct Tally {
    size_t compared = 0, shadowed = 0, lit = 0, partial = 0;
};

// Every lane of `lanes`, in packets, through every supported target's vector lookup with random
// lane masks, against maps.visibility.
Tally compareAllTargets(const ShadowMaps& maps, const std::vector<Lane>& lanes,
                        std::mt19937& random, const std::string& label) {
    Tally tally;
    const uint32_t shadow = maps.shadowOf(0);
    EXPECT_NE(shadow, ShadowMaps::kNoShadow);
    const auto& targets = lighting::kernel::supportedVectorTargets();
    EXPECT_FALSE(targets.empty());
    for (size_t first = 0; first < lanes.size(); first += kPacketLanes) {
        ShadingPacket packet{};
        float expected[kPacketLanes];
        for (size_t l = 0; l < kPacketLanes; ++l) {
            const Lane& lane = lanes[std::min(first + l, lanes.size() - 1)];
            for (int k = 0; k < 3; ++k) {
                packet.positionView[k][l] = lane.positionView[k];
                packet.normalView[k][l] = lane.normalView[k];
            }
            expected[l] = maps.visibility(shadow, lane.positionView, lane.normalView);
        }
        // Every other packet: a random lane mask (the kernel asks only where a light passes).
        const uint32_t laneMask = (first / kPacketLanes) % 2 == 0 ? 0xffffu : random() & 0xffffu;
        for (const lighting::kernel::VectorFunctions* target : targets) {
            float visibility[kPacketLanes];
            target->shadowVisibility(
                ShadowVisibilityArgs{maps.view(), shadow, &packet, laneMask, visibility});
            for (size_t l = 0; l < kPacketLanes; ++l) {
                const float want = laneMask >> l & 1u ? expected[l] : 1.0f;
                EXPECT_TRUE(sameBits(visibility[l], want))
                    << label << " target " << target->name << " lane " << first + l << ": vector "
                    << visibility[l] << " scalar " << want << " at (" << packet.positionView[0][l]
                    << ", " << packet.positionView[1][l] << ", " << packet.positionView[2][l]
                    << ") normal (" << packet.normalView[0][l] << ", " << packet.normalView[1][l]
                    << ", " << packet.normalView[2][l] << ")";
            }
        }
        for (size_t l = 0; l < kPacketLanes; ++l) {
            ++tally.compared;
            tally.shadowed += expected[l] == 0.0f;
            tally.lit += expected[l] == 1.0f;
            tally.partial += expected[l] > 0.0f && expected[l] < 1.0f;
        }
    }
    return tally;
}

const ShadowFilter kFilters[] = {ShadowFilter::None, ShadowFilter::Pcf3, ShadowFilter::Pcf5,
                                 ShadowFilter::Poisson};

struct LightCase {
    const char* name;
    Light light;
    int cascades;
};

class VectorShadows : public ::testing::TestWithParam<LightCase> {};

TEST_P(VectorShadows, EqualTheScalarLookupBitwiseOnEveryTarget) {
    const LightCase& c = GetParam();
    for (const lighting::ShadowDepthFormat format :
         {lighting::ShadowDepthFormat::Float32, lighting::ShadowDepthFormat::Unorm16})
        for (ShadowFilter filter : kFilters)
            for (float normalOffset : {0.0f, 1.5f}) {
                ShadowSettings settings;
                // Unorm16: an odd size, so that texels sit in both halves of a word on every row.
                settings.mapSize = format == lighting::ShadowDepthFormat::Unorm16 ? 255 : 256;
                settings.filter = filter;
                settings.normalOffset = normalOffset;
                settings.cascades = c.cascades;
                settings.depthFormat = format;
                const Frame frame(c.light, settings);
                ASSERT_EQ(frame.maps.shadowCount(), 1u);
                const std::string label = std::string(c.name) + " " +
                                          lighting::formatShadowDepthFormat(format) + " " +
                                          lighting::formatShadowFilter(filter) + " normal offset " +
                                          std::to_string(normalOffset);
                std::mt19937 random(1234);
                const Tally tally =
                    compareAllTargets(frame.maps, randomLanes(random, 4096), random, label);
                // Not two constant answers: shadowed, lit and (with a filter) partly lit lanes.
                EXPECT_GT(tally.shadowed, tally.compared / 50) << label;
                EXPECT_GT(tally.lit, tally.compared / 10) << label;
                if (filter != ShadowFilter::None)
                    EXPECT_GT(tally.partial, tally.compared / 200) << label;
                if (c.light.type == LightType::Point) {
                    const Tally seams = compareAllTargets(frame.maps, seamLanes(random, 2048),
                                                          random, label + " seams");
                    EXPECT_GT(seams.shadowed + seams.partial, 0u) << label;
                }
            }
}

INSTANTIATE_TEST_SUITE_P(Lights, VectorShadows,
                         ::testing::Values(LightCase{"spot", spotLight(), 1},
                                           LightCase{"point", pointLight(), 1},
                                           LightCase{"directional", directionalLight(), 1},
                                           LightCase{"directional4", directionalLight(), 4}),
                         [](const auto& info) { return std::string(info.param.name); });

// The seam lanes do what they are for: the view has no rotation (so world offsets are exact), and
// a packet of them spans several cube faces.
TEST(VectorShadows, SeamLanesSpanSeveralCubeFaces) {
    const Frame frame(pointLight(), ShadowSettings{});
    const glm::dmat4& m = frame.view.viewFromWorldExact;
    for (int column = 0; column < 3; ++column)
        for (int row = 0; row < 3; ++row)
            ASSERT_EQ(m[column][row], column == row ? 1.0 : 0.0);
    std::mt19937 random(99);
    const glm::vec3 lightView = kPointLight - kCamera;
    int ties = 0;
    for (const Lane& lane : seamLanes(random, 256)) {
        const glm::vec3 a = glm::abs(lane.positionView - lightView);
        ties += (a.x == a.y) + (a.y == a.z) + (a.x == a.z) > 0 ? 1 : 0;
    }
    EXPECT_EQ(ties, 256);
}

// What the vector lookup does not model goes to the scalar lookup: dual-paraboloid faces and a
// light's own settings (scenes::LightShadow) differing from the frame's. The kernel reads
// ShadowView::scalarOnly (LightKernel-inl.h, chunkVisibility); cube maps and per-light settings
// equal to the frame's stay on the vector path.
TEST(VectorShadows, ParaboloidFacesAndOwnSettingsTakeTheScalarLookup) {
    ShadowSettings cube;
    cube.mapSize = 128;
    EXPECT_FALSE(Frame(pointLight(), cube).maps.view()->shadows[0].scalarOnly);
    ShadowSettings paraboloid = cube;
    paraboloid.pointProjection = lighting::ShadowPointProjection::DualParaboloid;
    EXPECT_TRUE(Frame(pointLight(), paraboloid).maps.view()->shadows[0].scalarOnly);
    Light same = spotLight();
    same.shadow.mapSize = cube.mapSize;
    EXPECT_FALSE(Frame(same, cube).maps.view()->shadows[0].scalarOnly);
    Light own = spotLight();
    own.shadow.filter = ShadowFilter::Pcf5;
    EXPECT_TRUE(Frame(own, cube).maps.view()->shadows[0].scalarOnly);
    own.shadow = {};
    own.shadow.mapSize = 64;
    EXPECT_TRUE(Frame(own, cube).maps.view()->shadows[0].scalarOnly);
}

} // namespace
