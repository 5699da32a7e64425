// Shadow-map rendering on `atrium` (issue 29's target: 16 casting point lights, cube maps of
// 512^2, 96 faces, <= 15 ms on 2 threads), at 1 and 2 threads, with the faces in parallel (one
// Rasterizer per thread) or in sequence (the rasterizer's own tile parallelism). Reports ms per
// render (manual time: mean; minimum and median beside it, as a shared machine inflates the
// mean), faces, triangles drawn and bytes.
// shadowLookup: the cost of one lookup in the same maps, the scalar ShadowMaps::visibility lane by
// lane against the kernel's vector lookup (VectorShadows-inl.h, the dispatched target) a packet
// of 16 lanes at a time, per filter, on one thread.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include <random>

#include <tbb/task_arena.h>

#include "lighting/kernel/VectorTargets.h"

#include "gbuffer/visibility/CameraView.h"
#include "gbuffer/visibility/SceneGeometry.h"
#include "lighting/shadows/ShadowMaps.h"
#include "tests/bench/BenchScenes.h"

namespace {

struct ShadowFrame {
    scenes::Scene scene;
    gbuffer::SceneGeometry geometry;
    gbuffer::CameraView view;
};

// Atrium with 256 generated lights (seed 1), the first 16 point lights casting.
const ShadowFrame& atrium() {
    static const ShadowFrame frame = [] {
        ShadowFrame f;
        f.scene = bench::proceduralScene("atrium", 256);
        int casting = 0;
        for (scenes::Light& light : f.scene.lights)
            if (light.type == scenes::LightType::Point && casting < 16) {
                light.castsShadows = true;
                ++casting;
            }
        f.geometry = gbuffer::SceneGeometry::build(f.scene);
        f.view = gbuffer::CameraView::fromCamera(f.scene.cameras[0], bench::kWidth, bench::kHeight);
        return f;
    }();
    return frame;
}

// Renders `f`'s maps once per benchmark iteration under `threads` (each frame taking over the
// last frame's buffers when `recycle`), timed by hand; sets the counters render_ms_min,
// render_ms_median and faces, and returns the last frame's statistics.
lighting::ShadowStats timeRenders(benchmark::State& state, const ShadowFrame& f,
                                  const lighting::ShadowSettings& settings, int threads,
                                  bool recycle) {
    tbb::task_arena arena(threads);
    std::vector<double> renderMs;
    lighting::ShadowStats stats;
    lighting::ShadowMaps previous; // the last frame's, whose buffers a frame may take over
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        arena.execute([&] {
            previous = lighting::ShadowMaps::render(f.scene, f.geometry, f.view, settings,
                                                    recycle ? &previous : nullptr);
            stats = previous.stats();
        });
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        state.SetIterationTime(seconds);
        renderMs.push_back(seconds * 1e3);
    }
    std::sort(renderMs.begin(), renderMs.end());
    state.counters["render_ms_min"] = renderMs.front();
    state.counters["render_ms_median"] = renderMs[renderMs.size() / 2];
    state.counters["faces"] = double(stats.faceCount);
    state.counters["faces_outside_view"] = double(stats.facesOutsideView);
    return stats;
}

