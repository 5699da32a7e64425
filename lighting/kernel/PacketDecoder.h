// PacketDecoder: G-buffer planes decoded a packet (4x4 pixels) at a time into a ShadingPacket,
// the vector decode path of issue 14 beside the per-pixel GBuffer::decode, which stays the oracle.
//
// Scope (a prototype that lives beside the kernel until the integration moves it into gbuffer/):
// layouts with float32 view-space normals, any depth format (the G-buffer keeps depth as a float
// NDC plane whatever the format, quantised on write), either position method, albedo and specular
// stored as float32 planes, looked up from the per-pixel material index, constant or absent; the
// same for metallic-roughness parameters (roughness, metallic: float32 planes, material, constant
// or absent; ambient occlusion: a float32 plane or absent = 1), and the material model per lane
// (the layout's constant, or the material's when the layout has modelPerMaterial). That covers the
// reference layout and the layouts `render` derives with float planes (atrium: float depth +
// float32 normals + material index, 17 bytes per pixel; DamagedHelmet: + f32 albedo, roughness,
// metallic, occlusion). Other layouts (normal codes, packed albedo, specular, roughness-metallic or
// occlusion, world-space normals) are refused by supports(); their readers keep GBuffer::decode.
//
// The planes come in as raw pointers (GBufferPlanes) because gbuffer::GBuffer does not expose
// them yet; tests and benchmarks copy them out of a G-buffer, the integration will hand the
// G-buffer's own arrays over.
//
// Exactness: both paths compute every value with the operations GBuffer::decode uses, in its order
// (glm's mat4 * vec4 as (m0 x + m1 y) + (m2 z + m3), the exact divisions, no fused multiply-add),
// so a covered lane's surface is bitwise GBuffer::decode's on every instruction set
// (tests/kernel/packet_decode_test.cpp). Lanes outside the image or on background pixels have
// their bit clear in laneMask and unspecified contents. Packets that reach past the image's right
// or bottom edge are decoded by the scalar path (same values).
//
// Thread safety: decode() is const and writes only the given packet.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gbuffer/GBufferLayout.h"
#include "gbuffer/visibility/CameraView.h"
#include "lighting/kernel/KernelIsa.h"
#include "lighting/kernel/ShadingPacket.h"

namespace lighting::kernel {

// The planes of one G-buffer (structure of arrays, width * height each, row-major); null for
// planes the layout does not store.
struct GBufferPlanes {
    const float* depth =
        nullptr;                 // NDC depth in the view's convention; the clear value = background
    const float* normal[3] = {}; // float32 view-space normal
    const float* albedo[3] = {}; // float32 albedo
    const float* specular[2] = {};          // float32 intensity, power
    const float* roughnessMetallic[2] = {}; // float32 roughness, metallic
    const float* occlusion = nullptr;       // float32 ambient occlusion
    const uint16_t* material = nullptr;
};

// Where a channel's value comes from (one per layout, the same at every pixel).
enum class DecodeSource : uint32_t { Absent, Constant, Material, Plane };

// Plain data the per-target decoders read (built by PacketDecoder).
struct PacketDecodeTables {
    int width = 0;
    int height = 0;
    const float* depth = nullptr;
    float clearDepth = 0.0f;
    const float* normal[3] = {};
    const uint16_t* material = nullptr;
    DecodeSource albedoSource = DecodeSource::Absent;
    DecodeSource specularSource = DecodeSource::Absent;
    const float* albedoPlane[3] = {};
    const float* specularPlane[2] = {};
    float constantAlbedo[3] = {};
    float constantSpecular[2] = {0.0f, 1.0f};
    DecodeSource roughnessMetallicSource = DecodeSource::Absent;
    const float* roughnessMetallicPlane[2] = {};
    float constantRoughnessMetallic[2] = {1.0f, 0.0f};
    const float* occlusionPlane = nullptr; // null: occlusion 1
    // The material model: the layout's constant, or per material (materialMetallicRoughness).
    bool modelPerMaterial = false;
    bool constantMetallicRoughness = false;
    // The layout's material table as columns, with one more entry at index materialCount holding
    // what GBuffer::decode gives for an index out of range (albedo 0, specular (0, 1), roughness
    // 1, metallic 0, Blinn-Phong), repeated to at least 16 entries.
    const float* materialAlbedo[3] = {};
    const float* materialSpecular[2] = {};
    const float* materialRoughnessMetallic[2] = {};
    const float* materialMetallicRoughness = nullptr; // 1 where the model is metallic-roughness
    uint32_t materialCount = 0;
    bool viewRay = false;          // position method: false = inverse projection
    float viewFromClip[4][4] = {}; // columns, as glm::mat4
    float clipFromView00 = 1.0f;   // for the view ray: 1 / (aspect tan(fov / 2))
    float clipFromView11 = 1.0f;   // 1 / tan(fov / 2)
    bool reversedZ = true;         // DepthProjection::viewDepthFromNdcFloat's inputs, in float
    bool infiniteFar = false;
    float nearMetres = 0.1f;
    float nearTimesFar = 10.0f; // n * f
    float farMinusNear = 99.9f; // f - n
};

class PacketDecoder {
public:
    // Whether this decoder handles the layout; if not and `why` is given, the reason.
    static bool supports(const gbuffer::GBufferLayout& layout, std::string* why = nullptr);

    // Throws std::invalid_argument when !supports(layout) or a plane the layout needs is null.
    // The pointers must stay valid while the decoder is used.
    PacketDecoder(const gbuffer::GBufferLayout& layout, const gbuffer::CameraView& view,
                  const GBufferPlanes& planes);

    // Decodes the 4x4 pixels whose top-left is (x0, y0) into `packet` (laneMask, x0, y0 too).
    void decode(const KernelIsa& isa, int x0, int y0, ShadingPacket& packet) const;
    // The per-pixel path, lane by lane (what decode does for the scalar ISA and for edge packets).
    void decodeScalar(int x0, int y0, ShadingPacket& packet) const;

    const PacketDecodeTables& tables() const { return mTables; }

    PacketDecoder(const PacketDecoder&) = delete; // mTables points into the member vectors
    PacketDecoder& operator=(const PacketDecoder&) = delete;

private:
    gbuffer::CameraView mView;
    gbuffer::PositionMethod mPosition;
    PacketDecodeTables mTables;
    // albedo r, g, b, intensity, power, roughness, metallic, model (1 = metallic-roughness)
    std::vector<float> mMaterialColumns[8];
};

} // namespace lighting::kernel
