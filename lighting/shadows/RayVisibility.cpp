#include "lighting/shadows/RayVisibility.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "lighting/shadows/CasterMaterials.h"

namespace lighting::shadows {

namespace {

constexpr size_t kPacketSize = 16; // rtcOccluded16
// Packets per TBB task of the batched query: 1024 rays, a few hundred microseconds of work.
constexpr size_t kPacketsPerTask = 64;

// The first error Embree reports during construction, with its message (Embree's own text is
// better than the bare code). Used only by the constructor, before the object is shared.
struct ErrorLog {
    RTCError code = RTC_ERROR_NONE;
    std::string message;
};

void logError(void* userPointer, RTCError code, const char* message) {
    auto* log = static_cast<ErrorLog*>(userPointer);
    if (log->code == RTC_ERROR_NONE) {
        log->code = code;
        log->message = message ? message : "";
    }
}

void throwOnError(RTCDevice device, const ErrorLog& log, const char* step) {
    const RTCError code = rtcGetDeviceError(device);
    if (code == RTC_ERROR_NONE && log.code == RTC_ERROR_NONE)
        return;
    throw std::runtime_error(std::string("RayVisibility: Embree failed at ") + step + " (error " +
                             std::to_string(int(log.code != RTC_ERROR_NONE ? log.code : code)) +
                             (log.message.empty() ? "" : ": " + log.message) + ")");
}

// Embree's memory monitor: the bytes it holds (allocations add, frees subtract), from every
// thread of its parallel build. Returning true lets every allocation proceed.
bool countBytes(void* userPointer, ssize_t bytes, bool post) {
    static_cast<std::atomic<int64_t>*>(userPointer)
        ->fetch_add(int64_t(bytes), std::memory_order_relaxed);
    return true;
}

// Kept iff Embree can intersect it: finite float vertices spanning a non-zero area. The cross
// product is taken in double of the float vertices, so "non-zero" is exact for what Embree sees.
bool usable(const std::array<glm::vec3, 3>& v) {
    for (const glm::vec3& p : v)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return false;
    const glm::dvec3 a(v[0]);
    const glm::dvec3 cross = glm::cross(glm::dvec3(v[1]) - a, glm::dvec3(v[2]) - a);
    return cross != glm::dvec3(0.0);
}

// Embree's ray of a segment: the float rounding of the double segment. tnear = 0 (the origin is
// already offset), tfar the length (+infinity for directional lights).
float farOf(const ShadowSegment& segment) {
    return std::isinf(segment.lengthWorld) ? std::numeric_limits<float>::infinity()
                                           : float(segment.lengthWorld);
}

} // namespace

void RayVisibility::DeviceRelease::operator()(RTCDeviceTy* device) const {
    rtcReleaseDevice(device);
}

void RayVisibility::SceneRelease::operator()(RTCSceneTy* scene) const {
    rtcReleaseScene(scene);
}

struct RayAlphaFilter {
    CasterAlphaTest test;
    std::vector<uint32_t> sceneTriangle; // per primitive of the filtered geometry
};

namespace {

// Embree's occlusion filter of the alpha-tested geometry: a hit where the caster's alpha does not
// pass is rejected (valid = 0), and the traversal goes on to the next hit.
void alphaTestedHit(const RTCFilterFunctionNArguments* args) {
    const auto* filter = static_cast<const RayAlphaFilter*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1)
            continue;
        const unsigned primitive = RTCHitN_primID(args->hit, args->N, i);
        const float u = RTCHitN_u(args->hit, args->N, i);
        const float v = RTCHitN_v(args->hit, args->N, i);
        if (!filter->test.casts(filter->sceneTriangle[primitive], glm::vec3(1.0f - u - v, u, v)))
            args->valid[i] = 0;
    }
}

} // namespace

RayVisibility::RayVisibility(const gbuffer::SceneGeometry& geometry,
                             std::span<const uint8_t> castingMaterial) {
    build(geometry, castingMaterial, nullptr);
}

RayVisibility::RayVisibility(const scenes::Scene& scene, const gbuffer::SceneGeometry& geometry) {
    const CasterAlphaTest alphaTest(scene, geometry);
    build(geometry, castingMaterials(scene), alphaTest.any() ? &alphaTest : nullptr);
}

size_t RayVisibility::alphaTestedTriangleCount() const {
    return mAlphaFilter ? mAlphaFilter->sceneTriangle.size() : 0;
}

