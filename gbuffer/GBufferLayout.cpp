#include "gbuffer/GBufferLayout.h"

#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace gbuffer {

namespace {

struct AlbedoInfo {
    AlbedoEncoding encoding;
    const char* name;
};
constexpr AlbedoInfo kAlbedoEncodings[] = {
    {AlbedoEncoding::None, "none"},         {AlbedoEncoding::Constant, "constant"},
    {AlbedoEncoding::Material, "material"}, {AlbedoEncoding::Rgb8Srgb, "rgb8-srgb"},
    {AlbedoEncoding::Float32, "f32"},
};
struct SpecularInfo {
    SpecularEncoding encoding;
    const char* name;
};
constexpr SpecularInfo kSpecularEncodings[] = {
    {SpecularEncoding::None, "none"},
    {SpecularEncoding::Constant, "constant"},
    {SpecularEncoding::Material, "material"},
    {SpecularEncoding::Unorm8Log8, "unorm8+log8"},
    {SpecularEncoding::Unorm8Half, "unorm8+f16"},
    {SpecularEncoding::Float32, "f32"},
};

struct RoughnessMetallicInfo {
    RoughnessMetallicEncoding encoding;
    const char* name;
};
constexpr RoughnessMetallicInfo kRoughnessMetallicEncodings[] = {
    {RoughnessMetallicEncoding::None, "none"},
    {RoughnessMetallicEncoding::Constant, "constant"},
    {RoughnessMetallicEncoding::Material, "material"},
    {RoughnessMetallicEncoding::Unorm8, "unorm8"},
    {RoughnessMetallicEncoding::Float32, "f32"},
};

// Bytes of the CPU array that holds a plane of `bits` bits (the next power-of-two word).
int storageBytes(int bits) {
    return bits <= 8 ? 1 : bits <= 16 ? 2 : bits <= 32 ? 4 : 8;
}

} // namespace

const char* channelName(Channel channel) {
    switch (channel) {
    case Channel::Depth:
        return "depth";
    case Channel::Normal:
        return "normal";
    case Channel::Albedo:
        return "albedo";
    case Channel::Specular:
        return "specular";
    case Channel::Emission:
        return "emission";
    }
    return "?";
}

const char* normalSpaceName(NormalSpace space) {
    return space == NormalSpace::View ? "view" : "world";
}

NormalSpace parseNormalSpace(const std::string& text) {
    if (text == "view")
        return NormalSpace::View;
    if (text == "world")
        return NormalSpace::World;
    throw std::invalid_argument("unknown normal space '" + text + "'; valid: view, world");
}

bool codecWorksInWorldSpace(NormalCodecKind kind) {
    return kind != NormalCodecKind::XyReconstructZ && kind != NormalCodecKind::PixelView;
}

const char* albedoEncodingName(AlbedoEncoding encoding) {
    for (const AlbedoInfo& info : kAlbedoEncodings)
        if (info.encoding == encoding)
            return info.name;
    return "?";
}

const char* specularEncodingName(SpecularEncoding encoding) {
    for (const SpecularInfo& info : kSpecularEncodings)
        if (info.encoding == encoding)
            return info.name;
    return "?";
}

const char* roughnessMetallicEncodingName(RoughnessMetallicEncoding encoding) {
    for (const RoughnessMetallicInfo& info : kRoughnessMetallicEncodings)
        if (info.encoding == encoding)
            return info.name;
    return "?";
}

const char* emissionEncodingName(EmissionEncoding encoding) {
    switch (encoding) {
    case EmissionEncoding::None:
        return "none";
    case EmissionEncoding::Material:
        return "material";
    case EmissionEncoding::Float32:
        return "f32";
    }
    return "?";
}

bool GBufferLayout::provides(Channel channel) const {
    switch (channel) {
    case Channel::Depth:
        return true;
    case Channel::Normal:
        return hasNormals;
    case Channel::Albedo:
        return albedo != AlbedoEncoding::None;
    case Channel::Specular:
        return specular != SpecularEncoding::None ||
               roughnessMetallic != RoughnessMetallicEncoding::None;
    case Channel::Emission:
        return true; // `none` is chosen only where nothing emits: zero is the exact value
    }
    return false;
}

