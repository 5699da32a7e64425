// GBufferPlaneCopy: the planes of a G-buffer copied out through GBuffer::decode (lossless for the
// layouts PacketDecoder supports: float32 normals, albedo, specular, roughness, metallic and
// occlusion, 16-bit material index),
// because gbuffer::GBuffer does not expose its arrays yet. For the kernel's tests and benchmarks.
#pragma once

#include <vector>

#include "gbuffer/GBuffer.h"
#include "lighting/kernel/PacketDecoder.h"

namespace kerneltest {

struct GBufferPlaneCopy {
    std::vector<float> depth;
    std::vector<float> normal[3];
    std::vector<float> albedo[3];
    std::vector<float> specular[2];
    std::vector<float> roughnessMetallic[2];
    std::vector<float> occlusion;
    std::vector<uint16_t> material;

    explicit GBufferPlaneCopy(const gbuffer::GBuffer& gb) {
        const size_t n = gb.pixelCount();
        depth.assign(gb.depth().begin(), gb.depth().end());
        for (auto* planes :
             {&normal[0], &normal[1], &normal[2], &albedo[0], &albedo[1], &albedo[2], &specular[0],
              &specular[1], &roughnessMetallic[0], &roughnessMetallic[1], &occlusion})
            planes->resize(n);
        material.resize(n);
        for (int y = 0; y < gb.height(); ++y)
            for (int x = 0; x < gb.width(); ++x) {
                const size_t pixel = size_t(y) * gb.width() + x;
                const gbuffer::Surface s = gb.decode(x, y);
                for (int k = 0; k < 3; ++k) {
                    normal[k][pixel] = s.normalView[k];
                    albedo[k][pixel] = s.albedo[k];
                }
                specular[0][pixel] = s.specularIntensity;
                specular[1][pixel] = s.specularPower;
                roughnessMetallic[0][pixel] = s.roughness;
                roughnessMetallic[1][pixel] = s.metallic;
                occlusion[pixel] = s.occlusion;
                material[pixel] = uint16_t(s.material);
            }
    }

    lighting::kernel::GBufferPlanes planes() const {
        lighting::kernel::GBufferPlanes p;
        p.depth = depth.data();
        for (int k = 0; k < 3; ++k) {
            p.normal[k] = normal[k].data();
            p.albedo[k] = albedo[k].data();
        }
        p.specular[0] = specular[0].data();
        p.specular[1] = specular[1].data();
        p.roughnessMetallic[0] = roughnessMetallic[0].data();
        p.roughnessMetallic[1] = roughnessMetallic[1].data();
        p.occlusion = occlusion.data();
        p.material = material.data();
        return p;
    }
};

} // namespace kerneltest
