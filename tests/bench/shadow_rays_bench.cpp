// Benchmarks of the ray-traced shadow visibility (lighting/shadows/RayVisibility.h, Embree 3):
//   shadowBvhBuild/<scene>/<t>   RayVisibility's constructor (degenerate filter, conversion to
//                                float, Embree BVH at RTC_BUILD_QUALITY_HIGH, robust) in a
//                                t-thread TBB arena: milliseconds per build, wall clock; the
//                                bytes Embree holds per triangle (its memory monitor)
//   shadowRaysSingle/<scene>     2^16 random shadow rays, one occluded() call each, one thread:
//                                rays per second of thread CPU time
//   shadowRaysBatched/<scene>    the same rays through the batched call (rtcOccluded16 packets)
//                                in a 1-thread arena: rays per second of wall time
// Scenes: atrium (the default procedural scene) and DamagedHelmet (glTF). The rays: a point on a
// random triangle (uniform over triangles, uniform on the triangle), its geometric normal turned
// toward the light, to a point light uniform in the scene's bounding box: incoherent, as a
// reference's shadow rays from every pixel to every light are. `occluded` is the fraction
// blocked.
//   build/bin/testbed_bench --benchmark_counters_tabular=true --benchmark_filter=shadow
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/RayVisibility.h"
#include "scenes/SceneLoader.h"
#include "tests/bench/BenchScenes.h"

namespace {

using lighting::shadows::RayVisibility;
using lighting::shadows::ShadowRay;

constexpr size_t kRayCount = size_t(1) << 16;

scenes::Scene benchScene(const std::string& name) {
    if (name == "atrium")
        return bench::proceduralScene("atrium", 256);
    scenes::SceneRequest request;
    request.lightCount = 256;
    request.seed = 1;
    return scenes::loadScene(TESTBED_GLTF_DIR "/DamagedHelmet/DamagedHelmet.gltf", request);
}

// The scene's geometry, its BVH and the random rays, made once per scene.
struct ShadowFixture {
    gbuffer::SceneGeometry geometry;
    std::unique_ptr<RayVisibility> visibility;
    std::vector<ShadowRay> rays;

    explicit ShadowFixture(const std::string& name)
        : geometry(gbuffer::SceneGeometry::build(benchScene(name))) {
        visibility = std::make_unique<RayVisibility>(geometry);
        glm::dvec3 low(1e300), high(-1e300);
        for (const glm::dvec3& p : geometry.positionWorldExact) {
            low = glm::min(low, p);
            high = glm::max(high, p);
        }
        std::mt19937 random(1);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        std::uniform_int_distribution<uint32_t> triangle(0, geometry.triangleCount() - 1);
        while (rays.size() < kRayCount) {
            const uint32_t t = triangle(random);
            const glm::dvec3 a = geometry.positionWorldExact[geometry.indices[3 * t]];
            const glm::dvec3 b = geometry.positionWorldExact[geometry.indices[3 * t + 1]];
            const glm::dvec3 c = geometry.positionWorldExact[geometry.indices[3 * t + 2]];
            const glm::dvec3 normal = glm::cross(b - a, c - a);
            if (!(glm::dot(normal, normal) > 0.0))
                continue;
            double u = unit(random);
            double v = unit(random);
            if (u + v > 1.0) {
                u = 1.0 - u;
                v = 1.0 - v;
            }
            const glm::dvec3 surface = a + (b - a) * u + (c - a) * v;
            const double x = unit(random);
            const double y = unit(random);
            const double z = unit(random);
            const glm::dvec3 light = low + (high - low) * glm::dvec3(x, y, z);
            const double side = glm::dot(normal, light - surface) < 0.0 ? -1.0 : 1.0;
            rays.push_back(ShadowRay::toPoint(surface, normal * side, light));
        }
    }
};

ShadowFixture& fixture(const std::string& name) {
    static std::map<std::string, std::unique_ptr<ShadowFixture>> fixtures;
    auto& slot = fixtures[name];
    if (!slot)
        slot = std::make_unique<ShadowFixture>(name);
    return *slot;
}

void shadowBvhBuild(benchmark::State& state, const std::string& name) {
    const ShadowFixture& f = fixture(name);
    tbb::task_arena arena(int(state.range(0)));
    size_t triangles = 0;
    size_t bytes = 0;
    for (auto _ : state) {
        double milliseconds = 0.0;
        arena.execute([&] {
            const RayVisibility visibility(f.geometry);
            milliseconds = visibility.buildMilliseconds();
            triangles = visibility.triangleCount();
            bytes = visibility.embreeBytes();
        });
        state.SetIterationTime(milliseconds * 1e-3);
    }
    state.counters["triangles"] = double(triangles);
    state.counters["threads"] = double(state.range(0));
    state.counters["bytes/triangle"] = double(bytes) / double(triangles);
}

void shadowRaysSingle(benchmark::State& state, const std::string& name) {
    const ShadowFixture& f = fixture(name);
    size_t occluded = 0;
    for (auto _ : state) {
        occluded = 0;
        for (const ShadowRay& ray : f.rays)
            occluded += f.visibility->occluded(ray) ? 1 : 0;
        benchmark::DoNotOptimize(occluded);
    }
    state.counters["rays/s"] =
        benchmark::Counter(double(f.rays.size()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["occluded"] = double(occluded) / double(f.rays.size());
    state.counters["triangles"] = double(f.visibility->triangleCount());
}

void shadowRaysBatched(benchmark::State& state, const std::string& name) {
    const ShadowFixture& f = fixture(name);
    tbb::task_arena arena(1);
    std::vector<uint8_t> result(f.rays.size());
    for (auto _ : state)
        arena.execute([&] { f.visibility->occluded(f.rays, result); });
    size_t occluded = 0;
    for (const uint8_t r : result)
        occluded += r;
    state.counters["rays/s"] =
        benchmark::Counter(double(f.rays.size()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["occluded"] = double(occluded) / double(f.rays.size());
}

} // namespace

BENCHMARK_CAPTURE(shadowBvhBuild, atrium, std::string("atrium"))
    ->Arg(1)
    ->Arg(2)
    ->UseManualTime()
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(shadowBvhBuild, DamagedHelmet, std::string("DamagedHelmet"))
    ->Arg(1)
    ->Arg(2)
    ->UseManualTime()
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(shadowRaysSingle, atrium, std::string("atrium"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(shadowRaysSingle, DamagedHelmet, std::string("DamagedHelmet"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(shadowRaysBatched, atrium, std::string("atrium"))
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(shadowRaysBatched, DamagedHelmet, std::string("DamagedHelmet"))
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