void RayVisibility::build(const gbuffer::SceneGeometry& geometry,
                          std::span<const uint8_t> castingMaterial,
                          const CasterAlphaTest* alphaTest) {
    const auto start = std::chrono::steady_clock::now();
    const size_t vertexCount = geometry.positionWorldExact.size();
    const size_t sceneTriangleCount = geometry.indices.size() / 3;
    if (vertexCount > std::numeric_limits<uint32_t>::max() ||
        sceneTriangleCount > std::numeric_limits<uint32_t>::max())
        throw std::length_error("RayVisibility: more than 2^32 - 1 vertices or triangles");

    mDevice.reset(rtcNewDevice("verbose=0"));
    if (!mDevice)
        throw std::runtime_error("RayVisibility: Embree could not create a device (error " +
                                 std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    RTCDevice device = mDevice.get();
    ErrorLog log;
    rtcSetDeviceErrorFunction(device, logError, &log);
    std::atomic<int64_t> embreeBytes{0};
    rtcSetDeviceMemoryMonitorFunction(device, countBytes, &embreeBytes);

    // The triangles Embree can use: the opaque ones as float vertex indices (vertices are shared,
    // unfiltered: Embree reads only the ones the kept triangles name), the alpha-tested ones with
    // three corners each in their own geometry, whose filter maps a primitive to its triangle.
    std::vector<uint32_t> kept;
    kept.reserve(geometry.indices.size());
    std::vector<glm::vec3> testedCorners;
    std::vector<uint32_t> testedTriangle;
    for (size_t t = 0; t < sceneTriangleCount; ++t) {
        if (!castingMaterial.empty() && t < geometry.triangleMaterial.size() &&
            geometry.triangleMaterial[t] < castingMaterial.size() &&
            !castingMaterial[geometry.triangleMaterial[t]])
            continue;
        std::array<glm::vec3, 3> corner;
        bool inRange = true;
        for (int i = 0; i < 3; ++i) {
            const uint32_t index = geometry.indices[3 * t + i];
            inRange = inRange && index < vertexCount;
            if (inRange)
                corner[i] = glm::vec3(geometry.positionWorldExact[index]);
        }
        if (!inRange || !usable(corner))
            continue;
        if (alphaTest && alphaTest->tested(uint32_t(t))) {
            testedCorners.insert(testedCorners.end(), corner.begin(), corner.end());
            testedTriangle.push_back(uint32_t(t));
            continue;
        }
        kept.insert(kept.end(), geometry.indices.begin() + 3 * t,
                    geometry.indices.begin() + 3 * t + 3);
    }
    mTriangleCount = kept.size() / 3 + testedTriangle.size();
    mDroppedTriangleCount = sceneTriangleCount - mTriangleCount;

    mScene.reset(rtcNewScene(device));
    throwOnError(device, log, "rtcNewScene");
    RTCScene scene = mScene.get();
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    // One triangle geometry of `vertices` (float3) and `triangles` index triples, in buffers
    // Embree allocates itself, with the padding its vector loads need past the last vertex.
    auto attach = [&](size_t vertexTotal, auto vertexAt, std::span<const uint32_t> triangles,
                      RTCFilterFunctionN occludedFilter, void* userData) {
        RTCGeometry mesh = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        throwOnError(device, log, "rtcNewGeometry");
        rtcSetGeometryBuildQuality(mesh, RTC_BUILD_QUALITY_HIGH);
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertexTotal));
        auto* indices = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(uint32_t), triangles.size() / 3));
        if (!vertices || !indices) {
            rtcReleaseGeometry(mesh);
            throwOnError(device, log, "rtcSetNewGeometryBuffer");
            throw std::runtime_error("RayVisibility: Embree gave no geometry buffer");
        }
        for (size_t v = 0; v < vertexTotal; ++v) {
            const glm::vec3 p = vertexAt(v);
            vertices[3 * v + 0] = p.x;
            vertices[3 * v + 1] = p.y;
            vertices[3 * v + 2] = p.z;
        }
        std::copy(triangles.begin(), triangles.end(), indices);
        if (occludedFilter) {
            rtcSetGeometryUserData(mesh, userData);
            rtcSetGeometryOccludedFilterFunction(mesh, occludedFilter);
        }
        rtcCommitGeometry(mesh);
        rtcAttachGeometry(scene, mesh);
        rtcReleaseGeometry(mesh); // the scene holds it now
        throwOnError(device, log, "rtcAttachGeometry");
    };
    if (!kept.empty())
        attach(
            vertexCount, [&](size_t v) { return glm::vec3(geometry.positionWorldExact[v]); }, kept,
            nullptr, nullptr);
    if (!testedTriangle.empty()) {
        mAlphaFilter =
            std::make_unique<RayAlphaFilter>(RayAlphaFilter{*alphaTest, std::move(testedTriangle)});
        std::vector<uint32_t> sequential(testedCorners.size());
        std::iota(sequential.begin(), sequential.end(), 0u);
        attach(
            testedCorners.size(), [&](size_t v) { return testedCorners[v]; }, sequential,
            alphaTestedHit, mAlphaFilter.get());
    }
    rtcCommitScene(scene);
    throwOnError(device, log, "rtcCommitScene");
    // The log dies with the constructor; later errors (none are expected from queries on a
    // committed scene) stay readable through rtcGetDeviceError.
    rtcSetDeviceErrorFunction(device, nullptr, nullptr);
    rtcSetDeviceMemoryMonitorFunction(device, nullptr, nullptr);
    mEmbreeBytes = size_t(std::max<int64_t>(embreeBytes.load(), 0));
    mBuildMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

