// GBufferLayout: what the G-buffer stores, as data (Falcor-style channel table). A layout says,
// for each channel a lighting stage can read, how it is encoded; the stored planes (structure of
// arrays), their formats and bits, and the reason each is there follow from that.
//
// Channels are what stages read (Depth, Normal, Albedo, Specular, Emission). How each is stored:
//   depth     a DepthFormatSpec (always present: coverage and position come from it) and the
//             position reconstruction method (inverse projection or view ray)
//   normal    a NormalCodecSpec (absent when no reader needs normals)
//   albedo    f32 (3 x float), rgb8-srgb (24 bits), material (decoded from the per-pixel material
//             index and the layout's material table), constant (one value for the whole scene,
//             0 bits), none
//   specular  the parameters of the material model's specular lobe, one encoding per model:
//             Blinn-Phong  f32 (intensity, power as floats), unorm8+f16 (8-bit intensity, half
//                          power: the thesis' layout), unorm8+log8 (8-bit intensity, 8-bit log
//                          power: Killzone 2's), material, constant, none
//             metallic-roughness (roughnessMetallic)  f32 (roughness, metallic as floats), unorm8
//                          (8 bits each), material, constant, none
//             A scene that uses only one model stores only that model's parameters.
//   emission  f32 (3 x float, where an emissive texture varies it), material, none (no used
//             material emits: decodes to zero, so every layout provides the channel)
//   The material model of a pixel (MaterialConstants::model) is the constant's when every used
//   material has the same model, else it is decoded from the material index (modelPerMaterial).
// A material index plane (8 or 16 bits) exists when albedo, specular or roughness-metallic is
// `material`, or when the model is per material.
// Historical presets also carry `unmodelled` planes: data the original layout stored that no stage
// here reads (ambient occlusion, motion vectors, stencil...). They count in bytesPerPixel, so the
// preset's size is the published one, but are never allocated.
//
// The visibility buffer (`visibilityBuffer`, preset "visibility"; Burns & Hunt, "The Visibility
// Buffer", JCGT 2013) stores depth and the visible triangle's visibility code (32 bits) and no
// attribute at all: every other channel is fetched from the triangle (its vertices interpolated at
// the pixel centre, its material and textures read) where the stage decodes the pixel, so each
// channel is exactly what the rasterizer computes (the lossless layouts' values) for 8 bytes per
// pixel, and the cost moves from G-buffer bytes to fetches at shading time. The channel encodings
// below then only say which channels the scene has (emission present or not); no plane is stored.
//
// Readers never touch planes: they call GBuffer::decode. Layouts are built by LayoutDerivation.h.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/codecs/DepthFormat.h"
#include "gbuffer/codecs/NormalCodec.h"
#include "scenes/materials/Material.h"

