#include "lighting/passes/FragmentShading.h"

#include <algorithm>
#include <array>
#include <iterator>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

#include "lighting/kernel/KernelLights.h"
#include "lighting/kernel/LightKernel.h"
#include "lighting/passes/ForwardGeometry.h"
#include "lighting/passes/KernelWork.h"
#include "lighting/passes/LightAccumulation.h"

namespace lighting {

using kernel::kPacketLanes;

namespace {

constexpr int kMaxWarpLanes = 64;

// A queued fragment: its pixel, surface and alpha, and the list it is shaded with.
struct QueuedFragment {
    int x = 0;
    int y = 0;
    uint32_t triangle = 0; // scene triangle
    bool frontFacing = true;
    uint8_t coverage = 1; // multisampled: the samples the fragment is applied to
    float alpha = 1.0f;
    uint64_t listKey = 0;
    std::span<const uint32_t> lights; // when copied: empty, see copiedFirst
    int64_t copiedFirst = -1;         // >= 0: the list is copiedLights[copiedFirst, + count)
    uint32_t copiedCount = 0;
    bool beyondRange = false; // addBeyondRange: not shaded, its sums are zero (surface unset)
    gbuffer::Surface surface;
};

// Fills `q` (a batch's next slot) with what every kind of queued fragment has; returns it.
QueuedFragment& queued(QueuedFragment& q, const raster::Fragment& fragment, uint32_t triangle,
                       uint64_t listKey, std::span<const uint32_t> lights, float alpha) {
    q.x = fragment.x;
    q.y = fragment.y;
    q.triangle = triangle;
    q.frontFacing = fragment.frontFacing;
    q.coverage = fragment.coverage;
    q.alpha = alpha;
    q.listKey = listKey;
    q.lights = lights;
    q.copiedFirst = -1;
    q.copiedCount = 0;
    q.beyondRange = false;
    return q;
}

// The union of the ascending lists of `fragments` (runs of one key taken once) into `merged`.
void unionOfLists(std::span<const QueuedFragment* const> fragments, std::vector<uint32_t>& merged,
                  std::vector<uint32_t>& next) {
    merged.clear();
    const QueuedFragment* previous = nullptr;
    for (const QueuedFragment* q : fragments) {
        if (previous != nullptr && q->listKey == previous->listKey)
            continue;
        previous = q;
        next.clear();
        std::set_union(merged.begin(), merged.end(), q->lights.begin(), q->lights.end(),
                       std::back_inserter(next));
        merged.swap(next);
    }
}

// Keys of copied lists: one per fragment, never equal to a caller's key of the same batch
// (callers' keys are object, tile or light indices, or addresses, all below 2^63).
constexpr uint64_t kCopiedListKey = uint64_t(1) << 63;

} // namespace

// One raster tile's queue and counters; cache-line aligned since neighbouring tiles are drawn by
// different threads.
struct alignas(64) FragmentShading::TileBatch {
    std::array<QueuedFragment, kMaxWarpLanes> fragments;
    int count = 0;
    uint64_t queuedTotal = 0;           // fragments queued since begin()
    KernelWork work;                    // SIMT lane slots and kernel counters
    std::vector<uint32_t> copiedLights; // the lists of addCopyingList, until the batch is shaded
    std::vector<uint32_t> unionScratch; // the union of the batch's lists, for the SIMT model
    std::vector<uint32_t> unionNext;
    std::vector<uint32_t> beyondLights; // per packet, the lights of its beyond-range lanes
};

FragmentShading::FragmentShading() = default;
FragmentShading::~FragmentShading() = default;

void FragmentShading::begin(const StageInputs& inputs, FragmentApply apply, StageResult& result,
                            SampleRadiance* samples) {
    if (inputs.simtWarpLanes != 32 && inputs.simtWarpLanes != 64)
        throw std::invalid_argument("FragmentShading: simtWarpLanes must be 32 or 64, not " +
                                    std::to_string(inputs.simtWarpLanes));
    mResult = &result;
    mSamples = samples;
    mApply = apply;
    mCountOracle = apply == FragmentApply::Over && !result.lightsOracle.empty();
    mIsa = inputs.isa;
    mWarpLanes = inputs.simtWarpLanes;
    mWidth = inputs.view->width;
    mTilesX = (inputs.view->width + raster::kTileSize - 1) / raster::kTileSize;
    const int tilesY = (inputs.view->height + raster::kTileSize - 1) / raster::kTileSize;
    mLights = std::make_unique<kernel::KernelLights>(inputs.lights->lights, inputs.shadows);
    mTiles.resize(size_t(mTilesX) * size_t(tilesY));
    for (TileBatch& tile : mTiles) {
        tile.count = 0;
        tile.queuedTotal = 0;
        tile.work = {};
        tile.copiedLights.clear();
    }
}

FragmentShading::TileBatch& FragmentShading::tileOf(const raster::Fragment& fragment) {
    return mTiles[size_t(fragment.y / raster::kTileSize) * size_t(mTilesX) +
                  size_t(fragment.x / raster::kTileSize)];
}

void FragmentShading::add(const raster::Fragment& fragment, uint32_t triangle,
                          const gbuffer::Surface& surface, uint64_t listKey,
                          std::span<const uint32_t> lights, float alpha) {
    TileBatch& batch = tileOf(fragment);
    queued(batch.fragments[size_t(batch.count)], fragment, triangle, listKey, lights, alpha)
        .surface = surface;
    if (++batch.count == mWarpLanes)
        shadeBatch(batch);
}

void FragmentShading::addCopyingList(const raster::Fragment& fragment, uint32_t triangle,
                                     const gbuffer::Surface& surface,
                                     std::span<const uint32_t> lights, float alpha) {
    TileBatch& batch = tileOf(fragment);
    QueuedFragment& q = queued(batch.fragments[size_t(batch.count)], fragment, triangle,
                               kCopiedListKey | uint64_t(batch.count), {}, alpha);
    q.copiedFirst = int64_t(batch.copiedLights.size());
    q.copiedCount = uint32_t(lights.size());
    batch.copiedLights.insert(batch.copiedLights.end(), lights.begin(), lights.end());
    q.surface = surface;
    if (++batch.count == mWarpLanes)
        shadeBatch(batch);
}

bool FragmentShading::beyondRange(uint32_t light, const glm::vec3& positionView) const {
    const kernel::KernelLight& record = mLights->records()[light];
    const auto type = scenes::LightType(record.type);
    if (type != scenes::LightType::Point && type != scenes::LightType::Spot)
        return false;
    const float dx = record.positionView[0] - positionView.x;
    const float dy = record.positionView[1] - positionView.y;
    const float dz = record.positionView[2] - positionView.z;
    // The kernel's test is distance^2 < rangeSquared with these operations; the margin (2^-16,
    // ~100x a 3-term dot product's rounding) makes "beyond" hold whatever the rounding or
    // contraction on either side, so a fragment said beyond is rejected at range on every path.
    return (dx * dx + dy * dy) + dz * dz > record.rangeSquared * (1.0f + 0x1p-16f);
}

void FragmentShading::addBeyondRange(const raster::Fragment& fragment, uint32_t triangle,
                                     uint64_t listKey, std::span<const uint32_t> lights) {
    if (mApply != FragmentApply::Add)
        throw std::logic_error("FragmentShading::addBeyondRange: for FragmentApply::Add only");
    TileBatch& batch = tileOf(fragment);
    queued(batch.fragments[size_t(batch.count)], fragment, triangle, listKey, lights, 1.0f)
        .beyondRange = true;
    if (++batch.count == mWarpLanes)
        shadeBatch(batch);
}

void FragmentShading::flush() {
    tbb::parallel_for(size_t(0), mTiles.size(), [&](size_t tile) {
        if (mTiles[tile].count > 0)
            shadeBatch(mTiles[tile]);
    });
}

namespace {

// Multisampled frames: lane `lane`'s result applied to the fragment's covered samples of
// `target` with `apply`'s semantics (the file comment of FragmentShading.h).
void applyToSamples(FragmentApply apply, bool countOracle, SampleRadiance& target,
                    StageResult& result, const QueuedFragment& q,
                    const kernel::PacketAccumulator& accumulator, int lane, size_t pixel) {
    const int samples = target.samples();
    glm::vec3 lit;
    for (int c = 0; c < 3; ++c)
        lit[c] = accumulator.radiance[c][lane] +
                 (apply == FragmentApply::Add ? 0.0f : q.surface.emissive[c]);
    if (apply == FragmentApply::Over) {
        target.over(pixel, q.coverage, lit, q.alpha, result);
        if (countOracle)
            result.lightsOracle[pixel] += accumulator.lightsContributing[lane];
        result.traceBlendedFragment(pixel, q.triangle, q.frontFacing, q.lights);
        return;
    }
    for (int c = 0; c < 3; ++c) {
        float* sample = target.pixel(c, pixel);
        for (int s = 0; s < samples; ++s)
            if (q.coverage >> s & 1u)
                sample[s] = apply == FragmentApply::Add ? sample[s] + lit[c] : lit[c];
    }
    if (!target.tracing())
        return;
    for (int s = 0; s < samples; ++s) {
        if (!(q.coverage >> s & 1u))
            continue;
        std::vector<uint32_t>& trace = target.traceOf(pixel, s);
        if (apply == FragmentApply::Replace)
            trace.assign(q.lights.begin(), q.lights.end());
        else
            trace.insert(trace.end(), q.lights.begin(), q.lights.end());
    }
}

} // namespace

uint64_t FragmentShading::fragmentCount() const {
    uint64_t count = 0;
    for (const TileBatch& tile : mTiles)
        count += tile.queuedTotal;
    return count;
}

void FragmentShading::shadeBatch(TileBatch& batch) {
    StageResult& result = *mResult;
    batch.queuedTotal += uint64_t(batch.count);
    // Copied lists live in the batch's storage, which stops growing once the batch is full.
    for (int i = 0; i < batch.count; ++i) {
        QueuedFragment& q = batch.fragments[size_t(i)];
        if (q.copiedFirst >= 0)
            q.lights = std::span<const uint32_t>(batch.copiedLights)
                           .subspan(size_t(q.copiedFirst), q.copiedCount);
    }
    kernel::ShadingPacket packet;
    kernel::PacketAccumulator accumulator;
    PacketLightLists lists;
    for (int first = 0; first < batch.count; first += kPacketLanes) {
        const QueuedFragment* lanes = batch.fragments.data() + first;
        const int laneCount = std::min(kPacketLanes, batch.count - first);
        packet.clear();
        bool anyBeyond = false;
        for (int lane = 0; lane < laneCount; ++lane) {
            if (lanes[lane].beyondRange)
                anyBeyond = true;
            else
                setLaneSurface(packet, lane, lanes[lane].surface);
        }
        // Lanes grouped by list: one kernel call over the union of the packet's lists, each lane
        // masked to its own list (bitwise one call per list).
        lists.clear();
        lists.addByKeyMerged(
            packet, [&](int lane) { return lanes[lane].listKey; },
            [&](uint64_t key) {
                int lane = 0;
                while (lanes[lane].listKey != key)
                    ++lane;
                return lanes[lane].lights;
            });
        accumulator.clear();
        for (int g = 0; g < lists.size(); ++g) {
            const PacketLightLists::Group& group = lists[g];
            if (group.lightLaneMasks.empty())
                kernel::shadePacket(mIsa, packet, group.laneMask, *mLights, group.lights,
                                    accumulator, mCountOracle);
            else
                kernel::shadePacket(mIsa, packet, group.laneMask, *mLights, group.lights,
                                    group.lightLaneMasks, accumulator, mCountOracle);
        }
        batch.work.groups += uint64_t(lists.size());
        if (anyBeyond) {
            // The beyond-range lanes were not shaded. With them active the kernel would have made
            // the packet's one group (addByKeyMerged) and found every light that only they have
            // rejected at range by all its lanes: count exactly that, so the counters are the
            // ones of shading every lane.
            std::array<const QueuedFragment*, kPacketLanes> beyond{};
            size_t beyondCount = 0;
            for (int lane = 0; lane < laneCount; ++lane)
                if (lanes[lane].beyondRange)
                    beyond[beyondCount++] = &lanes[lane];
            unionOfLists(std::span(beyond.data(), beyondCount), batch.beyondLights,
                         batch.unionNext);
            const std::span<const uint32_t> shadedLights =
                lists.size() > 0 ? lists[0].lights : std::span<const uint32_t>();
            for (uint32_t light : batch.beyondLights)
                if (!std::binary_search(shadedLights.begin(), shadedLights.end(), light))
                    ++batch.work.skippedAtRange;
            if (lists.size() == 0)
                batch.work.groups += 1;
        }
        batch.work.addCounters(accumulator);

        // In fragment order: a later fragment of the same pixel comes after an earlier one.
        for (int lane = 0; lane < laneCount; ++lane) {
            const QueuedFragment& q = lanes[lane];
            const size_t pixel = size_t(q.y) * size_t(mWidth) + size_t(q.x);
            if (mSamples) {
                applyToSamples(mApply, mCountOracle, *mSamples, result, q, accumulator, lane,
                               pixel);
                result.lightsEvaluated[pixel] +=
                    q.beyondRange ? uint32_t(q.lights.size()) : accumulator.lightsEvaluated[lane];
                continue;
            }
            switch (mApply) {
            case FragmentApply::Replace:
                for (int c = 0; c < 3; ++c)
                    result.radiance[c][pixel] =
                        accumulator.radiance[c][lane] + q.surface.emissive[c];
                result.traceLightList(pixel, q.lights);
                break;
            case FragmentApply::Add:
                for (int c = 0; c < 3; ++c)
                    result.radiance[c][pixel] += accumulator.radiance[c][lane];
                if (result.tracing())
                    for (uint32_t light : q.lights)
                        result.traceAddedLight(pixel, light);
                break;
            case FragmentApply::Over:
                for (int c = 0; c < 3; ++c) {
                    const float lit = accumulator.radiance[c][lane] + q.surface.emissive[c];
                    result.radiance[c][pixel] =
                        q.alpha * lit + (1.0f - q.alpha) * result.radiance[c][pixel];
                }
                if (mCountOracle)
                    result.lightsOracle[pixel] += accumulator.lightsContributing[lane];
                result.traceBlendedFragment(pixel, q.triangle, q.frontFacing, q.lights);
                break;
            }
            result.lightsEvaluated[pixel] +=
                q.beyondRange ? uint32_t(q.lights.size()) : accumulator.lightsEvaluated[lane];
        }
    }

    // SIMT cost model: the batch is one warp; it pays every light of its lanes' union.
    size_t unionSize = batch.fragments[0].lights.size();
    const uint64_t firstKey = batch.fragments[0].listKey;
    const bool oneList =
        std::all_of(batch.fragments.begin(), batch.fragments.begin() + batch.count,
                    [&](const QueuedFragment& q) { return q.listKey == firstKey; });
    if (!oneList) {
        std::array<const QueuedFragment*, kMaxWarpLanes> all{};
        for (int i = 0; i < batch.count; ++i)
            all[size_t(i)] = &batch.fragments[size_t(i)];
        unionOfLists(std::span(all.data(), size_t(batch.count)), batch.unionScratch,
                     batch.unionNext);
        unionSize = batch.unionScratch.size();
    }
    batch.work.laneSlots += uint64_t(mWarpLanes) * unionSize;
    batch.count = 0;
    batch.copiedLights.clear();
}

void FragmentShading::end() {
    KernelWork work;
    for (const TileBatch& tile : mTiles)
        work += tile.work;
    work.record(mIsa, mWarpLanes, *mResult);
}

} // namespace lighting