RayVisibility::~RayVisibility() = default;

bool RayVisibility::occluded(const ShadowRay& shadowRay) const {
    const ShadowSegment segment = shadowSegment(shadowRay);
    if (!(segment.lengthWorld > 0.0))
        return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = float(segment.originWorld.x);
    ray.org_y = float(segment.originWorld.y);
    ray.org_z = float(segment.originWorld.z);
    ray.tnear = 0.0f;
    ray.dir_x = float(segment.directionWorld.x);
    ray.dir_y = float(segment.directionWorld.y);
    ray.dir_z = float(segment.directionWorld.z);
    ray.time = 0.0f;
    ray.tfar = farOf(segment);
    ray.mask = ~0u;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(mScene.get(), &context, &ray);
    return ray.tfar < 0.0f; // Embree sets tfar to -infinity on a hit
}

bool RayVisibility::occluded(const glm::dvec3& surfaceWorld, const glm::dvec3& normalWorld,
                             const glm::dvec3& lightWorld) const {
    return occluded(ShadowRay::toPoint(surfaceWorld, normalWorld, lightWorld));
}

bool RayVisibility::occludedDirectional(const glm::dvec3& surfaceWorld,
                                        const glm::dvec3& normalWorld,
                                        const glm::dvec3& directionWorld) const {
    return occluded(ShadowRay::directional(surfaceWorld, normalWorld, directionWorld));
}

void RayVisibility::occluded(std::span<const ShadowRay> rays, std::span<uint8_t> result) const {
    if (rays.size() != result.size())
        throw std::invalid_argument("RayVisibility::occluded: " + std::to_string(rays.size()) +
                                    " rays but " + std::to_string(result.size()) + " results");
    const size_t packetCount = (rays.size() + kPacketSize - 1) / kPacketSize;
    RTCScene scene = mScene.get();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, packetCount, kPacketsPerTask),
                      [&](const tbb::blocked_range<size_t>& packets) {
                          RTCIntersectContext context;
                          rtcInitIntersectContext(&context);
                          for (size_t packet = packets.begin(); packet != packets.end(); ++packet) {
                              const size_t first = packet * kPacketSize;
                              const size_t count = std::min(kPacketSize, rays.size() - first);
                              RTCRay16 rays16;
                              alignas(64) int valid[kPacketSize] = {};
                              for (size_t lane = 0; lane < kPacketSize; ++lane) {
                                  ShadowSegment segment;
                                  if (lane < count)
                                      segment = shadowSegment(rays[first + lane]);
                                  valid[lane] = segment.lengthWorld > 0.0 ? -1 : 0;
                                  rays16.org_x[lane] = float(segment.originWorld.x);
                                  rays16.org_y[lane] = float(segment.originWorld.y);
                                  rays16.org_z[lane] = float(segment.originWorld.z);
                                  rays16.tnear[lane] = 0.0f;
                                  rays16.dir_x[lane] = float(segment.directionWorld.x);
                                  rays16.dir_y[lane] = float(segment.directionWorld.y);
                                  rays16.dir_z[lane] = float(segment.directionWorld.z);
                                  rays16.time[lane] = 0.0f;
                                  rays16.tfar[lane] = valid[lane] ? farOf(segment) : 0.0f;
                                  rays16.mask[lane] = ~0u;
                                  rays16.id[lane] = unsigned(lane);
                                  rays16.flags[lane] = 0;
                              }
                              rtcOccluded16(valid, scene, &context, &rays16);
                              for (size_t lane = 0; lane < count; ++lane)
                                  result[first + lane] =
                                      valid[lane] && rays16.tfar[lane] < 0.0f ? 1 : 0;
                          }
                      });
}

} // namespace lighting::shadows
