// The visibility buffer as a layout of its own (`--layout visibility`, GBufferLayout.h): depth and
// the visible triangle's code, 8 bytes per pixel, every other channel fetched from the triangle
// where a stage decodes the pixel. It must be exact against the G-buffer path: every decoded
// surface bitwise the lossless layout's (atrium, and DamagedHelmet with its metallic-roughness,
// normal, occlusion and emissive textures), and every stage's image and light counts bitwise the
// ones it gives on its derived layout, with and without 4x MSAA. A read after the pass has moved
// on to another frame must throw, not fetch another frame's triangles.
#include <gtest/gtest.h>

#include <cctype>
#include <cstring>
#include <map>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gbuffer/GBufferPass.h"
#include "gbuffer/LayoutDerivation.h"
#include "lighting/MultisampleShading.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/SceneLoader.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

using gbuffer::Channel;

const std::vector<Channel> kEverything = {Channel::Depth, Channel::Normal, Channel::Albedo,
                                          Channel::Specular, Channel::Emission};

// Loaded once per name and light count: decoding the helmet's textures dominates the suite's time
// (several times over under the sanitizers), and every case may share the scene.
const scenes::Scene& sceneNamed(const std::string& name, int lights) {
    static std::map<std::pair<std::string, int>, scenes::Scene> cache;
    const auto key = std::make_pair(name, lights);
    if (const auto found = cache.find(key); found != cache.end())
        return found->second;
    scenes::SceneRequest request;
    request.lightCount = lights;
    request.seed = 5;
    return cache[key] = name == "helmet"
                            ? scenes::loadScene(
                                  TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", request)
                            : scenes::buildProceduralScene(name, request);
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(VisibilityLayout, IsDepthAndATriangleCodeAndProvidesEveryChannel) {
    const scenes::Scene& scene = sceneNamed("helmet", 4);
    const gbuffer::GBufferLayout layout = gbuffer::presetLayout("visibility", scene);
    EXPECT_TRUE(layout.visibilityBuffer);
    EXPECT_DOUBLE_EQ(layout.bytesPerPixel(), 8.0);
    EXPECT_DOUBLE_EQ(layout.allocatedBytesPerPixel(), 8.0);
    const std::vector<gbuffer::PlaneDesc> planes = layout.planes();
    ASSERT_EQ(planes.size(), 2u);
    EXPECT_EQ(planes[0].name, "Z");
    EXPECT_EQ(planes[1].name, "triangle");
    for (Channel channel : kEverything)
        EXPECT_TRUE(layout.provides(channel)) << gbuffer::channelName(channel);
    // The derived layout of a stage that reads everything stores far more on this model.
    EXPECT_GT(gbuffer::deriveLayout(scene, kEverything).bytesPerPixel(), 20.0);
    // Overrides: depth applies (position still comes from it), normals cannot.
    gbuffer::LayoutRequest request;
    request.preset = "visibility";
    request.depth = gbuffer::DepthFormatSpec{gbuffer::DepthFormatKind::Unorm24, false};
    EXPECT_DOUBLE_EQ(gbuffer::makeLayout(scene, kEverything, "brute", request).bytesPerPixel(),
                     7.0);
    request.depth.reset();
    request.normals = gbuffer::NormalCodecSpec{gbuffer::NormalCodecKind::Octahedral, 24};
    EXPECT_THROW(gbuffer::makeLayout(scene, kEverything, "brute", request), std::invalid_argument);
    EXPECT_NE(layout.explain().find("triangle"), std::string::npos);
}

// Every covered pixel's decoded surface is bitwise the reference layout's (float32 everything,
// the scene's material channels added losslessly), and decodeRun gives decode's surfaces.
TEST(VisibilityLayout, DecodesBitwiseTheLosslessLayoutsSurfaces) {
    for (const std::string name : {"atrium", "helmet", "glass"}) {
        SCOPED_TRACE(name);
        const scenes::Scene& scene = sceneNamed(name, 8);
        lighting::PreparedScene fetched(scene, 192, 108, false,
                                        gbuffer::presetLayout("visibility", scene));
        lighting::PreparedScene stored(scene, 192, 108, false,
                                       gbuffer::presetLayout("reference", scene));
        const gbuffer::GBuffer& a = *fetched.gbuffer;
        const gbuffer::GBuffer& b = *stored.gbuffer;
        ASSERT_TRUE(a.layout().visibilityBuffer);
        int covered = 0, failures = 0;
        for (int y = 0; y < a.height(); ++y) {
            std::vector<gbuffer::Surface> run(size_t(a.width()));
            std::vector<int> runCovered(size_t(a.width()), 0);
            a.decodeRun(0, a.width(), y, [&](int x, const gbuffer::Surface& s) {
                run[size_t(x)] = s;
                runCovered[size_t(x)] = 1;
            });
            for (int x = 0; x < a.width(); ++x) {
                const size_t pixel = size_t(y) * size_t(a.width()) + size_t(x);
                ASSERT_EQ(a.covered(pixel), b.covered(pixel)) << x << ", " << y;
                ASSERT_EQ(runCovered[size_t(x)] != 0, a.covered(pixel));
                if (!a.covered(pixel))
                    continue;
                ++covered;
                const gbuffer::Surface sa = a.decode(x, y), sb = b.decode(x, y);
                // The parameters of the models the scene uses (a Blinn-Phong scene's reference
                // layout stores no roughness: it decodes a default no stage reads).
                std::vector<std::pair<float, float>> values;
                if (b.layout().specular != gbuffer::SpecularEncoding::None) {
                    values.push_back({sa.specularIntensity, sb.specularIntensity});
                    values.push_back({sa.specularPower, sb.specularPower});
                }
                if (b.layout().roughnessMetallic != gbuffer::RoughnessMetallicEncoding::None) {
                    values.push_back({sa.roughness, sb.roughness});
                    values.push_back({sa.metallic, sb.metallic});
                }
                for (int c = 0; c < 3; ++c) {
                    values.push_back({sa.positionView[c], sb.positionView[c]});
                    values.push_back({sa.normalView[c], sb.normalView[c]});
                    values.push_back({sa.albedo[c], sb.albedo[c]});
                    values.push_back({sa.emissive[c], sb.emissive[c]});
                    values.push_back({a.emission(pixel)[c], b.emission(pixel)[c]});
                    values.push_back({run[size_t(x)].normalView[c], sa.normalView[c]});
                    values.push_back({run[size_t(x)].positionView[c], sa.positionView[c]});
                    values.push_back({run[size_t(x)].albedo[c], sa.albedo[c]});
                }
                std::string differing = sa.model == sb.model ? "" : " model";
                for (size_t i = 0; i < values.size(); ++i)
                    if (!sameBits(values[i].first, values[i].second))
                        differing += " value " + std::to_string(i) + " (" +
                                     std::to_string(values[i].first) + " vs " +
                                     std::to_string(values[i].second) + ")";
                if (!differing.empty() && failures++ < 5)
                    ADD_FAILURE() << "pixel (" << x << ", " << y << ") differs:" << differing;
            }
        }
        EXPECT_GT(covered, a.width() * a.height() / 20);
        EXPECT_EQ(failures, 0);
    }
}

TEST(VisibilityLayout, ReadingAfterThePassMovedOnThrows) {
    const scenes::Scene& scene = sceneNamed("atrium", 4);
    const gbuffer::GBufferLayout layout = gbuffer::presetLayout("visibility", scene);
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(scene.cameras.front(), 64, 36);
    gbuffer::GBuffer unfilled(layout, view);
    const gbuffer::SceneGeometry geometry = gbuffer::SceneGeometry::build(scene);
    gbuffer::GBufferPass pass(scene, geometry);
    raster::Rasterizer rasterizer(64, 36);
    gbuffer::GBuffer first(layout, view), second(layout, view);
    pass.render(rasterizer, first);
    int x = 0, y = 0;
    while (!first.covered(size_t(y) * 64 + size_t(x)))
        if (++x == 64) {
            x = 0;
            ASSERT_LT(++y, 36);
        }
    EXPECT_NO_THROW(first.decode(x, y));
    pass.render(rasterizer, second);
    EXPECT_THROW(first.decode(x, y), std::logic_error);
    EXPECT_THROW(first.emission(size_t(y) * 64 + size_t(x)), std::logic_error);
    EXPECT_NO_THROW(second.decode(x, y));
    EXPECT_THROW(unfilled.decodeRun(0, 64, y, [](int, const gbuffer::Surface&) {}),
                 std::logic_error);
    // A layout that stores its planes fetches from nothing.
    gbuffer::GBuffer planes(gbuffer::presetLayout("reference", scene), view);
    EXPECT_THROW(planes.fetchSurfacesFrom(gbuffer::VisibilityPass{}), std::logic_error);
}

struct StageCase {
    std::string stage;
    std::string scene;
    int samples;
};

std::vector<StageCase> stageCases() {
    std::vector<StageCase> cases;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        for (const char* scene : {"atrium", "helmet"})
            for (int samples : {1, 4})
                if (samples == 1 || info.msaaRefusal.empty())
                    cases.push_back({info.name, scene, samples});
    return cases;
}

void PrintTo(const StageCase& c, std::ostream* out) {
    *out << c.stage << " on " << c.scene << " at " << c.samples << "x";
}

class VisibilityLayoutStages : public ::testing::TestWithParam<StageCase> {};

// The stage shades bitwise the same image, with the same light counts, from the visibility buffer
// as from its derived layout (the derived layout is lossless: the surfaces are the same, so every
// stage must read the same values whichever way they reach it).
TEST_P(VisibilityLayoutStages, ShadeBitwiseTheDerivedLayoutsImage) {
    const StageCase& c = GetParam();
    const scenes::Scene& scene = sceneNamed(c.scene, c.scene == "helmet" ? 24 : 96);
    auto shade = [&](const std::string& preset) {
        const std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage(c.stage);
        gbuffer::LayoutRequest request;
        request.preset = preset;
        const gbuffer::GBufferLayout layout =
            gbuffer::makeLayout(scene, stage->requirements().channels, c.stage, request);
        lighting::Multisampling multisampling;
        multisampling.samples = c.samples;
        lighting::PreparedScene frame(scene, 160, 90, stage->requirements().exactSurface, layout,
                                      multisampling);
        EXPECT_EQ(frame.gbuffer->layout().visibilityBuffer, preset == "visibility");
        lighting::StageResult result;
        lighting::MultisampleShading().shade(*stage, frame, result);
        return result;
    };
    const lighting::StageResult derived = shade("");
    const lighting::StageResult fetched = shade("visibility");
    ASSERT_EQ(derived.radiance[0].size(), fetched.radiance[0].size());
    int failures = 0;
    for (size_t pixel = 0; pixel < derived.radiance[0].size(); ++pixel) {
        bool same = derived.lightsEvaluated[pixel] == fetched.lightsEvaluated[pixel];
        for (int c3 = 0; c3 < 3; ++c3)
            same = same && sameBits(derived.radiance[c3][pixel], fetched.radiance[c3][pixel]);
        if (!same && failures++ < 5)
            ADD_FAILURE() << "pixel " << pixel << ": " << derived.radiance[0][pixel] << " vs "
                          << fetched.radiance[0][pixel] << ", lights "
                          << derived.lightsEvaluated[pixel] << " vs "
                          << fetched.lightsEvaluated[pixel];
    }
    EXPECT_EQ(failures, 0);
}

INSTANTIATE_TEST_SUITE_P(EveryStage, VisibilityLayoutStages, ::testing::ValuesIn(stageCases()),
                         [](const ::testing::TestParamInfo<StageCase>& info) {
                             std::string name = info.param.stage + "_" + info.param.scene + "_" +
                                                std::to_string(info.param.samples) + "x";
                             for (char& ch : name)
                                 if (!std::isalnum(static_cast<unsigned char>(ch)))
                                     ch = '_';
                             return name;
                         });

} // namespace
