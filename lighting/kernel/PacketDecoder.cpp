#include "lighting/kernel/PacketDecoder.h"

#include <algorithm>
#include <stdexcept>

#include "gbuffer/codecs/DepthFormat.h"
#include "lighting/kernel/VectorTargets.h"

namespace lighting::kernel {

namespace {

DecodeSource albedoSource(gbuffer::AlbedoEncoding encoding) {
    switch (encoding) {
    case gbuffer::AlbedoEncoding::Float32:
        return DecodeSource::Plane;
    case gbuffer::AlbedoEncoding::Material:
        return DecodeSource::Material;
    case gbuffer::AlbedoEncoding::Constant:
        return DecodeSource::Constant;
    default:
        return DecodeSource::Absent;
    }
}

DecodeSource specularSource(gbuffer::SpecularEncoding encoding) {
    switch (encoding) {
    case gbuffer::SpecularEncoding::Float32:
        return DecodeSource::Plane;
    case gbuffer::SpecularEncoding::Material:
        return DecodeSource::Material;
    case gbuffer::SpecularEncoding::Constant:
        return DecodeSource::Constant;
    default:
        return DecodeSource::Absent;
    }
}

DecodeSource roughnessMetallicSource(gbuffer::RoughnessMetallicEncoding encoding) {
    switch (encoding) {
    case gbuffer::RoughnessMetallicEncoding::Float32:
        return DecodeSource::Plane;
    case gbuffer::RoughnessMetallicEncoding::Material:
        return DecodeSource::Material;
    case gbuffer::RoughnessMetallicEncoding::Constant:
        return DecodeSource::Constant;
    default:
        return DecodeSource::Absent;
    }
}

void requirePlane(const void* plane, const char* name, const gbuffer::GBufferLayout& layout) {
    if (!plane)
        throw std::invalid_argument(std::string("packet decoder: layout '") + layout.name +
                                    "' stores the plane " + name + ", but none was given");
}

} // namespace

bool PacketDecoder::supports(const gbuffer::GBufferLayout& layout, std::string* why) {
    std::string reason;
    if (layout.visibilityBuffer)
        reason = "the visibility buffer stores no attribute plane (surfaces are fetched from the "
                 "triangle per pixel)";
    else if (!layout.hasNormals)
        reason = "the layout stores no normals";
    else if (layout.normals.kind != gbuffer::NormalCodecKind::Float32)
        reason = "normals are stored as codes (only float32 normals are decoded by packets)";
    else if (layout.normalSpace != gbuffer::NormalSpace::View)
        reason = "normals are stored in world space";
    else if (layout.albedo == gbuffer::AlbedoEncoding::Rgb8Srgb)
        reason = "albedo is packed (rgb8-srgb)";
    else if (layout.specular == gbuffer::SpecularEncoding::Unorm8Half ||
             layout.specular == gbuffer::SpecularEncoding::Unorm8Log8)
        reason = "specular is packed";
    else if (layout.roughnessMetallic == gbuffer::RoughnessMetallicEncoding::Unorm8)
        reason = "roughness and metallic are packed (unorm8)";
    else if (layout.occlusion != gbuffer::RoughnessMetallicEncoding::None &&
             layout.occlusion != gbuffer::RoughnessMetallicEncoding::Float32)
        reason = "ambient occlusion is packed (unorm8)";
    if (why)
        *why = reason;
    return reason.empty();
}

PacketDecoder::PacketDecoder(const gbuffer::GBufferLayout& layout, const gbuffer::CameraView& view,
                             const GBufferPlanes& planes)
    : mView(view), mPosition(layout.position) {
    std::string why;
    if (!supports(layout, &why))
        throw std::invalid_argument("packet decoder: layout '" + layout.name +
                                    "' is not supported: " + why);
    PacketDecodeTables& t = mTables;
    t.width = view.width;
    t.height = view.height;
    requirePlane(planes.depth, "Z", layout);
    t.depth = planes.depth;
    t.clearDepth = view.clearDepth();
    for (int k = 0; k < 3; ++k) {
        requirePlane(planes.normal[k], "N", layout);
        t.normal[k] = planes.normal[k];
    }
    t.albedoSource = albedoSource(layout.albedo);
    t.specularSource = specularSource(layout.specular);
    if (t.albedoSource == DecodeSource::Plane)
        for (int k = 0; k < 3; ++k) {
            requirePlane(planes.albedo[k], "albedo", layout);
            t.albedoPlane[k] = planes.albedo[k];
        }
    if (t.specularSource == DecodeSource::Plane)
        for (int k = 0; k < 2; ++k) {
            requirePlane(planes.specular[k], "specular", layout);
            t.specularPlane[k] = planes.specular[k];
        }
    t.roughnessMetallicSource = roughnessMetallicSource(layout.roughnessMetallic);
    if (t.roughnessMetallicSource == DecodeSource::Plane)
        for (int k = 0; k < 2; ++k) {
            requirePlane(planes.roughnessMetallic[k], "roughness/metallic", layout);
            t.roughnessMetallicPlane[k] = planes.roughnessMetallic[k];
        }
    t.constantRoughnessMetallic[0] = layout.constant.roughness;
    t.constantRoughnessMetallic[1] = layout.constant.metallic;
    if (layout.occlusion == gbuffer::RoughnessMetallicEncoding::Float32) {
        requirePlane(planes.occlusion, "occlusion", layout);
        t.occlusionPlane = planes.occlusion;
    }
    t.modelPerMaterial = layout.modelPerMaterial;
    t.constantMetallicRoughness = layout.constant.model == scenes::MaterialModel::MetallicRoughness;
    for (int k = 0; k < 3; ++k)
        t.constantAlbedo[k] = layout.constant.albedo[k];
    t.constantSpecular[0] = layout.constant.specularIntensity;
    t.constantSpecular[1] = layout.constant.specularPower;
    if (layout.hasMaterialIndex()) {
        requirePlane(planes.material, "material", layout);
        t.material = planes.material;
    }
    // The material table as columns plus the "index out of range" entry GBuffer::decode implies.
    t.materialCount = uint32_t(layout.materials.size());
    for (const gbuffer::MaterialConstants& m : layout.materials) {
        for (int k = 0; k < 3; ++k)
            mMaterialColumns[k].push_back(m.albedo[k]);
        mMaterialColumns[3].push_back(m.specularIntensity);
        mMaterialColumns[4].push_back(m.specularPower);
        mMaterialColumns[5].push_back(m.roughness);
        mMaterialColumns[6].push_back(m.metallic);
        mMaterialColumns[7].push_back(m.model == scenes::MaterialModel::MetallicRoughness ? 1.0f
                                                                                          : 0.0f);
    }
    // The sentinel, repeated up to 16 entries so a vector decoder can load a whole column as one
    // vector of up to 16 lanes.
    const float sentinel[8] = {0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 0.0f, 0.0f};
    for (int k = 0; k < 8; ++k)
        mMaterialColumns[k].resize(std::max<size_t>(layout.materials.size() + 1, 16), sentinel[k]);
    for (int k = 0; k < 3; ++k)
        t.materialAlbedo[k] = mMaterialColumns[k].data();
    t.materialSpecular[0] = mMaterialColumns[3].data();
    t.materialSpecular[1] = mMaterialColumns[4].data();
    t.materialRoughnessMetallic[0] = mMaterialColumns[5].data();
    t.materialRoughnessMetallic[1] = mMaterialColumns[6].data();
    t.materialMetallicRoughness = mMaterialColumns[7].data();

    t.viewRay = layout.position == gbuffer::PositionMethod::ViewRay;
    for (int column = 0; column < 4; ++column)
        for (int row = 0; row < 4; ++row)
            t.viewFromClip[column][row] = view.viewFromClip[column][row];
    t.clipFromView00 = view.clipFromView[0][0];
    t.clipFromView11 = view.clipFromView[1][1];
    const gbuffer::DepthProjection projection = gbuffer::DepthProjection::of(view);
    t.reversedZ = projection.reversed;
    t.infiniteFar = projection.infiniteFar;
    // The float values DepthProjection::viewDepthFromNdcFloat computes from its doubles.
    const float n = float(projection.nearMetres), f = float(projection.farMetres);
    t.nearMetres = n;
    t.nearTimesFar = n * f;
    t.farMinusNear = f - n;
}

void PacketDecoder::decode(const KernelIsa& isa, int x0, int y0, ShadingPacket& packet) const {
    const bool inside = x0 >= 0 && y0 >= 0 && x0 + kPacketWidth <= mTables.width &&
                        y0 + kPacketHeight <= mTables.height;
    if (isa.isScalar() || !inside) {
        decodeScalar(x0, y0, packet);
        return;
    }
    isa.vector()->decode(DecodeArgs{&mTables, x0, y0, &packet});
}

void PacketDecoder::decodeScalar(int x0, int y0, ShadingPacket& packet) const {
    const PacketDecodeTables& t = mTables;
    const gbuffer::DepthProjection projection = gbuffer::DepthProjection::of(mView);
    packet.clear(x0, y0);
    for (int lane = 0; lane < kPacketLanes; ++lane) {
        const int x = x0 + laneX(lane), y = y0 + laneY(lane);
        if (x < 0 || y < 0 || x >= t.width || y >= t.height)
            continue;
        const size_t pixel = size_t(y) * size_t(t.width) + size_t(x);
        const float depth = t.depth[pixel];
        if (depth == t.clearDepth)
            continue;
        // GBuffer::reconstructPositionView and GBuffer::decode, channel by channel.
        const glm::vec2 ndc = mView.ndcOfPixel(x, y);
        const glm::vec3 position =
            mPosition == gbuffer::PositionMethod::InverseProjection
                ? gbuffer::positionByInverseProjection(mView, ndc, depth)
                : gbuffer::positionByViewRay(mView, ndc, projection.viewDepthFromNdcFloat(depth));
        const glm::vec3 normal(t.normal[0][pixel], t.normal[1][pixel], t.normal[2][pixel]);
        const uint32_t material =
            t.material ? std::min(uint32_t(t.material[pixel]), t.materialCount) : t.materialCount;
        glm::vec3 albedo(0.0f);
        for (int k = 0; k < 3; ++k) {
            if (t.albedoSource == DecodeSource::Plane)
                albedo[k] = t.albedoPlane[k][pixel];
            else if (t.albedoSource == DecodeSource::Material)
                albedo[k] = t.materialAlbedo[k][material];
            else if (t.albedoSource == DecodeSource::Constant)
                albedo[k] = t.constantAlbedo[k];
        }
        float specular[2] = {0.0f, 1.0f};
        for (int k = 0; k < 2; ++k) {
            if (t.specularSource == DecodeSource::Plane)
                specular[k] = t.specularPlane[k][pixel];
            else if (t.specularSource == DecodeSource::Material)
                specular[k] = t.materialSpecular[k][material];
            else if (t.specularSource == DecodeSource::Constant)
                specular[k] = t.constantSpecular[k];
        }
        packet.setLane(lane, position, normal, albedo, specular[0], specular[1]);
        // Both models' rows are filled whatever the lane's model, with GBuffer::decode's values.
        float roughnessMetallic[2] = {1.0f, 0.0f};
        for (int k = 0; k < 2; ++k) {
            if (t.roughnessMetallicSource == DecodeSource::Plane)
                roughnessMetallic[k] = t.roughnessMetallicPlane[k][pixel];
            else if (t.roughnessMetallicSource == DecodeSource::Material)
                roughnessMetallic[k] = t.materialRoughnessMetallic[k][material];
            else if (t.roughnessMetallicSource == DecodeSource::Constant)
                roughnessMetallic[k] = t.constantRoughnessMetallic[k];
        }
        packet.roughness[lane] = roughnessMetallic[0];
        packet.metallic[lane] = roughnessMetallic[1];
        packet.occlusion[lane] = t.occlusionPlane ? t.occlusionPlane[pixel] : 1.0f;
        const bool metallicRoughness = t.modelPerMaterial
                                           ? t.materialMetallicRoughness[material] != 0.0f
                                           : t.constantMetallicRoughness;
        if (metallicRoughness)
            packet.metallicRoughnessMask |= 1u << lane;
    }
}

} // namespace lighting::kernel
