// `tiled-forward` (Forward+) beyond the shared exactness suite: tile=32, vfc=0 and mask=1 variants
// are bitwise `brute` on atrium with evaluated >= oracle; it evaluates exactly as many lights per
// pixel as `tiled` at the same tile size and options (mask=1 included) (its pre-pass depth is the
// G-buffer's depth, so the tile bounds and hence the tile lists are the same, and the visible
// surface is the same); the pre-pass tile bounds equal the G-buffer's bitwise; 1 thread and N
// threads give the same bits; options are parsed, checked and recorded.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <span>
#include <string>

#include <tbb/task_arena.h>

#include "gbuffer/GBufferPass.h"
#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/culling/TileFrusta.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

// A PreparedScene (the runner's own frame construction) plus brute's result and the oracle.
struct TestScene {
    std::unique_ptr<lighting::PreparedScene> prepared;
    lighting::StageInputs inputs;
    gbuffer::CameraView view;
    const gbuffer::GBuffer* gbuffer = nullptr;
    std::vector<uint32_t> oracle;
    lighting::StageResult brute;
};

std::unique_ptr<TestScene>
makeTestScene(const std::string& sceneName, int lightCount, int width, int height,
              gbuffer::DepthConvention depth = gbuffer::DepthConvention::Reversed) {
    auto f = std::make_unique<TestScene>();
    scenes::SceneRequest request;
    request.lightCount = lightCount;
    request.seed = 5;
    f->prepared = std::make_unique<lighting::PreparedScene>(
        scenes::buildProceduralScene(sceneName, request), width, height, false, depth);
    f->inputs = f->prepared->inputs;
    // tiled-forward shades with evaluateLight per fragment: compared with brute's scalar path,
    // which gives the per-pixel loop's sums bitwise.
    f->inputs.isa = lighting::kernel::KernelIsa::scalar();
    f->view = f->prepared->view;
    f->gbuffer = f->prepared->gbuffer.get();
    f->oracle = lighting::countContributingLights(f->inputs);
    lighting::makeStage("brute")->shade(f->inputs, f->brute);
    return f;
}

