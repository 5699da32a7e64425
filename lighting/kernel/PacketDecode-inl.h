// decodePacketVector: the vector G-buffer decode of PacketDecoder, once per compiled instruction
// set (included by VectorTargets.cpp through foreach_target.h). Only packets wholly inside the
// image come here (PacketDecoder::decode sends edge packets to the scalar path).
//
// A hardware vector of N lanes covers N / 4 rows of the packet: each row is 4 consecutive pixels,
// one unaligned 128-bit load per float plane (64-bit for the 16-bit material index), joined with
// Combine. Then, per lane and with GBuffer::decode's operations in its order (no fused
// multiply-add): the pixel centre's NDC, the position (inverse projection or view ray), the
// material lookups (a permutation when the table fits in a vector, else GatherIndex), and
// coverage (depth != the clear value).
#include "lighting/kernel/PacketDecoder.h"
#include "lighting/kernel/VectorTargets.h"

#if defined(LIGHTING_KERNEL_PACKET_DECODE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef LIGHTING_KERNEL_PACKET_DECODE_INL_H_
#undef LIGHTING_KERNEL_PACKET_DECODE_INL_H_
#else
#define LIGHTING_KERNEL_PACKET_DECODE_INL_H_
#endif

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace lighting::kernel::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace decode {

using FloatTag = hn::ScalableTag<float>;
using IntTag = hn::RebindToSigned<FloatTag>;
using FloatVec = hn::Vec<FloatTag>;
using IntVec = hn::Vec<IntTag>;

constexpr size_t kLanes = hn::MaxLanes(FloatTag());
constexpr size_t kRowsPerVector = kLanes / kPacketWidth;
static_assert(kRowsPerVector == 1 || kRowsPerVector == 2 || kRowsPerVector == 4,
              "a vector holds 1, 2 or 4 whole packet rows");

// kRowsPerVector rows of 4 values, starting at `row0` (a pointer to the first pixel of the first
// row), `stride` values apart, as one vector.
template <class D, class T> HWY_INLINE hn::Vec<D> loadRows(D d, const T* row0, size_t stride) {
    if constexpr (kRowsPerVector == 1) {
        return hn::LoadU(d, row0);
    } else if constexpr (kRowsPerVector == 2) {
        const hn::Half<D> dh;
        return hn::Combine(d, hn::LoadU(dh, row0 + stride), hn::LoadU(dh, row0));
    } else {
        const hn::Half<D> dh;
        const hn::Half<decltype(dh)> dq;
        return hn::Combine(
            d, hn::Combine(dh, hn::LoadU(dq, row0 + 3 * stride), hn::LoadU(dq, row0 + 2 * stride)),
            hn::Combine(dh, hn::LoadU(dq, row0 + stride), hn::LoadU(dq, row0)));
    }
}

// The 16-bit material indices of the same rows, widened to int32 lanes.
template <class DI>
HWY_INLINE hn::Vec<DI> loadMaterialRows(DI di, const uint16_t* row0, size_t stride) {
    const hn::Rebind<uint32_t, DI> du32;
    const hn::Rebind<uint16_t, DI> du16;
    if constexpr (kRowsPerVector == 1) {
        return hn::BitCast(di, hn::PromoteTo(du32, hn::LoadU(du16, row0)));
    } else if constexpr (kRowsPerVector == 2) {
        const hn::Half<decltype(du32)> dh32;
        const hn::Rebind<uint16_t, decltype(dh32)> dh16;
        return hn::BitCast(di,
                           hn::Combine(du32, hn::PromoteTo(dh32, hn::LoadU(dh16, row0 + stride)),
                                       hn::PromoteTo(dh32, hn::LoadU(dh16, row0))));
    } else {
        const hn::Half<decltype(du32)> dh32;
        const hn::Half<decltype(dh32)> dq32;
        const hn::Rebind<uint16_t, decltype(dq32)> dq16;
        const auto row = [&](size_t r) HWY_ATTR {
            return hn::PromoteTo(dq32, hn::LoadU(dq16, row0 + r * stride));
        };
        return hn::BitCast(di, hn::Combine(du32, hn::Combine(dh32, row(3), row(2)),
                                           hn::Combine(dh32, row(1), row(0))));
    }
}

// Lane offsets within the packet as floats (x = lane % 4, y = lane / 4).
alignas(64) constexpr float kLaneX[kPacketLanes] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
alignas(64) constexpr float kLaneY[kPacketLanes] = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};

