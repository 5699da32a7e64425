// The forward stages (`forward`, `forward:prepass=1`, `forward-multipass`) beyond the shared
// exactness suite: bitwise equality with `brute`, overdraw counted, the fragment packets on the
// light kernel (ISA, counters and SIMT lane slots; `tiled-forward` too), per-object light lists
// (unlit objects cost nothing, a light behind the camera still lights what it reaches),
// thread-count independence, and the shared surface function against the G-buffer it must
// reproduce.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <span>

#include <glm/gtc/matrix_transform.hpp>
#include <tbb/task_arena.h>

#include "gbuffer/GBufferPass.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/passes/ForwardGeometry.h"
#include "lighting/passes/FragmentShading.h"
#include "scenes/mesh/MeshBuilder.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace {

struct TestScene : lighting::PreparedScene {
    TestScene(scenes::Scene s, int width, int height)
        : lighting::PreparedScene(std::move(s), width, height) {}
};

// On the kernel's scalar path: the forward stages shade with evaluateLight per fragment, which
// `brute` matches bitwise on that path (its vector path differs by a few ulps in pow).
lighting::StageResult run(const std::string& stage, const TestScene& f) {
    lighting::StageResult result;
    lighting::StageInputs inputs = f.inputs;
    inputs.isa = lighting::kernel::KernelIsa::scalar();
    lighting::makeStage(stage)->shade(inputs, result);
    return result;
}

