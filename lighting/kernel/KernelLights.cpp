#include "lighting/kernel/KernelLights.h"

namespace lighting::kernel {

KernelLights::KernelLights(std::vector<LightInView<float>> lights,
                           const shadows::ShadowLookup* shadows)
    : mSource(std::move(lights)), mShadows(shadows) {
    mRecords.resize(mSource.size());
    for (size_t i = 0; i < mSource.size(); ++i) {
        const LightInView<float>& light = mSource[i];
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
    }
}

} // namespace lighting::kernel
