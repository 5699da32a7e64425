// Benchmarks of the shading kernel (lighting/kernel/), every instruction set in the same run:
//   kernelBruteShading/<isa>     atrium 1280x720, 256 point lights + ambient + sun, every light
//                                for every packet (brute force), packets decoded beforehand;
//                                ns per covered pixel-light, one thread
//   kernelBruteSpeedup/<isa>     the same, scalar and <isa> timed alternately on the same packets:
//                                the median ratio (the target: >= 8)
//   kernelBruteFrame/<isa>/<t>   the same with the decode inside the timer, on t threads: what a
//                                brute stage on the kernel would cost (compare bruteShading)
//   kernelBruteSpeedupHelmet/<isa>  the same ratio on the DamagedHelmet glTF model (every
//                                material metallic-roughness: the GGX path), 256 point lights
//   kernelContributing/<isa>     synthetic packets where every lane receives every light (the
//                                kernel's full path only): GFLOP/s and fraction of the FP32 FMA
//                                peak
//   kernelContributingGgx/<isa>  the same packets with metallic-roughness surfaces (GGX, Smith,
//                                Schlick: 110 flops per point light)
//   kernelIdealAtrium/<isa>      atrium, each packet with exactly the lights that contribute to at
//                                least one of its lanes: contributing-light GFLOP/s and fraction
//   packetDecode/<isa>           derived atrium layout decoded a packet at a time, ns per pixel
//   gbufferDecodePerPixel        GBuffer::decode for every pixel (today's reader), ns per pixel
//   machinePeak                  the measured clock and FMA instructions per cycle
// Single-threaded benchmarks time the thread's CPU time (the machine is shared: time spent
// descheduled is not the kernel's); kernelBruteFrame times wall clock, as a frame is.
// Flops of one evaluation as the kernel executes it (lighting/kernel/README.md counts them): 99
// for a point light, 111 for a spot, 81 for a directional light, 6 for an ambient one
// (Blinn-Phong); 110, 122, 92 and 9 (metallic-roughness, no pow); additions, multiplications,
// divisions and square roots count 1, fused multiply-adds 2, comparisons, selections, conversions
// and integer operations 0, and pow the 44 flops Highway's Log (20), the product y log x (1) and
// Exp (23) execute. Peak = lanes x 2 FMA pipes x 2 flops x measured clock, with lanes the ISA's
// floats per vector (1 for the scalar path).
//   build/bin/testbed_bench --benchmark_counters_tabular=true
//       --benchmark_filter='kernel|packetDecode|gbufferDecode|machinePeak'
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "gbuffer/LayoutDerivation.h"
#include "lighting/kernel/LightKernel.h"
#include "lighting/kernel/PacketDecoder.h"
#include "scenes/SceneLoader.h"
#include "tests/bench/BenchScenes.h"
#include "tests/bench/MachinePeak.h"
#include "tests/kernel/GBufferPlaneCopy.h"