// A material table column per lane. When the table fits in one vector (most scenes: atrium has 8
// materials) the lookup is one permutation of the column loaded as a vector, else a gather.
// Indices past the table read the sentinel entry at materialCount (GBuffer::decode's values for
// an index out of range), by selection or by clamping.
struct MaterialLookup {
    bool byPermutation = false;
    LaneMask inRange = hn::FirstN(FloatTag(), 0);
    decltype(hn::IndicesFromVec(FloatTag(), hn::Zero(IntTag()))) indices =
        hn::IndicesFromVec(FloatTag(), hn::Zero(IntTag()));
    IntVec clamped = hn::Zero(IntTag());

    MaterialLookup() = default;
    MaterialLookup(const PacketDecodeTables& t, IntVec index) {
        const IntTag di;
        byPermutation = t.materialCount > 0 && t.materialCount <= kLanes;
        if (byPermutation) {
            inRange =
                hn::RebindMask(FloatTag(), hn::Lt(index, hn::Set(di, int32_t(t.materialCount))));
            indices = hn::IndicesFromVec(FloatTag(),
                                         hn::Min(index, hn::Set(di, int32_t(t.materialCount) - 1)));
        } else {
            clamped = hn::Min(index, hn::Set(di, int32_t(t.materialCount)));
        }
    }
    // `column` has materialCount + 1 entries and is padded to at least 16 floats.
    FloatVec column(const float* values, uint32_t materialCount) const {
        const FloatTag d;
        if (!byPermutation)
            return hn::GatherIndex(d, values, clamped);
        return hn::IfThenElse(inRange, hn::TableLookupLanes(hn::LoadU(d, values), indices),
                              hn::Set(d, values[materialCount]));
    }
};

} // namespace decode

