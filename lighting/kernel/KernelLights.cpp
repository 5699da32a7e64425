#include "lighting/kernel/KernelLights.h"

#include <mutex>
#include <utility>

#include <tbb/parallel_for.h>

namespace lighting::kernel {

namespace {

constexpr size_t kPooledRecords = size_t(1) << 16; // 4 MiB
constexpr size_t kPoolSize = 4;

std::mutex gPoolMutex;
std::vector<std::vector<KernelLight>> gPool; // guarded by gPoolMutex

// A pooled array with room for `count` records (the largest one, if any is large enough), else
// an empty one.
std::vector<KernelLight> takePooled(size_t count) {
    if (count < kPooledRecords)
        return {};
    const std::lock_guard lock(gPoolMutex);
    auto best = gPool.end();
    for (auto it = gPool.begin(); it != gPool.end(); ++it)
        if (it->capacity() >= count && (best == gPool.end() || it->capacity() < best->capacity()))
            best = it;
    if (best == gPool.end())
        return {};
    std::vector<KernelLight> records = std::move(*best);
    gPool.erase(best);
    return records;
}

void returnPooled(std::vector<KernelLight>&& records) {
    if (records.capacity() < kPooledRecords)
        return;
    const std::lock_guard lock(gPoolMutex);
    if (gPool.size() < kPoolSize)
        gPool.push_back(std::move(records));
}

} // namespace

KernelLights::~KernelLights() {
    returnPooled(std::move(mRecords));
}

KernelLights::KernelLights(const std::vector<LightInView<float>>& lights,
                           const shadows::ShadowLookup* shadows)
    : mSource(&lights), mRecords(takePooled(lights.size())), mShadows(shadows),
      mShadowView(shadows ? shadows->view() : nullptr) {
    mRecords.resize(lights.size());
    // Lights in parallel (10^6 lights: 64 MB of records every frame), each record a function of
    // its light alone.
    tbb::parallel_for(size_t(0), lights.size(), [&](size_t i) {
        const LightInView<float>& light = lights[i];
        KernelLight& record = mRecords[i];
        record = {};
        for (int c = 0; c < 3; ++c) {
            record.positionView[c] = light.positionView[c];
            record.directionView[c] = light.directionView[c];
            record.radiance[c] = light.radiance[c];
        }
        record.rangeSquared = light.rangeMetres * light.rangeMetres;
        record.spotOuterCos = light.spotOuterCos;
        record.spotWidth = light.spotInnerCos - light.spotOuterCos;
        record.type = uint32_t(light.type);
        // Ambient light comes from everywhere: nothing shadows it (occlusion is the material's).
        record.shadow = shadows && light.type != scenes::LightType::Ambient ? shadows->shadowOf(i)
                                                                            : shadows::kNoShadow;
    });
}

} // namespace lighting::kernel
