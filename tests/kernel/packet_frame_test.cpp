// A brute-force frame shaded packet by packet (decode + kernel, as the stages will) against the
// `brute` stage and the oracle of today's per-pixel code: with the scalar ISA bitwise the same
// image and counts; with every vector target the same evaluated and contributing counts at every
// pixel and the radiance within the kernel's ulp bound; and the same result for 1 and 2 threads.
#include <gtest/gtest.h>

#include <cstring>
#include <numeric>

#include <tbb/task_arena.h>

#include "lighting/Oracle.h"
#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "scenes/procedural/ProceduralScenes.h"
#include "tests/kernel/GBufferPlaneCopy.h"
#include "tests/kernel/KernelTestInputs.h"
#include "tests/kernel/PacketFrame.h"

namespace {

using lighting::kernel::KernelIsa;

struct Frame {
    std::unique_ptr<lighting::PreparedScene> prepared;
    std::unique_ptr<kerneltest::GBufferPlaneCopy> planes;
    std::unique_ptr<lighting::kernel::PacketDecoder> decoder;
    std::unique_ptr<lighting::kernel::KernelLights> lights;
    std::vector<uint32_t> everyLight;
    lighting::StageResult brute;
    std::vector<uint32_t> oracle;
};

const Frame& atriumFrame() {
    static const Frame frame = [] {
        Frame f;
        scenes::SceneRequest request;
        request.lightCount = 256;
        request.seed = 1;
        f.prepared = std::make_unique<lighting::PreparedScene>(
            scenes::buildProceduralScene("atrium", request), 322, 182);
        f.planes = std::make_unique<kerneltest::GBufferPlaneCopy>(*f.prepared->gbuffer);
        f.decoder = std::make_unique<lighting::kernel::PacketDecoder>(
            f.prepared->gbuffer->layout(), f.prepared->view, f.planes->planes());
        f.lights = std::make_unique<lighting::kernel::KernelLights>(f.prepared->lights.lights);
        f.everyLight.resize(f.lights->size());
        std::iota(f.everyLight.begin(), f.everyLight.end(), 0u);
        // brute on the scalar ISA: the loop the scalar packet path must reproduce bit for bit.
        lighting::StageInputs inputs = f.prepared->inputs;
        inputs.isa = KernelIsa::scalar();
        lighting::makeStage("brute")->shade(inputs, f.brute);
        f.oracle = lighting::countContributingLights(f.prepared->inputs);
        return f;
    }();
    return frame;
}

TEST(PacketFrame, ScalarPathIsBruteBitwise) {
    const Frame& f = atriumFrame();
    const kerneltest::PacketFrameResult r =
        kerneltest::shadeFrameByPackets(*f.decoder, KernelIsa::scalar(), *f.lights, f.everyLight);
    for (int k = 0; k < 3; ++k)
        EXPECT_EQ(std::memcmp(r.radiance[k].data(), f.brute.radiance[k].data(),
                              r.radiance[k].size() * sizeof(float)),
                  0);
    EXPECT_EQ(r.lightsEvaluated, f.brute.lightsEvaluated);
    EXPECT_EQ(r.lightsContributing, f.oracle);
}

TEST(PacketFrame, VectorTargetsMatchBrute) {
    const Frame& f = atriumFrame();
    for (const KernelIsa& isa : kerneltest::vectorIsas()) {
        const kerneltest::PacketFrameResult r =
            kerneltest::shadeFrameByPackets(*f.decoder, isa, *f.lights, f.everyLight);
        EXPECT_EQ(r.lightsEvaluated, f.brute.lightsEvaluated) << isa.name();
        EXPECT_EQ(r.lightsContributing, f.oracle) << isa.name();
        int64_t worst = 0;
        double error2 = 0, reference2 = 0;
        for (int k = 0; k < 3; ++k)
            for (size_t i = 0; i < r.radiance[k].size(); ++i) {
                worst = std::max(worst,
                                 kerneltest::ulpDistance(r.radiance[k][i], f.brute.radiance[k][i]));
                const double e = double(r.radiance[k][i]) - f.brute.radiance[k][i];
                error2 += e * e;
                reference2 += double(f.brute.radiance[k][i]) * f.brute.radiance[k][i];
            }
        std::printf("[ %s ] packets vs brute on atrium, 256 lights: worst %lld ulps, relative RMSE "
                    "%.3g; packet-lights shaded %llu, skipped at range %llu, at cone/n.l %llu\n",
                    isa.name().c_str(), (long long)worst, std::sqrt(error2 / reference2),
                    (unsigned long long)r.lightsShaded, (unsigned long long)r.lightsSkippedAtRange,
                    (unsigned long long)r.lightsSkippedAtConeOrFacing);
        EXPECT_LE(worst, 64) << isa.name();
    }
}

TEST(PacketFrame, IndependentOfThreadCount) {
    const Frame& f = atriumFrame();
    const KernelIsa isa = KernelIsa::best();
    kerneltest::PacketFrameResult one, two;
    tbb::task_arena(1).execute(
        [&] { one = kerneltest::shadeFrameByPackets(*f.decoder, isa, *f.lights, f.everyLight); });
    tbb::task_arena(2).execute(
        [&] { two = kerneltest::shadeFrameByPackets(*f.decoder, isa, *f.lights, f.everyLight); });
    for (int k = 0; k < 3; ++k)
        EXPECT_EQ(std::memcmp(one.radiance[k].data(), two.radiance[k].data(),
                              one.radiance[k].size() * sizeof(float)),
                  0);
    EXPECT_EQ(one.lightsContributing, two.lightsContributing);
    EXPECT_EQ(one.lightsShaded, two.lightsShaded);
}

} // namespace