void decodePacketVector(const DecodeArgs& args) {
    using namespace decode;
    const FloatTag d;
    const PacketDecodeTables& t = *args.tables;
    ShadingPacket& packet = *args.packet;
    packet.x0 = args.x0;
    packet.y0 = args.y0;
    packet.laneMask = 0;
    packet.metallicRoughnessMask = 0;
    const size_t stride = size_t(t.width);
    const FloatVec one = hn::Set(d, 1.0f);
    const FloatVec two = hn::Set(d, 2.0f);
    const FloatVec half = hn::Set(d, 0.5f);
    const FloatVec x0 = hn::Set(d, float(args.x0));
    const FloatVec y0 = hn::Set(d, float(args.y0));
    const FloatVec width = hn::Set(d, float(t.width));
    const FloatVec height = hn::Set(d, float(t.height));
    for (size_t first = 0; first < size_t(kPacketLanes); first += kLanes) {
        const size_t pixel0 = (size_t(args.y0) + first / kPacketWidth) * stride + size_t(args.x0);
        const FloatVec depth = loadRows(d, t.depth + pixel0, stride);
        uint8_t coveredBits[8] = {};
        const LaneMask covered = hn::Ne(depth, hn::Set(d, t.clearDepth));
        hn::StoreMaskBits(d, covered, coveredBits);
        packet.laneMask |= (uint32_t(coveredBits[0]) | uint32_t(coveredBits[1]) << 8) << first;

        // CameraView::ndcOfPixel: (x + 0.5) / width * 2 - 1 and 1 - (y + 0.5) / height * 2.
        const FloatVec pixelX = hn::Add(x0, hn::Load(d, kLaneX + first));
        const FloatVec pixelY = hn::Add(y0, hn::Load(d, kLaneY + first));
        const FloatVec ndcX = hn::Sub(hn::Mul(hn::Div(hn::Add(pixelX, half), width), two), one);
        const FloatVec ndcY = hn::Sub(one, hn::Mul(hn::Div(hn::Add(pixelY, half), height), two));
        FloatVec position[3];
        if (!t.viewRay) {
            // positionByInverseProjection: glm's mat4 * vec4(ndc, depth, 1) is
            // (m0 x + m1 y) + (m2 z + m3 * 1), then xyz / w.
            FloatVec clip[4];
            for (int i = 0; i < 4; ++i)
                clip[i] = hn::Add(hn::Add(hn::Mul(hn::Set(d, t.viewFromClip[0][i]), ndcX),
                                          hn::Mul(hn::Set(d, t.viewFromClip[1][i]), ndcY)),
                                  hn::Add(hn::Mul(hn::Set(d, t.viewFromClip[2][i]), depth),
                                          hn::Set(d, t.viewFromClip[3][i])));
            for (int k = 0; k < 3; ++k)
                position[k] = hn::Div(clip[k], clip[3]);
        } else {
            // DepthProjection::viewDepthFromNdcFloat, then viewRayOfNdc * depth.
            const FloatVec w = t.reversedZ ? depth : hn::Sub(one, depth);
            const FloatVec viewDepth =
                t.infiniteFar ? hn::Div(hn::Set(d, t.nearMetres), w)
                              : hn::Div(hn::Set(d, t.nearTimesFar),
                                        hn::Add(hn::Set(d, t.nearMetres),
                                                hn::Mul(w, hn::Set(d, t.farMinusNear))));
            position[0] = hn::Mul(hn::Div(ndcX, hn::Set(d, t.clipFromView00)), viewDepth);
            position[1] = hn::Mul(hn::Div(ndcY, hn::Set(d, t.clipFromView11)), viewDepth);
            position[2] = hn::Mul(hn::Set(d, -1.0f), viewDepth);
        }
        for (int k = 0; k < 3; ++k) {
            hn::Store(position[k], d, packet.positionView[k] + first);
            hn::Store(loadRows(d, t.normal[k] + pixel0, stride), d, packet.normalView[k] + first);
        }

        MaterialLookup material;
        if (t.albedoSource == DecodeSource::Material ||
            t.specularSource == DecodeSource::Material ||
            t.roughnessMetallicSource == DecodeSource::Material || t.modelPerMaterial)
            material = MaterialLookup(t, loadMaterialRows(IntTag(), t.material + pixel0, stride));
        for (int k = 0; k < 3; ++k) {
            FloatVec albedo = hn::Zero(d);
            if (t.albedoSource == DecodeSource::Plane)
                albedo = loadRows(d, t.albedoPlane[k] + pixel0, stride);
            else if (t.albedoSource == DecodeSource::Material)
                albedo = material.column(t.materialAlbedo[k], t.materialCount);
            else if (t.albedoSource == DecodeSource::Constant)
                albedo = hn::Set(d, t.constantAlbedo[k]);
            hn::Store(albedo, d, packet.albedo[k] + first);
        }
        float* specularTargets[2] = {packet.specularIntensity + first,
                                     packet.specularPower + first};
        for (int k = 0; k < 2; ++k) {
            FloatVec specular = hn::Set(d, k == 0 ? 0.0f : 1.0f); // Surface's defaults
            if (t.specularSource == DecodeSource::Plane)
                specular = loadRows(d, t.specularPlane[k] + pixel0, stride);
            else if (t.specularSource == DecodeSource::Material)
                specular = material.column(t.materialSpecular[k], t.materialCount);
            else if (t.specularSource == DecodeSource::Constant)
                specular = hn::Set(d, t.constantSpecular[k]);
            hn::Store(specular, d, specularTargets[k]);
        }
        float* roughnessMetallicTargets[2] = {packet.roughness + first, packet.metallic + first};
        for (int k = 0; k < 2; ++k) {
            FloatVec value = hn::Set(d, k == 0 ? 1.0f : 0.0f); // Surface's defaults
            if (t.roughnessMetallicSource == DecodeSource::Plane)
                value = loadRows(d, t.roughnessMetallicPlane[k] + pixel0, stride);
            else if (t.roughnessMetallicSource == DecodeSource::Material)
                value = material.column(t.materialRoughnessMetallic[k], t.materialCount);
            else if (t.roughnessMetallicSource == DecodeSource::Constant)
                value = hn::Set(d, t.constantRoughnessMetallic[k]);
            hn::Store(value, d, roughnessMetallicTargets[k]);
        }
        hn::Store(t.occlusionPlane ? loadRows(d, t.occlusionPlane + pixel0, stride) : one, d,
                  packet.occlusion + first);
        // The model: the material's (its column is 1 for metallic-roughness) or the layout's.
        LaneMask metallicRoughness = hn::FirstN(d, 0);
        if (t.modelPerMaterial)
            metallicRoughness =
                hn::Ne(material.column(t.materialMetallicRoughness, t.materialCount), hn::Zero(d));
        else if (t.constantMetallicRoughness)
            metallicRoughness = hn::FirstN(d, kLanes);
        uint8_t modelBits[8] = {};
        hn::StoreMaskBits(d, hn::And(covered, metallicRoughness), modelBits);
        packet.metallicRoughnessMask |= (uint32_t(modelBits[0]) | uint32_t(modelBits[1]) << 8)
                                        << first;
    }
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif // include guard toggle