namespace {

using lighting::kernel::KernelIsa;
using lighting::kernel::KernelLights;
using lighting::kernel::PacketAccumulator;
using lighting::kernel::ShadingPacket;

constexpr int kFmaPipes = 2; // Zen 5 (MachinePeak.h); machinePeak reports the measured figure

// A shaded metallic-roughness point light (lighting/kernel/README.md): range 8, direction and
// attenuation 10, n.l 5, then the BRDF 84 (halfway vector 12, V.H 5, Schlick 4, dielectric Fresnel
// 2, N.H 5, |N x H|^2 14, D's denominator and division 6, Vis 8 (its |N.V| half is per pixel),
// D Vis 1, diffuse weight 2, n.l x attenuation 1, per channel Fresnel 3, BRDF 3, radiance 2) and
// the sum 3.
constexpr double kGgxPointLightFlops = 110;

double flopsPerEvaluation(scenes::LightType type) {
    switch (type) {
    case scenes::LightType::Point:
        return 99;
    case scenes::LightType::Spot:
        return 111;
    case scenes::LightType::Directional:
        return 81;
    case scenes::LightType::Ambient:
        return 6;
    }
    return 0;
}

// Per-iteration times; figures are reported for the fastest and the median iteration (the
// machine is shared: the fastest is the least disturbed, the median the typical).
struct IterationTimes {
    std::vector<double> seconds;
    void add(benchmark::State& state, double elapsed) {
        state.SetIterationTime(elapsed);
        seconds.push_back(elapsed);
    }
    double fastest() const { return *std::min_element(seconds.begin(), seconds.end()); }
    double median() const {
        std::vector<double> sorted = seconds;
        std::sort(sorted.begin(), sorted.end());
        return sorted[sorted.size() / 2];
    }
};

double clockHz() {
    static const double hz = bench::measuredClockHz();
    return hz;
}

double peakFlops(const KernelIsa& isa) {
    return double(isa.vectorLanes()) * kFmaPipes * 2.0 * clockHz();
}

// Registers `function` once per available ISA as NAME/ISA (and NAME/ISA/THREADS).
void registerPerIsa(const char* name, void (*function)(benchmark::State&, const KernelIsa&),
                    std::vector<int64_t> threads = {}) {
    for (const KernelIsa& isa : KernelIsa::available()) {
        auto* registered = benchmark::RegisterBenchmark(
            (std::string(name) + "/" + isa.name()).c_str(),
            [function, isa](benchmark::State& state) { function(state, isa); });
        for (int64_t t : threads)
            registered->Arg(t);
        registered->UseManualTime()->MinTime(2.0)->Unit(benchmark::kMillisecond);
    }
}

// A frame of the stage benchmarks (atrium, or the helmet), its planes, decoder, lights and decoded
// packets.
struct AtriumKernelFrame {
    std::unique_ptr<lighting::PreparedScene> frame;
    std::unique_ptr<kerneltest::GBufferPlaneCopy> planes;
    std::unique_ptr<lighting::kernel::PacketDecoder> decoder;
    std::unique_ptr<KernelLights> lights;
    std::vector<uint32_t> everyLight;
    std::vector<ShadingPacket> packets;
    uint64_t coveredPixels = 0;
};

// The layout `render` derives for brute: float depth, float32 normals, material index (atrium);
// plus float32 albedo, roughness, metallic (the helmet's textures).
AtriumKernelFrame makeKernelFrame(scenes::Scene scene) {
    AtriumKernelFrame a;
    {
        const gbuffer::GBufferLayout layout =
            gbuffer::deriveLayout(scene, {gbuffer::Channel::Depth, gbuffer::Channel::Normal,
                                          gbuffer::Channel::Albedo, gbuffer::Channel::Specular});
        a.frame = std::make_unique<lighting::PreparedScene>(std::move(scene), bench::kWidth,
                                                            bench::kHeight, false, layout);
        a.planes = std::make_unique<kerneltest::GBufferPlaneCopy>(*a.frame->gbuffer);
        a.decoder = std::make_unique<lighting::kernel::PacketDecoder>(layout, a.frame->view,
                                                                      a.planes->planes());
        a.lights = std::make_unique<KernelLights>(a.frame->lights.lights);
        a.everyLight.resize(a.lights->size());
        std::iota(a.everyLight.begin(), a.everyLight.end(), 0u);
        for (int y0 = 0; y0 < bench::kHeight; y0 += 4)
            for (int x0 = 0; x0 < bench::kWidth; x0 += 4) {
                ShadingPacket packet;
                a.decoder->decode(KernelIsa::best(), x0, y0, packet);
                a.coveredPixels += uint64_t(__builtin_popcount(packet.laneMask));
                if (packet.laneMask)
                    a.packets.push_back(packet);
            }
    }
    return a;
}

const AtriumKernelFrame& atriumKernelFrame() {
    static const AtriumKernelFrame f = makeKernelFrame(bench::proceduralScene("atrium", 256));
    return f;
}

const AtriumKernelFrame& helmetKernelFrame() {
    static const AtriumKernelFrame f = [] {
        scenes::SceneRequest request;
        request.lightCount = 256;
        request.seed = 1;
        return makeKernelFrame(
            scenes::loadScene(TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", request));
    }();
    return f;
}

void kernelBruteShading(benchmark::State& state, const KernelIsa& isa) {
    const AtriumKernelFrame& f = atriumKernelFrame();
    PacketAccumulator accumulator;
    uint64_t shaded = 0, total = 0;
    IterationTimes times;
    for (auto _ : state) {
        const double start = bench::threadCpuSeconds();
        shaded = total = 0;
        for (const ShadingPacket& packet : f.packets) {
            accumulator.clear();
            // With the oracle count, as brute reports it.
            lighting::kernel::shadePacket(isa, packet, lighting::kernel::kAllLanes, *f.lights,
                                          f.everyLight, accumulator, true);
            shaded += accumulator.lightsShaded;
            total += f.everyLight.size();
        }
        benchmark::DoNotOptimize(accumulator);
        times.add(state, bench::threadCpuSeconds() - start);
    }
    const double pixelLights = double(f.coveredPixels) * double(f.everyLight.size());
    state.counters["ns/pixel-light_min"] = times.fastest() * 1e9 / pixelLights;
    state.counters["ns/pixel-light_median"] = times.median() * 1e9 / pixelLights;
    state.counters["shaded_fraction"] = double(shaded) / double(total);
    state.SetLabel(isa.name());
}

// The ratio, measured so that load on the shared machine hits both sides alike: each
// iteration times the scalar path and then `isa` on the same packets (every 8th packet of the
// frame, brute force, with the oracle count), and the ratio of the two times is kept; the median
// ratio over the iterations is reported.
void kernelBruteSpeedupOn(benchmark::State& state, const KernelIsa& isa,
                          const AtriumKernelFrame& f) {
    PacketAccumulator accumulator;
    auto shadeEighth = [&](const KernelIsa& which) {
        const double start = bench::threadCpuSeconds();
        for (size_t p = 0; p < f.packets.size(); p += 8) {
            accumulator.clear();
            lighting::kernel::shadePacket(which, f.packets[p], lighting::kernel::kAllLanes,
                                          *f.lights, f.everyLight, accumulator, true);
        }
        benchmark::DoNotOptimize(accumulator);
        return bench::threadCpuSeconds() - start;
    };
    double pixelLights = 0;
    for (size_t p = 0; p < f.packets.size(); p += 8)
        pixelLights += double(__builtin_popcount(f.packets[p].laneMask)) * f.everyLight.size();
    std::vector<double> ratios, scalarTimes, vectorTimes;
    for (auto _ : state) {
        const double scalar = shadeEighth(KernelIsa::scalar());
        const double vector = shadeEighth(isa);
        state.SetIterationTime(scalar + vector);
        ratios.push_back(scalar / vector);
        scalarTimes.push_back(scalar);
        vectorTimes.push_back(vector);
    }
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    state.counters["speedup_median"] = median(ratios);
    state.counters["speedup_min"] = *std::min_element(ratios.begin(), ratios.end());
    state.counters["scalar_ns/pixel-light"] = median(scalarTimes) * 1e9 / pixelLights;
    state.counters["vector_ns/pixel-light"] = median(vectorTimes) * 1e9 / pixelLights;
    uint32_t metallicRoughnessLanes = 0, lanes = 0;
    for (const ShadingPacket& packet : f.packets) {
        metallicRoughnessLanes += uint32_t(__builtin_popcount(packet.metallicRoughnessMask));
        lanes += uint32_t(__builtin_popcount(packet.laneMask));
    }
    state.counters["metallic_roughness_lanes"] = double(metallicRoughnessLanes) / double(lanes);
    state.SetLabel(isa.name() + " vs scalar");
}

void kernelBruteSpeedup(benchmark::State& state, const KernelIsa& isa) {
    kernelBruteSpeedupOn(state, isa, atriumKernelFrame());
}

void kernelBruteSpeedupHelmet(benchmark::State& state, const KernelIsa& isa) {
    kernelBruteSpeedupOn(state, isa, helmetKernelFrame());
}

void kernelBruteFrame(benchmark::State& state, const KernelIsa& isa) {
    const AtriumKernelFrame& f = atriumKernelFrame();
    tbb::task_arena arena(int(state.range(0)));
    const int packetRows = bench::kHeight / 4;
    std::vector<float> image(size_t(bench::kWidth) * bench::kHeight * 3);
    IterationTimes times;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] {
            tbb::parallel_for(0, packetRows, [&](int row) {
                ShadingPacket packet;
                PacketAccumulator accumulator;
                for (int x0 = 0; x0 < bench::kWidth; x0 += 4) {
                    f.decoder->decode(isa, x0, row * 4, packet);
                    accumulator.clear();
                    lighting::kernel::shadePacket(isa, packet, packet.laneMask, *f.lights,
                                                  f.everyLight, accumulator, true);
                    for (int lane = 0; lane < lighting::kernel::kPacketLanes; ++lane) {
                        const size_t pixel =
                            size_t(row * 4 + lane / 4) * bench::kWidth + size_t(x0 + lane % 4);
                        for (int k = 0; k < 3; ++k)
                            image[pixel * 3 + size_t(k)] = accumulator.radiance[k][lane];
                    }
                }
            });
        });
        times.add(state,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    benchmark::DoNotOptimize(image.data());
    const double pixelLights = double(f.coveredPixels) * double(f.everyLight.size());
    // Wall-clock nanoseconds per pixel-light (not per core), as bruteShading reports.
    state.counters["ns/pixel-light_min"] = times.fastest() * 1e9 / pixelLights;
    state.counters["ns/pixel-light_median"] = times.median() * 1e9 / pixelLights;
    state.SetLabel(isa.name());
}

// Synthetic: a 1 m x 1 m patch of a wall facing the camera at z = -4 (lanes 1 cm apart), lit by
// point lights 0.5-1.5 m in front of it with ranges of 6 m: every lane receives every light.
struct ContributingCase {
    std::vector<ShadingPacket> packets;
    std::unique_ptr<KernelLights> lights;
    std::vector<uint32_t> indices;
};

// metallicRoughness: the same packets with metallic-roughness surfaces (roughness 0.2-0.8,
// metallic 0, 0.5 or 1 by packet).
ContributingCase makeContributingCase(bool metallicRoughness) {
    {
        ContributingCase r;
        for (int p = 0; p < 256; ++p) {
            ShadingPacket packet;
            packet.clear();
            const float px = float(p % 16) * 0.04f - 0.32f, py = float(p / 16) * 0.04f - 0.32f;
            for (int lane = 0; lane < lighting::kernel::kPacketLanes; ++lane) {
                const glm::vec3 position(px + 0.01f * float(lane % 4), py + 0.01f * float(lane / 4),
                                         -4.0f);
                const float power = float(8 << (p % 6)); // 8..256
                packet.setLane(lane, position, {0.0f, 0.0f, 1.0f}, {0.6f, 0.5f, 0.4f}, 0.3f, power);
                if (metallicRoughness)
                    packet.setMetallicRoughness(lane, 0.2f + 0.1f * float(p % 7),
                                                0.5f * float(p % 3), 1.0f);
            }
            r.packets.push_back(packet);
        }
        std::vector<lighting::LightInView<float>> lights;
        for (int i = 0; i < 64; ++i) {
            lighting::LightInView<float> light;
            light.type = scenes::LightType::Point;
            const float a = 2.399963f * float(i);
            light.positionView = {0.8f * std::cos(a), 0.8f * std::sin(a),
                                  -3.5f + 0.5f * float(i % 3)};
            light.radiance = {1.0f, 0.9f, 0.8f};
            light.rangeMetres = 6.0f;
            lights.push_back(light);
        }
        r.lights = std::make_unique<KernelLights>(lights);
        r.indices.resize(lights.size());
        std::iota(r.indices.begin(), r.indices.end(), 0u);
        return r;
    }
}

const ContributingCase& contributingCase(bool metallicRoughness = false) {
    static const ContributingCase blinnPhong = makeContributingCase(false);
    static const ContributingCase ggx = makeContributingCase(true);
    return metallicRoughness ? ggx : blinnPhong;
}

void reportFlops(benchmark::State& state, const KernelIsa& isa, double flopsPerIteration,
                 const IterationTimes& times) {
    state.counters["GFLOP/s_best"] = flopsPerIteration / times.fastest() * 1e-9;
    state.counters["peak_GFLOP/s"] = peakFlops(isa) * 1e-9;
    state.counters["of_peak_best"] = flopsPerIteration / times.fastest() / peakFlops(isa);
    state.counters["of_peak_median"] = flopsPerIteration / times.median() / peakFlops(isa);
    state.SetLabel(isa.name());
}

void kernelContributingOf(benchmark::State& state, const KernelIsa& isa, bool metallicRoughness) {
    const ContributingCase& c = contributingCase(metallicRoughness);
    PacketAccumulator accumulator;
    IterationTimes times;
    for (auto _ : state) {
        const double start = bench::threadCpuSeconds();
        for (const ShadingPacket& packet : c.packets) {
            accumulator.clear();
            // The evaluation alone: no oracle count (a culling stage's call).
            lighting::kernel::shadePacket(isa, packet, lighting::kernel::kAllLanes, *c.lights,
                                          c.indices, accumulator, false);
        }
        benchmark::DoNotOptimize(accumulator);
        times.add(state, bench::threadCpuSeconds() - start);
    }
    // Checked outside the timer: every lane-light contributes.
    uint64_t contributing = 0;
    for (const ShadingPacket& packet : c.packets) {
        accumulator.clear();
        lighting::kernel::shadePacket(isa, packet, lighting::kernel::kAllLanes, *c.lights,
                                      c.indices, accumulator, true);
        for (uint32_t n : accumulator.lightsContributing)
            contributing += n;
    }
    const double laneLights = double(c.packets.size()) * 16.0 * double(c.indices.size());
    if (double(contributing) != laneLights)
        state.SkipWithError("not every lane-light contributes");
    const double flops =
        metallicRoughness ? kGgxPointLightFlops : flopsPerEvaluation(scenes::LightType::Point);
    reportFlops(state, isa, laneLights * flops, times);
    state.counters["flops/evaluation"] = flops;
    state.counters["cycles/packet-light_best"] = times.fastest() * clockHz() * 16.0 / laneLights;
    state.counters["cycles/packet-light_median"] = times.median() * clockHz() * 16.0 / laneLights;
}

void kernelContributing(benchmark::State& state, const KernelIsa& isa) {
    kernelContributingOf(state, isa, false);
}

void kernelContributingGgx(benchmark::State& state, const KernelIsa& isa) {
    kernelContributingOf(state, isa, true);
}

// Per packet of the atrium: the lights contributing to at least one lane (found with the widest
// vector path, one light at a time), and the flops of the contributing lane-lights.
struct IdealLists {
    std::vector<std::vector<uint32_t>> lists;
    double contributingFlops = 0;
    uint64_t laneLights = 0; // lane-lights walked: active lanes x list length
    uint64_t contributingLaneLights = 0;
};

const IdealLists& idealLists() {
    static const IdealLists lists = [] {
        const AtriumKernelFrame& f = atriumKernelFrame();
        IdealLists r;
        r.lists.resize(f.packets.size());
        PacketAccumulator accumulator;
        for (size_t p = 0; p < f.packets.size(); ++p) {
            const ShadingPacket& packet = f.packets[p];
            for (uint32_t index : f.everyLight) {
                accumulator.clear();
                const uint32_t one[1] = {index};
                lighting::kernel::shadePacket(KernelIsa::best(), packet,
                                              lighting::kernel::kAllLanes, *f.lights, one,
                                              accumulator);
                uint32_t lanes = 0;
                for (uint32_t n : accumulator.lightsContributing)
                    lanes += n;
                if (lanes == 0)
                    continue;
                r.lists[p].push_back(index);
                r.contributingLaneLights += lanes;
                r.contributingFlops +=
                    double(lanes) * flopsPerEvaluation(f.lights->source()[index].type);
                r.laneLights += uint64_t(__builtin_popcount(packet.laneMask));
            }
        }
        return r;
    }();
    return lists;
}

void kernelIdealAtrium(benchmark::State& state, const KernelIsa& isa) {
    const AtriumKernelFrame& f = atriumKernelFrame();
    const IdealLists& ideal = idealLists();
    PacketAccumulator accumulator;
    IterationTimes times;
    for (auto _ : state) {
        const double start = bench::threadCpuSeconds();
        for (size_t p = 0; p < f.packets.size(); ++p) {
            accumulator.clear();
            lighting::kernel::shadePacket(isa, f.packets[p], lighting::kernel::kAllLanes, *f.lights,
                                          ideal.lists[p], accumulator, false);
        }
        benchmark::DoNotOptimize(accumulator);
        times.add(state, bench::threadCpuSeconds() - start);
    }
    reportFlops(state, isa, ideal.contributingFlops, times);
    state.counters["lane_occupancy"] =
        double(ideal.contributingLaneLights) / double(ideal.laneLights);
}

void packetDecode(benchmark::State& state, const KernelIsa& isa) {
    const AtriumKernelFrame& f = atriumKernelFrame();
    ShadingPacket packet;
    uint64_t covered = 0;
    IterationTimes times;
    for (auto _ : state) {
        const double start = bench::threadCpuSeconds();
        covered = 0;
        for (int y0 = 0; y0 < bench::kHeight; y0 += 4)
            for (int x0 = 0; x0 < bench::kWidth; x0 += 4) {
                f.decoder->decode(isa, x0, y0, packet);
                covered += packet.laneMask;
                benchmark::ClobberMemory();
            }
        times.add(state, bench::threadCpuSeconds() - start);
    }
    benchmark::DoNotOptimize(covered);
    state.counters["ns/pixel_min"] = times.fastest() * 1e9 / (bench::kWidth * bench::kHeight);
    state.counters["ns/pixel_median"] = times.median() * 1e9 / (bench::kWidth * bench::kHeight);
    state.SetLabel(isa.name());
}

void gbufferDecodePerPixel(benchmark::State& state) {
    const AtriumKernelFrame& f = atriumKernelFrame();
    const gbuffer::GBuffer& gb = *f.frame->gbuffer;
    float sum = 0;
    IterationTimes times;
    for (auto _ : state) {
        const double start = bench::threadCpuSeconds();
        for (int y = 0; y < gb.height(); ++y)
            for (int x = 0; x < gb.width(); ++x) {
                if (!gb.covered(size_t(y) * gb.width() + x))
                    continue;
                const gbuffer::Surface s = gb.decode(x, y);
                sum += s.positionView.z + s.albedo.r;
            }
        times.add(state, bench::threadCpuSeconds() - start);
    }
    benchmark::DoNotOptimize(sum);
    state.counters["ns/pixel_min"] = times.fastest() * 1e9 / double(gb.pixelCount());
    state.counters["ns/pixel_median"] = times.median() * 1e9 / double(gb.pixelCount());
}
BENCHMARK(gbufferDecodePerPixel)->UseManualTime()->MinTime(2.0)->Unit(benchmark::kMillisecond);

void machinePeak(benchmark::State& state) {
    double clock = 0;
    for (auto _ : state)
        clock = clockHz();
    state.counters["clock_GHz"] = clock * 1e-9;
    const KernelIsa best = KernelIsa::best();
    state.counters["auto_lanes"] = best.vectorLanes();
    state.counters["auto_peak_GFLOP/s"] = peakFlops(best) * 1e-9;
    if (__builtin_cpu_supports("fma"))
        state.counters["fma_per_cycle_256"] = bench::measuredFmaPerSecond(256) / clock;
    if (__builtin_cpu_supports("avx512f"))
        state.counters["fma_per_cycle_512"] = bench::measuredFmaPerSecond(512) / clock;
    state.SetLabel("auto = " + best.name());
}
BENCHMARK(machinePeak)->Iterations(1);

const bool kRegistered = [] {
    registerPerIsa("kernelBruteShading", kernelBruteShading);
    registerPerIsa("kernelBruteFrame", kernelBruteFrame, {1, 2});
    for (const KernelIsa& isa : KernelIsa::available())
        if (!isa.isScalar())
            // Not a structured binding: clang 14 (the sanitizer and fuzzer builds) cannot
            // capture one in a lambda.
            for (const auto& entry :
                 {std::pair{"kernelBruteSpeedup/", &kernelBruteSpeedup},
                  std::pair{"kernelBruteSpeedupHelmet/", &kernelBruteSpeedupHelmet}})
                benchmark::RegisterBenchmark((entry.first + isa.name()).c_str(),
                                             [isa, function = entry.second](
                                                 benchmark::State& state) { function(state, isa); })
                    ->UseManualTime()
                    ->MinTime(4.0)
                    ->Unit(benchmark::kMillisecond);
    registerPerIsa("kernelContributing", kernelContributing);
    registerPerIsa("kernelContributingGgx", kernelContributingGgx);
    registerPerIsa("kernelIdealAtrium", kernelIdealAtrium);
    registerPerIsa("packetDecode", packetDecode);
    return true;
}();

} // namespace