// range(0): threads; range(1): 0 = faces in parallel, 1 = faces in sequence; range(2): 1 = each
// frame takes over the last frame's depth buffers (what the runner does), 0 = fresh buffers;
// range(3): 1 = each face drops the casters outside its frustum before the draw (the default),
// 0 = every face hands its light's whole caster list to the rasterizer (the same maps).
void shadowMapRender(benchmark::State& state) {
    const ShadowFrame& f = atrium();
    lighting::ShadowSettings settings;
    settings.mapSize = 512;
    settings.schedule = state.range(1) == 0 ? lighting::ShadowSchedule::FacesInParallel
                                            : lighting::ShadowSchedule::FacesInSequence;
    settings.cullCastersPerFace = state.range(3) == 1;
    state.SetLabel(std::string(state.range(1) == 0 ? "faces in parallel" : "faces in sequence") +
                   (state.range(2) == 1 ? ", buffers recycled" : ", fresh buffers") +
                   (state.range(3) == 1 ? ", per-face cull" : ", whole lists"));
    const lighting::ShadowStats stats =
        timeRenders(state, f, settings, int(state.range(0)), state.range(2) == 1);
    uint64_t triangles = 0;
    for (const lighting::ShadowLightStats& light : stats.lights)
        triangles += light.trianglesDrawn;
    state.counters["triangles_drawn"] = double(triangles);
    state.counters["scene_triangles"] = double(f.geometry.triangleCount());
    state.counters["MB"] = double(stats.totalBytes) / (1024.0 * 1024.0);
}
BENCHMARK(shadowMapRender)
    ->ArgsProduct({{1, 2}, {0, 1}, {0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// Faces outside the camera's view (ShadowSettings::cullFacesOutsideView) on atrium's 16 casting
// point lights at 512^2, buffers recycled, faces in parallel, per-face cull. range(0): threads;
// range(1): 1 = faces no receiver in view can select are left empty (the default), 0 = every
// face drawn (the same image).
void shadowMapRenderFaceCull(benchmark::State& state) {
    const ShadowFrame& f = atrium();
    lighting::ShadowSettings settings;
    settings.mapSize = 512;
    settings.cullFacesOutsideView = state.range(1) == 1;
    state.SetLabel(state.range(1) == 1 ? "faces outside the view left empty" : "every face drawn");
    const lighting::ShadowStats stats = timeRenders(state, f, settings, int(state.range(0)), true);
    uint64_t triangles = 0;
    for (const lighting::ShadowLightStats& light : stats.lights)
        triangles += light.trianglesDrawn;
    state.counters["triangles_drawn"] = double(triangles);
    state.counters["MB"] = double(stats.totalBytes) / (1024.0 * 1024.0);
}
BENCHMARK(shadowMapRenderFaceCull)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// The depth format (ShadowSettings.h ShadowDepthFormat) on atrium's 16 casting point lights at
// 512^2, buffers recycled, faces in parallel, per-face cull. range(0): threads; range(1): 0 =
// float32, 1 = unorm16 (drawn into the thread's float buffer, then packed: the packing's cost).
void shadowMapRenderDepthFormat(benchmark::State& state) {
    const ShadowFrame& f = atrium();
    lighting::ShadowSettings settings;
    settings.mapSize = 512;
    settings.depthFormat = state.range(1) == 1 ? lighting::ShadowDepthFormat::Unorm16
                                               : lighting::ShadowDepthFormat::Float32;
    state.SetLabel(lighting::formatShadowDepthFormat(settings.depthFormat));
    const lighting::ShadowStats stats = timeRenders(state, f, settings, int(state.range(0)), true);
    state.counters["MB"] = double(stats.totalBytes) / (1024.0 * 1024.0);
}
BENCHMARK(shadowMapRenderDepthFormat)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// Alpha-tested casters (CasterMaterials.h): `foliage` (12 leaf cards of a textured Mask
// material, 664 triangles) with 16 generated point lights (seed 1) and its sun casting, cube maps
// of 512^2 (97 faces), buffers recycled, faces in parallel. range(0): threads; range(1): 1 = the
// cards alpha-tested per texel (what the testbed renders), 0 = the same scene with the cards'
// material made Opaque (the depth-only span path): the test's cost is the difference.
const ShadowFrame& foliage(bool alphaTested) {
    auto make = [](bool opaqueCards) {
        ShadowFrame f;
        f.scene = bench::proceduralScene("foliage", 16);
        for (scenes::Material& material : f.scene.materials)
            if (opaqueCards && material.alphaMode == scenes::AlphaMode::Mask)
                material.alphaMode = scenes::AlphaMode::Opaque;
        f.geometry = gbuffer::SceneGeometry::build(f.scene);
        f.view = gbuffer::CameraView::fromCamera(f.scene.cameras[0], bench::kWidth, bench::kHeight);
        return f;
    };
    static const ShadowFrame frames[2] = {make(true), make(false)};
    return frames[alphaTested ? 1 : 0];
}

void shadowMapRenderAlphaTested(benchmark::State& state) {
    const ShadowFrame& f = foliage(state.range(1) == 1);
    lighting::ShadowSettings settings;
    settings.mapSize = 512;
    state.SetLabel(state.range(1) == 1 ? "cards alpha-tested" : "cards opaque");
    timeRenders(state, f, settings, int(state.range(0)), true);
}
BENCHMARK(shadowMapRenderAlphaTested)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);

// The atrium's maps (512^2, the filter of `filterIndex`: none, pcf3, pcf5, poisson) and packets of
// receivers: each packet 16 points within 5 cm of a centre drawn uniformly in the ball of 0.9 x
// the range of one casting light (a 4x4 pixel block's spread on a surface a few metres away),
// one random unit normal per packet, the light's shadow beside it.
struct LookupFrame {
    lighting::ShadowMaps maps;
    std::vector<lighting::kernel::ShadingPacket> packets;
    std::vector<uint32_t> shadows; // per packet
};

const LookupFrame& lookupFrame(int filterIndex, int formatIndex) {
    static LookupFrame frames[4][2];
    static bool built[4][2] = {};
    LookupFrame& frame = frames[filterIndex][formatIndex];
    if (built[filterIndex][formatIndex])
        return frame;
    built[filterIndex][formatIndex] = true;
    const ShadowFrame& f = atrium();
    lighting::ShadowSettings settings;
    settings.mapSize = 512;
    settings.filter = lighting::ShadowFilter(filterIndex);
    settings.depthFormat = formatIndex == 1 ? lighting::ShadowDepthFormat::Unorm16
                                            : lighting::ShadowDepthFormat::Float32;
    frame.maps = lighting::ShadowMaps::render(f.scene, f.geometry, f.view, settings);
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    auto inBall = [&] {
        glm::vec3 v;
        do
            v = {unit(random), unit(random), unit(random)};
        while (glm::dot(v, v) > 1.0f);
        return v;
    };
    constexpr size_t kPackets = 4096;
    for (size_t i = 0; i < kPackets; ++i) {
        const size_t lightIndex = f.scene.lights.size() * (random() % 1024) / 1024;
        const uint32_t shadow = frame.maps.shadowOf(lightIndex);
        if (shadow == lighting::ShadowMaps::kNoShadow) {
            --i;
            continue;
        }
        const scenes::Light& light = f.scene.lights[lightIndex];
        const glm::vec3 centreWorld = light.positionWorld + 0.9f * light.rangeMetres * inBall();
        const glm::vec3 centre(f.view.viewFromWorldExact * glm::dvec4(centreWorld, 1.0));
        const glm::vec3 normal = glm::normalize(inBall() + glm::vec3(0.0f, 0.0f, 1e-3f));
        lighting::kernel::ShadingPacket packet{};
        for (size_t l = 0; l < lighting::kernel::kPacketLanes; ++l) {
            const glm::vec3 p = centre + 0.05f * inBall();
            for (int k = 0; k < 3; ++k) {
                packet.positionView[k][l] = p[k];
                packet.normalView[k][l] = normal[k];
            }
        }
        frame.packets.push_back(packet);
        frame.shadows.push_back(shadow);
    }
    return frame;
}

// range(0): 0 = scalar ShadowMaps::visibility per lane, 1 = the vector lookup per packet;
// range(1): the filter (0 none, 1 pcf3, 2 pcf5, 3 poisson); range(2): the depth format (0
// float32, 1 unorm16).
void shadowLookup(benchmark::State& state) {
    const LookupFrame& frame = lookupFrame(int(state.range(1)), int(state.range(2)));
    const bool vector = state.range(0) == 1;
    const lighting::kernel::VectorFunctions* target = lighting::kernel::dispatchedVectorTarget();
    state.SetLabel(std::string(vector ? target->name : "scalar") + ", " +
                   lighting::formatShadowFilter(lighting::ShadowFilter(state.range(1))) + ", " +
                   (state.range(2) == 1 ? "unorm16" : "float32"));
    constexpr size_t kLanes = lighting::kernel::kPacketLanes;
    float visibility[kLanes];
    double sum = 0.0;
    for (auto _ : state) {
        for (size_t i = 0; i < frame.packets.size(); ++i) {
            const lighting::kernel::ShadingPacket& packet = frame.packets[i];
            if (vector) {
                target->shadowVisibility(lighting::kernel::ShadowVisibilityArgs{
                    frame.maps.view(), frame.shadows[i], &packet, 0xffffu, visibility});
            } else {
                for (size_t l = 0; l < kLanes; ++l)
                    visibility[l] = frame.maps.visibility(
                        frame.shadows[i],
                        glm::vec3(packet.positionView[0][l], packet.positionView[1][l],
                                  packet.positionView[2][l]),
                        glm::vec3(packet.normalView[0][l], packet.normalView[1][l],
                                  packet.normalView[2][l]));
            }
            for (float v : visibility)
                sum += v;
        }
    }
    benchmark::DoNotOptimize(sum);
    // items_per_second: lookups per CPU second (1e9 / it = CPU ns per lookup; CPU time, because
    // wall time on the shared machine includes other jobs' time slices).
    state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(frame.packets.size() * kLanes));
}
BENCHMARK(shadowLookup)->ArgsProduct({{0, 1}, {0, 1, 2, 3}, {0, 1}})->Unit(benchmark::kMillisecond);

} // namespace