std::vector<PlaneDesc> GBufferLayout::planes() const {
    std::vector<PlaneDesc> result;
    result.push_back({"Z", depth.text(), depth.bits(), "depth"});
    if (visibilityBuffer) {
        result.push_back({"triangle", "u32 visibility code", 32, "visibility"});
        return result;
    }
    if (hasNormals) {
        if (normals.kind == NormalCodecKind::Float32) {
            for (const char* name : {"N.X", "N.Y", "N.Z"})
                result.push_back({name,
                                  std::string("f32, ") + normalSpaceName(normalSpace) + " space",
                                  32, "normal"});
        } else {
            result.push_back(
                {"N", "code of " + normals.text() + ", " + normalSpaceName(normalSpace) + " space",
                 normals.bits, "normal"});
        }
    }
    switch (albedo) {
    case AlbedoEncoding::Float32:
        for (const char* name : {"albedo.R", "albedo.G", "albedo.B"})
            result.push_back({name, "f32", 32, "albedo"});
        break;
    case AlbedoEncoding::Rgb8Srgb:
        result.push_back({"albedo", "unorm8 x3, sRGB", 24, "albedo"});
        break;
    default:
        break;
    }
    switch (specular) {
    case SpecularEncoding::Float32:
        result.push_back({"specular.intensity", "f32", 32, "specular"});
        result.push_back({"specular.power", "f32", 32, "specular"});
        break;
    case SpecularEncoding::Unorm8Half:
        result.push_back({"specular.intensity", "unorm8", 8, "specular"});
        result.push_back({"specular.power", "f16", 16, "specular"});
        break;
    case SpecularEncoding::Unorm8Log8:
        result.push_back({"specular.intensity", "unorm8", 8, "specular"});
        result.push_back({"specular.power", "unorm8 of log2(power) / 13", 8, "specular"});
        break;
    default:
        break;
    }
    switch (roughnessMetallic) {
    case RoughnessMetallicEncoding::Float32:
        result.push_back({"roughness", "f32", 32, "specular"});
        result.push_back({"metallic", "f32", 32, "specular"});
        break;
    case RoughnessMetallicEncoding::Unorm8:
        result.push_back({"roughness", "unorm8", 8, "specular"});
        result.push_back({"metallic", "unorm8", 8, "specular"});
        break;
    default:
        break;
    }
    if (occlusion == RoughnessMetallicEncoding::Float32)
        result.push_back({"occlusion", "f32", 32, "specular"});
    if (occlusion == RoughnessMetallicEncoding::Unorm8)
        result.push_back({"occlusion", "unorm8", 8, "specular"});
    if (emission == EmissionEncoding::Float32)
        for (const char* name : {"emission.R", "emission.G", "emission.B"})
            result.push_back({name, "f32", 32, "emission"});
    if (hasMaterialIndex())
        result.push_back({"material", "uint" + std::to_string(materialIndexBits()),
                          materialIndexBits(), "material"});
    for (PlaneDesc plane : unmodelled) {
        plane.unmodelled = true;
        plane.channel = "unmodelled";
        result.push_back(plane);
    }
    return result;
}

double GBufferLayout::bytesPerPixel() const {
    int bits = 0;
    for (const PlaneDesc& plane : planes())
        bits += plane.bits;
    return bits / 8.0;
}

double GBufferLayout::allocatedBytesPerPixel() const {
    double bytes = 0.0;
    for (const PlaneDesc& plane : planes()) {
        if (plane.unmodelled)
            continue;
        // Depth is kept as the rasterizer's float working plane whatever its format (see
        // GBuffer.h).
        bytes += plane.channel == "depth" ? 4 : storageBytes(plane.bits);
    }
    return bytes;
}

std::string GBufferLayout::explain() const {
    std::ostringstream out;
    out << "G-buffer layout '" << name << "': " << bytesPerPixel() << " bytes per pixel ("
        << allocatedBytesPerPixel() << " allocated)\n";
    auto reasonOf = [&](const std::string& channel) -> std::string {
        for (const auto& [c, reason] : reasons)
            if (channel == channelName(c))
                return reason;
        return {};
    };
    for (const PlaneDesc& plane : planes()) {
        out << "  " << std::left << std::setw(20) << plane.name << std::setw(36) << plane.format
            << std::right << std::setw(3) << plane.bits << " bits  ";
        if (plane.unmodelled)
            out << "unmodelled: stored by the original layout, read by no stage here";
        else if (plane.channel == "material")
            out << "material index: decodes "
                << (albedo == AlbedoEncoding::Material ? std::string("albedo") : std::string())
                << (albedo == AlbedoEncoding::Material && specular == SpecularEncoding::Material
                        ? " and "
                        : "")
                << (specular == SpecularEncoding::Material ? "specular" : "")
                << (roughnessMetallic == RoughnessMetallicEncoding::Material ? " roughness-metallic"
                                                                             : "")
                << (modelPerMaterial ? " material-model" : "")
                << (emission == EmissionEncoding::Material ? " emission" : "")
                << " from the material table (" << materials.size() << " materials)";
        else if (const auto found = planeReasons.find(plane.name); found != planeReasons.end())
            out << found->second;
        else
            out << reasonOf(plane.channel);
        out << "\n";
    }
    for (Channel channel :
         {Channel::Normal, Channel::Albedo, Channel::Specular, Channel::Emission}) {
        const bool stored = [&] {
            if (visibilityBuffer)
                return false;
            for (const PlaneDesc& plane : planes())
                if (plane.channel == channelName(channel))
                    return true;
            if (channel == Channel::Emission)
                return emission == EmissionEncoding::Material;
            return channel != Channel::Normal && hasMaterialIndex() &&
                   (channel == Channel::Albedo
                        ? albedo == AlbedoEncoding::Material
                        : specular == SpecularEncoding::Material ||
                              roughnessMetallic == RoughnessMetallicEncoding::Material);
        }();
        if (!stored)
            out << "  (no " << channelName(channel) << " plane)  " << reasonOf(channelName(channel))
                << "\n";
    }
    for (const auto& [plane, reason] : absentPlanes)
        out << "  (no " << plane << " plane)  " << reason << "\n";
    out << "  position: " << positionMethodName(position) << " from " << depth.text() << "\n";
    for (const std::string& note : notes)
        out << "  note: " << note << "\n";
    return out.str();
}

GBufferLayout GBufferLayout::reference() {
    GBufferLayout layout;
    layout.name = "reference";
    layout.reasons = {
        {Channel::Depth, "position is reconstructed from depth (float32, reversed Z)"},
        {Channel::Normal, "view-space normal for diffuse and specular terms"},
        {Channel::Albedo, "diffuse colour"},
        {Channel::Specular, "Blinn-Phong specular intensity and exponent"}};
    return layout;
}

GBufferLayout GBufferLayout::lossless(DepthConvention depth, bool infiniteFar) {
    GBufferLayout layout = reference();
    layout.depth.kind =
        depth == DepthConvention::Reversed ? DepthFormatKind::F32Reversed : DepthFormatKind::F32;
    layout.depth.infiniteFar = infiniteFar;
    return layout;
}

} // namespace gbuffer