bool sameBits(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

uint64_t total(const std::vector<uint32_t>& counts) {
    uint64_t sum = 0;
    for (uint32_t n : counts)
        sum += n;
    return sum;
}

const TestScene& atrium() {
    static const TestScene frame = [] {
        scenes::SceneRequest request;
        request.lightCount = 200;
        request.seed = 5;
        return TestScene(scenes::buildProceduralScene("atrium", request), 192, 108);
    }();
    return frame;
}

// Three unit boxes in front of a camera at the origin looking down -Z: A (left) lit by a small
// light in front of it, B (right) lit only by a light BEHIND the camera (view z > 0), and C
// (below) out of reach of both.
const TestScene& threeBoxes() {
    static const TestScene frame = [] {
        scenes::Scene scene;
        scene.name = "three-boxes";
        scene.materials.push_back({});
        scenes::Mesh box;
        box.name = "box";
        scenes::appendBox(box, {glm::vec3(-0.5f), glm::vec3(0.5f)}, 0.25f);
        scene.meshes.push_back(box);
        for (const glm::vec3 centre : {glm::vec3(-2.0f, 0.0f, -5.0f), glm::vec3(2.0f, 0.0f, -5.0f),
                                       glm::vec3(0.0f, -2.2f, -5.0f)})
            scene.instances.push_back({0, glm::translate(glm::mat4(1.0f), centre)});
        scene.cameras.push_back({});
        scenes::Light nearA;
        nearA.positionWorld = {-2.0f, 0.0f, -3.5f};
        nearA.rangeMetres = 1.5f;
        nearA.intensity = 5.0f;
        scenes::Light behindCamera;
        behindCamera.positionWorld = {3.0f, 0.0f, 1.0f};
        behindCamera.rangeMetres = 6.2f;
        behindCamera.intensity = 50.0f;
        scene.lights = {nearA, behindCamera};
        scenes::validate(scene);
        return TestScene(std::move(scene), 128, 96);
    }();
    return frame;
}

void expectBitwiseEqual(const lighting::StageResult& result, const lighting::StageResult& brute,
                        const std::string& what) {
    ASSERT_EQ(result.width, brute.width);
    ASSERT_EQ(result.height, brute.height);
    int failures = 0;
    for (size_t pixel = 0; pixel < brute.radiance[0].size(); ++pixel)
        for (int ch = 0; ch < 3; ++ch)
            if (!sameBits(result.radiance[ch][pixel], brute.radiance[ch][pixel]) && failures++ < 5)
                ADD_FAILURE() << what << ": pixel " << pixel << " channel " << ch << " is "
                              << result.radiance[ch][pixel] << ", brute "
                              << brute.radiance[ch][pixel];
    EXPECT_EQ(failures, 0) << what;
}

TEST(Forward, EveryVariantIsBitwiseBrute) {
    for (const TestScene* f : {&atrium(), &threeBoxes()}) {
        const lighting::StageResult brute = run("brute", *f);
        for (const char* stage : {"forward", "forward:prepass=1", "forward-multipass"})
            expectBitwiseEqual(run(stage, *f), brute, std::string(stage) + " on " + f->scene.name);
    }
}

TEST(Forward, PrepassShadesEachPixelOnceAndOverdrawIsCounted) {
    const TestScene& f = atrium();
    const lighting::StageResult single = run("forward", f);
    const lighting::StageResult prepass = run("forward:prepass=1", f);
    EXPECT_EQ(single.parameters.at("prepass"), "0");
    EXPECT_EQ(prepass.parameters.at("prepass"), "1");
    // Overdraw: every fragment that passed the depth test without a pre-pass was shaded.
    EXPECT_GT(total(single.lightsEvaluated), total(prepass.lightsEvaluated));
    for (size_t pixel = 0; pixel < single.lightsEvaluated.size(); ++pixel) {
        ASSERT_GE(single.lightsEvaluated[pixel], prepass.lightsEvaluated[pixel]) << pixel;
        if (!f.gbuffer->covered(pixel)) {
            ASSERT_EQ(prepass.lightsEvaluated[pixel], 0u) << pixel;
        }
    }
    std::vector<std::string> passes;
    for (const auto& [name, ms] : prepass.timingsMs)
        passes.push_back(name);
    EXPECT_NE(std::find(passes.begin(), passes.end(), "prepass"), passes.end());
    EXPECT_NE(std::find(passes.begin(), passes.end(), "cull"), passes.end());
    EXPECT_NE(std::find(passes.begin(), passes.end(), "shading"), passes.end());
}

TEST(Forward, MultipassEvaluatesOnlyVisibleFragments) {
    // With the pre-pass's equal test, multipass never evaluates more lights at a pixel than the
    // single-pass stage does for that pixel's visible object (the same culling), and nothing on
    // the background.
    const TestScene& f = atrium();
    const lighting::StageResult multipass = run("forward-multipass", f);
    const lighting::StageResult prepass = run("forward:prepass=1", f);
    for (size_t pixel = 0; pixel < multipass.lightsEvaluated.size(); ++pixel)
        ASSERT_EQ(multipass.lightsEvaluated[pixel], prepass.lightsEvaluated[pixel]) << pixel;
}

TEST(Forward, UnlitObjectsCostNothingAndALightBehindTheCameraStillLights) {
    const TestScene& f = threeBoxes();
    lighting::ForwardGeometry forward;
    forward.prepare(f.inputs);
    ASSERT_EQ(forward.objects().size(), 3u);
    forward.drawDepthPrepass();
    const std::span<const uint32_t> visible = forward.visibility().codes();

    for (const char* stage : {"forward", "forward:prepass=1", "forward-multipass"}) {
        const lighting::StageResult result = run(stage, f);
        int pixelsOfObject[3] = {0, 0, 0};
        int litPixelsOfObject[3] = {0, 0, 0};
        for (size_t pixel = 0; pixel < visible.size(); ++pixel) {
            if (visible[pixel] == gbuffer::VisibilityPass::kNoTriangle) {
                EXPECT_EQ(result.lightsEvaluated[pixel], 0u) << stage;
                continue;
            }
            const uint32_t object =
                forward.objectOfTriangle(gbuffer::VisibilityPass::triangleOf(visible[pixel]));
            ++pixelsOfObject[object];
            litPixelsOfObject[object] += result.radiance[0][pixel] > 0.0f ? 1 : 0;
            // A and B each have exactly one light in reach; C none.
            EXPECT_EQ(result.lightsEvaluated[pixel] > 0, object != 2)
                << stage << " pixel " << pixel;
            if (object == 2) {
                EXPECT_EQ(result.radiance[0][pixel], 0.0f) << stage;
            }
        }
        for (int o = 0; o < 3; ++o)
            EXPECT_GT(pixelsOfObject[o], 100) << "object " << o << " not in view";
        EXPECT_GT(litPixelsOfObject[0], 0) << stage;
        EXPECT_GT(litPixelsOfObject[1], 0) << stage << ": the light behind the camera lit nothing";
    }
}

TEST(Forward, SameResultForAnyThreadCount) {
    const TestScene& f = atrium();
    for (const char* stage : {"forward", "forward:prepass=1", "forward-multipass"}) {
        lighting::StageResult one, two;
        tbb::task_arena(1).execute([&] { one = run(stage, f); });
        tbb::task_arena(2).execute([&] { two = run(stage, f); });
        EXPECT_EQ(one.lightsEvaluated, two.lightsEvaluated) << stage;
        expectBitwiseEqual(one, two, std::string(stage) + " 1 vs 2 threads");
    }
}

// The forward stages on the light kernel (lighting/passes/FragmentShading.h): on the widest ISA
// they report it and stay bitwise brute's there (overdraw included: a later fragment of a pixel,
// even in the same 16-lane packet, replaces the earlier one); counts and the kernel's packet
// counters do not depend on the ISA; the SIMT model's warps (32 or 64 consecutive fragments of a
// raster tile) pay warpLanes lane slots per light of their union, so slots are a multiple of the
// warp, at least the evaluations, and a 64-lane warp (two 32-lane warps' union) pays at least as
// much.
TEST(Forward, FragmentPacketsOnTheKernelReportIsaAndSimtLaneSlots) {
    const TestScene& f = atrium();
    const lighting::kernel::KernelIsa best = lighting::kernel::KernelIsa::best();
    auto runOn = [&](const std::string& stage, const lighting::kernel::KernelIsa& isa, int warp) {
        lighting::StageResult result;
        lighting::StageInputs inputs = f.inputs;
        inputs.isa = isa;
        inputs.simtWarpLanes = warp;
        lighting::makeStage(stage)->shade(inputs, result);
        return result;
    };
    const lighting::StageResult brute = runOn("brute", best, 32);
    for (const char* stage :
         {"forward", "forward:prepass=1", "forward-multipass", "tiled-forward"}) {
        const lighting::StageResult vector = runOn(stage, best, 32);
        const lighting::StageResult scalar =
            runOn(stage, lighting::kernel::KernelIsa::scalar(), 32);
        const lighting::StageResult wide = runOn(stage, best, 64);
        EXPECT_EQ(vector.parameters.at("isa"), best.name()) << stage;
        EXPECT_EQ(scalar.parameters.at("isa"), "scalar") << stage;
        expectBitwiseEqual(vector, brute, std::string(stage) + " on " + best.name());
        EXPECT_EQ(vector.lightsEvaluated, scalar.lightsEvaluated) << stage;
        for (const char* counter :
             {"packet_groups", "packet_lights_skipped_at_range",
              "packet_lights_skipped_at_cone_or_facing", "packet_lights_shaded", "simt_lane_slots"})
            EXPECT_EQ(vector.parameters.at(counter), scalar.parameters.at(counter))
                << stage << " " << counter;
        EXPECT_GT(std::stoull(vector.parameters.at("packet_lights_shaded")), 0u) << stage;

        const uint64_t slots = std::stoull(vector.parameters.at("simt_lane_slots"));
        const uint64_t wideSlots = std::stoull(wide.parameters.at("simt_lane_slots"));
        EXPECT_EQ(vector.parameters.at("simt_warp"), "32");
        EXPECT_EQ(wide.parameters.at("simt_warp"), "64");
        EXPECT_EQ(slots % 32, 0u) << stage;
        EXPECT_EQ(wideSlots % 64, 0u) << stage;
        EXPECT_GE(slots, total(vector.lightsEvaluated)) << stage;
        EXPECT_GE(wideSlots, slots) << stage;
        EXPECT_EQ(wide.lightsEvaluated, vector.lightsEvaluated) << stage;
        expectBitwiseEqual(wide, vector, std::string(stage) + " 64- vs 32-lane batches");
    }
}

TEST(Forward, SharedSurfaceFunctionReproducesTheGBuffer) {
    // The G-buffer pass and the forward stages share the visibility pass (transform, draw,
    // surface) and the lossless layout's depth decoder: at every covered pixel, the G-buffer's
    // decoded surface must equal, bit for bit, the forward geometry's surface of the pre-pass's
    // visible fragment.
    for (const TestScene* f : {&atrium(), &threeBoxes()}) {
        lighting::ForwardGeometry forward;
        forward.prepare(f->inputs);
        forward.drawDepthPrepass();
        const std::span<const float> depth = forward.depth();
        const std::span<const uint32_t> visible = forward.visibility().codes();
        int covered = 0, failures = 0;
        for (int y = 0; y < f->view.height; ++y)
            for (int x = 0; x < f->view.width; ++x) {
                const size_t pixel = size_t(y) * f->view.width + x;
                ASSERT_TRUE(sameBits(depth[pixel], f->gbuffer->depth()[pixel])) << pixel;
                ASSERT_EQ(visible[pixel] != gbuffer::VisibilityPass::kNoTriangle,
                          f->gbuffer->covered(pixel));
                if (visible[pixel] == gbuffer::VisibilityPass::kNoTriangle)
                    continue;
                ++covered;
                raster::Fragment fragment;
                fragment.x = x;
                fragment.y = y;
                fragment.depth = depth[pixel];
                fragment.frontFacing = !gbuffer::VisibilityPass::backFaceOf(visible[pixel]);
                const auto point = forward.surfaceAt(
                    fragment, gbuffer::VisibilityPass::triangleOf(visible[pixel]));
                const gbuffer::Surface decoded = f->gbuffer->decode(x, y);
                bool same = sameBits(point.specularIntensity, decoded.specularIntensity) &&
                            sameBits(point.specularPower, decoded.specularPower);
                for (int c = 0; c < 3; ++c)
                    same = same && sameBits(point.positionView[c], decoded.positionView[c]) &&
                           sameBits(point.normalView[c], decoded.normalView[c]) &&
                           sameBits(point.albedo[c], decoded.albedo[c]);
                if (!same && failures++ < 5)
                    ADD_FAILURE() << f->scene.name << ": pixel (" << x << ", " << y << ")";
            }
        EXPECT_EQ(failures, 0);
        EXPECT_GT(covered, 0);
    }
}

TEST(Forward, RejectsBadOptions) {
    EXPECT_THROW(lighting::makeStage("forward:prepass=2"), lighting::StageError);
    EXPECT_THROW(lighting::makeStage("forward-multipass:prepass=1"), lighting::StageError);
}

// FragmentShading::addBeyondRange (what `forward-multipass` queues for a fragment outside its
// pass's light): against queueing every fragment with its surface, the additive light passes
// give bitwise the same radiance, the same counts, trace and kernel counters (on every ISA),
// and a light pass over fragments mostly beyond range leaves most of them unshaded. Fragments
// here are the G-buffer's pixels of atrium, one additive pass per light, 16-lane packets of
// consecutive pixels of a raster tile.
TEST(Forward, BeyondRangeFragmentsAddNothingAndCountAsShaded) {
    const TestScene& f = atrium();
    const gbuffer::GBuffer& gb = *f.inputs.gbuffer;
    const size_t lightCount = f.inputs.lights->size();
    for (const lighting::kernel::KernelIsa& isa :
         {lighting::kernel::KernelIsa::scalar(), lighting::kernel::KernelIsa::best()}) {
        lighting::StageInputs inputs = f.inputs;
        inputs.isa = isa;
        auto passes = [&](bool skipBeyond, uint64_t& beyondCount) {
            lighting::StageResult result;
            result.traceLights = true;
            result.resize(gb.width(), gb.height(), false);
            lighting::FragmentShading shading;
            shading.begin(inputs, lighting::FragmentApply::Add, result);
            beyondCount = 0;
            for (uint32_t l = 0; l < lightCount; ++l) {
                const uint32_t light[1] = {l};
                for (int y = 0; y < gb.height(); ++y)
                    for (int x = 0; x < gb.width(); ++x) {
                        gbuffer::Surface s;
                        if (!gb.surfaceAt(x, y, s))
                            continue;
                        raster::Fragment fragment;
                        fragment.x = x;
                        fragment.y = y;
                        if (skipBeyond && shading.beyondRange(l, s.positionView)) {
                            ++beyondCount;
                            shading.addBeyondRange(fragment, 0, l, light);
                        } else {
                            shading.add(fragment, 0, s, l, light);
                        }
                    }
                shading.flush();
            }
            shading.end();
            return result;
        };
        uint64_t none = 0, beyond = 0;
        const lighting::StageResult all = passes(false, none);
        const lighting::StageResult skipped = passes(true, beyond);
        const std::string what = std::string("beyond-range lanes on ") + isa.name();
        expectBitwiseEqual(skipped, all, what);
        EXPECT_EQ(skipped.lightsEvaluated, all.lightsEvaluated) << what;
        EXPECT_EQ(skipped.lightTrace, all.lightTrace) << what;
        EXPECT_EQ(skipped.parameters, all.parameters) << what;
        const uint64_t evaluations = total(all.lightsEvaluated);
        std::cout << "[measured] " << isa.name() << ": " << beyond << " of " << evaluations
                  << " fragment-light pairs beyond range (not shaded)\n";
        EXPECT_EQ(none, 0u);
        EXPECT_GT(beyond, evaluations / 2) << what;
    }
}

} // namespace