namespace gbuffer {

enum class Channel { Depth, Normal, Albedo, Specular, Emission };
const char* channelName(Channel channel);

// Where normals are encoded. View space suits the hemisphere codecs (xy-z, pixel-view,
// stereographic put their precision where visible normals are); world space keeps codes
// independent of the camera (e.g. for temporal reuse) but needs full-sphere codecs.
enum class NormalSpace { View, World };
const char* normalSpaceName(NormalSpace space); // "view", "world"
NormalSpace parseNormalSpace(const std::string& text);
// Whether a codec can hold world-space normals (every direction is equally likely there):
// false for xy-z and pixel-view, which assume a visible hemisphere.
bool codecWorksInWorldSpace(NormalCodecKind kind);

enum class AlbedoEncoding { None, Constant, Material, Rgb8Srgb, Float32 };
enum class SpecularEncoding { None, Constant, Material, Unorm8Log8, Unorm8Half, Float32 };
enum class RoughnessMetallicEncoding { None, Constant, Material, Unorm8, Float32 };
// Emitted radiance: three float planes where an emissive texture makes it vary per pixel,
// `material` (decoded from the material index) where it is constant per material, none where no
// used material emits (decodes to zero).
enum class EmissionEncoding { None, Material, Float32 };
const char* albedoEncodingName(AlbedoEncoding encoding); // "none", "constant", ...
const char* specularEncodingName(SpecularEncoding encoding);
const char* roughnessMetallicEncodingName(RoughnessMetallicEncoding encoding);
const char* emissionEncodingName(EmissionEncoding encoding);

// Per-material values the `material` and `constant` encodings decode from.
struct MaterialConstants {
    glm::vec3 albedo{0.0f};
    float specularIntensity = 0.0f;
    float specularPower = 1.0f;
    scenes::MaterialModel model = scenes::MaterialModel::BlinnPhong;
    float roughness = 1.0f; // the factors (metallic-roughness; the texture multiplies them)
    float metallic = 0.0f;
    glm::vec3 emission{0.0f}; // emissive factor x strength (the texture multiplies it)
    friend bool operator==(const MaterialConstants&, const MaterialConstants&) = default;
};

// One stored plane, as stats.json and --explain-layout show it.
struct PlaneDesc {
    std::string name;    // e.g. "N" (a packed code), "albedo.R", "Z"
    std::string format;  // e.g. "f32", "u32 code of octahedral-precise:24", "unorm8 x3 sRGB"
    int bits = 32;       // bits this plane costs per pixel in the layout's budget
    std::string channel; // "depth", "normal", "albedo", "specular", "material", or "unmodelled"
    bool unmodelled = false;
};

struct GBufferLayout {
    std::string name = "reference";
    DepthFormatSpec depth;
    PositionMethod position = PositionMethod::InverseProjection;
    bool hasNormals = true;
    NormalCodecSpec normals{NormalCodecKind::Float32, 96};
    NormalSpace normalSpace = NormalSpace::View;
    AlbedoEncoding albedo = AlbedoEncoding::Float32;
    SpecularEncoding specular = SpecularEncoding::Float32;
    RoughnessMetallicEncoding roughnessMetallic = RoughnessMetallicEncoding::None;
    bool modelPerMaterial = false; // the model comes from the material index (mixed scenes)
    // Ambient occlusion of metallic-roughness materials (Surface::occlusion, ambient light only):
    // stored only when a used material has an occlusion texture and the scene an ambient light;
    // else it decodes to 1. f32 (derived, lossless) or unorm8 (presets).
    RoughnessMetallicEncoding occlusion = RoughnessMetallicEncoding::None;
    // Emitted radiance (Channel::Emission): planes only where a used material emits
    // (LayoutDerivation.h addEmission).
    EmissionEncoding emission = EmissionEncoding::None;
    std::vector<MaterialConstants> materials; // index = scene material, for `material`
    MaterialConstants constant;               // for `constant`
    std::vector<PlaneDesc> unmodelled;        // historical presets only
    std::map<Channel, std::string> reasons;   // why each channel is stored as it is
    // Why a plane that is one part of a channel is there (roughness, metallic, occlusion: the
    // specular channel of metallic-roughness materials), by plane name; explain() prefers it to
    // the channel's reason.
    std::map<std::string, std::string> planeReasons;
    // Parts of a channel the scene could have needed but that are not stored, with why
    // (e.g. occlusion textures without an ambient light): explain()'s "(no ... plane)" lines.
    std::vector<std::pair<std::string, std::string>> absentPlanes;
    std::vector<std::string> notes; // e.g. where a preset departs from its source
    // Depth and the visibility code only; every other channel is fetched from the triangle where
    // it is decoded (see the top of this file). The encodings above are then not stored.
    bool visibilityBuffer = false;

    // Whether a reader can decode this channel (a `constant` channel can, with no plane).
    bool provides(Channel channel) const;
    bool hasMaterialIndex() const {
        return albedo == AlbedoEncoding::Material || specular == SpecularEncoding::Material ||
               roughnessMetallic == RoughnessMetallicEncoding::Material || modelPerMaterial ||
               emission == EmissionEncoding::Material;
    }
    int materialIndexBits() const { return materials.size() <= 256 ? 8 : 16; }
    // Every plane of the layout, including unmodelled ones.
    std::vector<PlaneDesc> planes() const;
    // Sum of the planes' bits / 8: the layout's size as a GPU packs it (bits, not our CPU arrays).
    double bytesPerPixel() const;
    // Bytes per pixel this program actually allocates for the layout (planes are padded to 8,
    // 16, 32 or 64-bit arrays, unmodelled planes are not allocated, depth is a float working
    // plane).
    double allocatedBytesPerPixel() const;
    // One line per plane with its format, bits and the reason it is there, then the notes.
    std::string explain() const;

    // How readers get depth and position back from this layout's depth plane.
    DepthDecoder depthDecoder(const CameraView& view) const { return {depth, position, view}; }

    // float32 reversed-Z depth, float32 view-space normal, float32 albedo RGB, float32 specular
    // (intensity, power): lossless with respect to what the rasterizer computes for Blinn-Phong
    // scenes (LayoutDerivation.h's addMaterialModels adds what metallic-roughness materials need).
    static GBufferLayout reference();
    // The reference layout with float depth in the given convention and far plane: what the
    // rasterizer computes, kept as is (the surface forward stages shade).
    static GBufferLayout lossless(DepthConvention depth, bool infiniteFar = false);
};

} // namespace gbuffer