const TestScene& atrium() {
    static const std::unique_ptr<TestScene> frame = makeTestScene("atrium", 200, 320, 180);
    return *frame;
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

lighting::StageResult run(const std::string& spec, const TestScene& f) {
    lighting::StageResult result;
    lighting::makeStage(spec)->shade(f.inputs, result);
    return result;
}

// Bitwise brute's image and evaluated >= oracle at every pixel; returns the result.
lighting::StageResult expectExact(const TestScene& f, const std::string& spec) {
    const lighting::StageResult result = run(spec, f);
    EXPECT_EQ(result.width, f.view.width);
    EXPECT_EQ(result.height, f.view.height);
    int imageFailures = 0, dropped = 0;
    for (size_t pixel = 0; pixel < f.oracle.size(); ++pixel) {
        for (int ch = 0; ch < 3; ++ch)
            if (!sameBits(result.radiance[ch][pixel], f.brute.radiance[ch][pixel]) &&
                imageFailures++ < 3)
                ADD_FAILURE() << spec << ": pixel (" << pixel % f.view.width << ", "
                              << pixel / f.view.width << ") channel " << ch << ": "
                              << result.radiance[ch][pixel] << " vs brute "
                              << f.brute.radiance[ch][pixel];
        if (result.lightsEvaluated[pixel] < f.oracle[pixel] && dropped++ < 3)
            ADD_FAILURE() << spec << ": pixel (" << pixel % f.view.width << ", "
                          << pixel / f.view.width << ") evaluated " << result.lightsEvaluated[pixel]
                          << " < oracle " << f.oracle[pixel];
    }
    EXPECT_EQ(imageFailures, 0) << spec;
    EXPECT_EQ(dropped, 0) << spec;
    return result;
}

TEST(TiledForward, VariantsAreBitwiseBruteOnAtrium) {
    for (const char* spec : {"tiled-forward", "tiled-forward:tile=32", "tiled-forward:vfc=0",
                             "tiled-forward:tile=32,vfc=0", "tiled-forward:tile=4",
                             "tiled-forward:mask=1", "tiled-forward:tile=8,mask=1,vfc=0"})
        expectExact(atrium(), spec);
}

// Standard Z (near=0, far=1): the pre-pass and the tile bounds follow the view's convention.
TEST(TiledForward, BitwiseBruteWithStandardDepth) {
    const std::unique_ptr<TestScene> f =
        makeTestScene("atrium", 200, 320, 180, gbuffer::DepthConvention::Standard);
    expectExact(*f, "tiled-forward");
    expectExact(*f, "tiled-forward:tile=32,vfc=0");
    expectExact(*f, "tiled-forward:mask=1");
    EXPECT_EQ(run("tiled-forward", *f).lightsEvaluated, run("tiled", *f).lightsEvaluated);
    EXPECT_EQ(run("tiled-forward:mask=1", *f).lightsEvaluated,
              run("tiled:mask=1", *f).lightsEvaluated);
}

// Same tile size, same lists, same visible surface: the pre-pass draws the same triangles with
// the same rasterizer and depth test as the G-buffer pass, so its depth plane is the G-buffer's
// (float depth in the reference layout), its tile bounds are bitwise `tiled`'s, and the list
// tests are the same. Holds exactly, so this checks equality, not just >= oracle.
TEST(TiledForward, EvaluatesExactlyAsManyLightsAsTiled) {
    const std::unique_ptr<TestScene> wall = makeTestScene("wall", 300, 320, 180);
    for (const TestScene* f : {&atrium(), static_cast<const TestScene*>(wall.get())}) {
        for (const std::string options : {"tile=16", "tile=32", "tile=8,vfc=0", "tile=32,vfc=0",
                                          "mask=1", "tile=32,mask=1,vfc=0"}) {
            const lighting::StageResult tiled = run("tiled:" + options, *f);
            const lighting::StageResult forward = run("tiled-forward:" + options, *f);
            EXPECT_EQ(forward.lightsEvaluated, tiled.lightsEvaluated) << options;
            EXPECT_EQ(forward.parameters.at("tile_light_pairs"),
                      tiled.parameters.at("tile_light_pairs"))
                << options;
            EXPECT_EQ(forward.parameters.at("lights_after_vfc"),
                      tiled.parameters.at("lights_after_vfc"))
                << options;
        }
    }
}

TEST(TiledForward, PrepassTileBoundsEqualGBufferBounds) {
    const TestScene& f = atrium();
    for (int tileSize : {4, 16, 37}) {
        const lighting::TileGrid grid =
            lighting::TileGrid::make(f.view.width, f.view.height, tileSize);
        // The decoder the forward stages read their pre-pass depth with (ForwardGeometry.h).
        const gbuffer::DepthDecoder forwardDecoder =
            gbuffer::GBufferLayout::lossless(f.view.depthConvention, f.view.infiniteFar)
                .depthDecoder(f.view);
        for (bool mask : {false, true}) {
            const auto fromGBuffer =
                lighting::computeTileSurfaceBounds(*f.gbuffer, grid, {mask, false});
            const auto fromDepth = lighting::computeTileDepthBounds(
                forwardDecoder, std::span<const float>(f.gbuffer->depth()), grid, mask);
            ASSERT_EQ(fromGBuffer.size(), fromDepth.size());
            for (size_t tile = 0; tile < fromDepth.size(); ++tile) {
                EXPECT_EQ(fromDepth[tile].covered, fromGBuffer[tile].covered) << tile;
                EXPECT_TRUE(
                    sameBits(fromDepth[tile].minDepthMetres, fromGBuffer[tile].minDepthMetres))
                    << tile;
                EXPECT_TRUE(
                    sameBits(fromDepth[tile].maxDepthMetres, fromGBuffer[tile].maxDepthMetres))
                    << tile;
                EXPECT_EQ(fromDepth[tile].depthMask, fromGBuffer[tile].depthMask) << tile;
            }
        }
    }
}

TEST(TiledForward, SameResultForAnyThreadCount) {
    const std::unique_ptr<TestScene> f = makeTestScene("wall", 300, 320, 180);
    for (const char* spec : {"tiled-forward", "tiled-forward:tile=8,vfc=0"}) {
        lighting::StageResult one, many;
        tbb::task_arena(1).execute([&] { lighting::makeStage(spec)->shade(f->inputs, one); });
        lighting::makeStage(spec)->shade(f->inputs, many);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_EQ(one.radiance[ch], many.radiance[ch]) << spec;
        EXPECT_EQ(one.lightsEvaluated, many.lightsEvaluated) << spec;
        EXPECT_EQ(one.parameters, many.parameters) << spec;
    }
}

TEST(TiledForward, StageReusedAcrossFramesGivesSameResult) {
    // The stage keeps its rasterizer, depth and lists between frames; a second frame of another
    // size must not see stale data.
    const std::unique_ptr<TestScene> small = makeTestScene("spheres", 100, 160, 90);
    std::unique_ptr<lighting::ShadingStage> stage = lighting::makeStage("tiled-forward:tile=16");
    lighting::StageResult first, second;
    stage->shade(atrium().inputs, first);
    stage->shade(small->inputs, second);
    const lighting::StageResult fresh = run("tiled-forward:tile=16", *small);
    for (int ch = 0; ch < 3; ++ch)
        EXPECT_EQ(second.radiance[ch], fresh.radiance[ch]);
    EXPECT_EQ(second.lightsEvaluated, fresh.lightsEvaluated);
}

TEST(TiledForward, OptionsParseAndAreRecorded) {
    EXPECT_NO_THROW(lighting::makeStage("tiled-forward:tile=128,vfc=0"));
    EXPECT_THROW(lighting::makeStage("tiled-forward:tile=3"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("tiled-forward:tile=129"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("tiled-forward:vfc=2"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("tiled-forward:mask=2"), lighting::StageError);

    const lighting::StageResult r = run("tiled-forward:tile=32,vfc=0", atrium());
    EXPECT_EQ(r.parameters.at("tile"), "32");
    EXPECT_EQ(r.parameters.at("vfc"), "0");
    EXPECT_EQ(r.parameters.at("vfc_culled"), "0");
    EXPECT_EQ(r.parameters.at("mask"), "0");
    EXPECT_EQ(run("tiled-forward:mask=1", atrium()).parameters.at("mask"), "1");
    ASSERT_EQ(r.timingsMs.size(), 4u);
    EXPECT_EQ(r.timingsMs[0].first, "transform");
    EXPECT_EQ(r.timingsMs[1].first, "prepass");
    EXPECT_EQ(r.timingsMs[2].first, "cull");
    EXPECT_EQ(r.timingsMs[3].first, "shading");
    EXPECT_TRUE(lighting::makeStage("tiled-forward")->requirements().channels.empty());
}

} // namespace
