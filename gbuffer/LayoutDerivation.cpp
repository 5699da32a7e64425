#include "gbuffer/LayoutDerivation.h"

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

namespace gbuffer {

namespace {

bool reads(const std::vector<Channel>& stageReads, Channel channel) {
    return std::find(stageReads.begin(), stageReads.end(), channel) != stageReads.end();
}

// Materials that some mesh uses: unused entries of a glTF file must not force a plane.
std::set<uint32_t> usedMaterials(const scenes::Scene& scene) {
    std::set<uint32_t> used;
    for (const scenes::Mesh& mesh : scene.meshes)
        used.insert(mesh.material);
    return used;
}

std::string describe(const glm::vec3& v) {
    std::ostringstream out;
    out << "(" << v.x << ", " << v.y << ", " << v.z << ")";
    return out.str();
}

// The compact preset's encodings: the smallest choices whose error on atrium stays under the
// threshold documented in gbuffer/README.md (see the layout study there).
constexpr NormalCodecSpec kCompactNormals{NormalCodecKind::OctahedralPrecise, 24};
constexpr DepthFormatSpec kCompactDepth{DepthFormatKind::Unorm24, false};

// Whether every used material has the same model.
bool oneModel(const scenes::Scene& scene, const std::set<uint32_t>& used) {
    bool blinnPhong = false, metallicRoughness = false;
    for (uint32_t index : used)
        if (index < scene.materials.size())
            (scene.materials[index].model == scenes::MaterialModel::BlinnPhong
                 ? blinnPhong
                 : metallicRoughness) = true;
    return !(blinnPhong && metallicRoughness);
}

} // namespace

std::vector<std::string> layoutPresetNames() {
    return {"reference", "compact", "stalker", "clear-sky", "killzone2",
            "bf3",       "thesis",  "ue4",     "visibility"};
}

std::vector<MaterialConstants> materialTable(const scenes::Scene& scene) {
    std::vector<MaterialConstants> table;
    for (const scenes::Material& m : scene.materials)
        table.push_back({glm::vec3(m.baseColorFactor), m.specularIntensity, m.specularPower,
                         m.model, m.roughness, m.metallic, m.emission()});
    return table;
}

void addMaterialModels(GBufferLayout& layout, const scenes::Scene& scene, bool readsSpecular,
                       bool eightBitPlanes) {
    using scenes::MaterialModel;
    const std::set<uint32_t> used = usedMaterials(scene);
    bool anyMetallicRoughness = false, anyBlinnPhong = false, textured = false, oneValue = true;
    bool occlusionTextured = false;
    const scenes::Material* first = nullptr;
    for (uint32_t index : used) {
        if (index >= scene.materials.size())
            continue;
        const scenes::Material& m = scene.materials[index];
        if (m.model == MaterialModel::BlinnPhong) {
            anyBlinnPhong = true;
            continue;
        }
        anyMetallicRoughness = true;
        textured = textured || m.metallicRoughnessTexture >= 0;
        occlusionTextured = occlusionTextured || m.occlusionTexture >= 0;
        if (!first)
            first = &m;
        oneValue = oneValue && m.roughness == first->roughness && m.metallic == first->metallic;
    }
    layout.modelPerMaterial = anyMetallicRoughness && anyBlinnPhong;
    layout.constant.model = anyMetallicRoughness && !anyBlinnPhong
                                ? MaterialModel::MetallicRoughness
                                : MaterialModel::BlinnPhong;
    if (layout.modelPerMaterial)
        layout.notes.push_back("both material models are used: the model is decoded from the "
                               "material index");
    if (!anyMetallicRoughness || !readsSpecular)
        return;
    layout.constant.roughness = first->roughness;
    layout.constant.metallic = first->metallic;
    std::string& reason = layout.reasons[Channel::Specular];
    reason += reason.empty() ? "" : "; ";
    const std::string readBy = "; read by the metallic-roughness BRDF (MetallicRoughness.h)";
    if (textured) {
        layout.roughnessMetallic =
            eightBitPlanes ? RoughnessMetallicEncoding::Unorm8 : RoughnessMetallicEncoding::Float32;
        const std::string precision = eightBitPlanes ? " (8 bits)" : " (float32, lossless)";
        layout.planeReasons["roughness"] =
            "perceptual roughness, the GGX lobe's width: factor x the metallic-roughness "
            "texture's G, varies per pixel" +
            precision + readBy;
        layout.planeReasons["metallic"] =
            "metallic, which mixes base colour into F0 and removes diffuse: factor x the "
            "metallic-roughness texture's B, varies per pixel" +
            precision + readBy;
        reason += eightBitPlanes ? "metallic-roughness textures: roughness and metallic vary per "
                                   "pixel (8 bits each)"
                                 : "metallic-roughness textures: roughness and metallic vary per "
                                   "pixel (float32, lossless)";
    } else if (oneValue) {
        layout.roughnessMetallic = RoughnessMetallicEncoding::Constant;
        reason += "every metallic-roughness material has roughness " +
                  std::to_string(first->roughness) + " and metallic " +
                  std::to_string(first->metallic) + ": a constant, no plane";
    } else {
        layout.roughnessMetallic = RoughnessMetallicEncoding::Material;
        reason += "roughness and metallic differ between materials but not inside one: material "
                  "index";
    }
    const bool ambient =
        std::any_of(scene.lights.begin(), scene.lights.end(), [](const scenes::Light& light) {
            return light.type == scenes::LightType::Ambient;
        });
    if (occlusionTextured && ambient) {
        layout.occlusion =
            eightBitPlanes ? RoughnessMetallicEncoding::Unorm8 : RoughnessMetallicEncoding::Float32;
        reason += "; occlusion textures and an ambient light: ambient occlusion per pixel";
        layout.planeReasons["occlusion"] =
            "ambient occlusion (1 + strength x (texture R - 1)): occlusion textures, and the scene "
            "has an ambient light, the only light it darkens" +
            std::string(eightBitPlanes ? " (8 bits)" : " (float32, lossless)") + readBy;
    } else if (occlusionTextured) {
        layout.absentPlanes.push_back(
            {"occlusion", "occlusion textures, but no ambient light: occlusion darkens ambient "
                          "light only, so it would change nothing"});
    }
}

void addEmission(GBufferLayout& layout, const scenes::Scene& scene, bool readsEmission) {
    std::string& reason = layout.reasons[Channel::Emission];
    layout.emission = EmissionEncoding::None;
    if (!readsEmission) {
        reason = "the stage does not read emission (it adds its own surfaces' emission, if any)";
        return;
    }
    int emitting = 0;
    bool textured = false;
    for (uint32_t index : usedMaterials(scene)) {
        // Blended surfaces never enter the G-buffer: the blended pass adds their emission from
        // their own surface (lighting/passes/BlendedPass.h).
        if (index >= scene.materials.size() || !scene.materials[index].emits() ||
            scene.materials[index].alphaMode == scenes::AlphaMode::Blend)
            continue;
        ++emitting;
        textured = textured || scene.materials[index].emissiveTexture >= 0;
    }
    if (emitting == 0) {
        reason = "no used material emits (blended ones add their own): emission is zero, no plane";
    } else if (textured) {
        layout.emission = EmissionEncoding::Float32;
        reason = std::to_string(emitting) +
                 " emitting material(s) with an emissive texture: emitted radiance varies per "
                 "pixel (float32 RGB, lossless), added once per pixel after the lights";
    } else {
        layout.emission = EmissionEncoding::Material;
        reason = std::to_string(emitting) +
                 " emitting material(s), untextured: emission is constant per material, decoded "
                 "from the material index";
    }
}

GBufferLayout deriveLayout(const scenes::Scene& scene, const std::vector<Channel>& stageReads) {
    GBufferLayout layout;
    layout.name = "derived";
    layout.materials = materialTable(scene);
    const std::set<uint32_t> used = usedMaterials(scene);
    layout.reasons[Channel::Depth] = reads(stageReads, Channel::Depth)
                                         ? "the stage reads depth; position is reconstructed from "
                                           "it (float32 reversed Z, lossless)"
                                         : "coverage only: the stage does not read depth, but the "
                                           "runner needs to know which pixels are covered";

    layout.hasNormals = reads(stageReads, Channel::Normal);
    layout.reasons[Channel::Normal] = layout.hasNormals
                                          ? "the stage reads normals (float32, lossless)"
                                          : "the stage does not read normals";
    const size_t normalMapped = std::count_if(used.begin(), used.end(), [&](uint32_t index) {
        return index < scene.materials.size() && scene.materials[index].normalTexture >= 0;
    });
    if (layout.hasNormals && normalMapped > 0)
        layout.reasons[Channel::Normal] += "; the shading normal after the normal maps of " +
                                           std::to_string(normalMapped) + " material(s)";

    bool textured = false, oneAlbedo = true, oneSpecular = true, anyBlinnPhong = false;
    const MaterialConstants* first = nullptr;
    const MaterialConstants* firstBlinnPhong = nullptr;
    for (uint32_t index : used) {
        if (index >= layout.materials.size())
            continue; // validated by the scene loader
        textured = textured || scene.materials[index].baseColorTexture >= 0;
        const MaterialConstants& m = layout.materials[index];
        if (!first)
            first = &m;
        oneAlbedo = oneAlbedo && m.albedo == first->albedo;
        if (m.model != scenes::MaterialModel::BlinnPhong)
            continue; // its Blinn-Phong stand-in is not read
        anyBlinnPhong = true;
        if (!firstBlinnPhong)
            firstBlinnPhong = &m;
        oneSpecular = oneSpecular && m.specularIntensity == firstBlinnPhong->specularIntensity &&
                      m.specularPower == firstBlinnPhong->specularPower;
    }
    if (first)
        layout.constant = *first;
    const std::string materialCount = std::to_string(used.size()) + " used material(s)";

    if (!reads(stageReads, Channel::Albedo)) {
        layout.albedo = AlbedoEncoding::None;
        layout.reasons[Channel::Albedo] = "the stage does not read albedo";
    } else if (textured) {
        layout.albedo = AlbedoEncoding::Float32;
        layout.reasons[Channel::Albedo] =
            "textured materials: albedo varies per pixel (float32, lossless)";
    } else if (oneAlbedo && first) {
        layout.albedo = AlbedoEncoding::Constant;
        layout.reasons[Channel::Albedo] = "every used material has albedo " +
                                          describe(first->albedo) +
                                          " and no texture: a constant, no plane";
    } else {
        layout.albedo = AlbedoEncoding::Material;
        layout.reasons[Channel::Albedo] = materialCount + ", no textures: one colour per material, "
                                                          "stored as a material index";
    }

    if (!reads(stageReads, Channel::Specular)) {
        layout.specular = SpecularEncoding::None;
        layout.reasons[Channel::Specular] = "the stage does not read specular";
    } else if (first && !anyBlinnPhong) {
        layout.specular = SpecularEncoding::None;
        layout.reasons[Channel::Specular] = "no used material is Blinn-Phong";
    } else if (oneSpecular && firstBlinnPhong) {
        layout.specular = SpecularEncoding::Constant;
        layout.constant.specularIntensity = firstBlinnPhong->specularIntensity;
        layout.constant.specularPower = firstBlinnPhong->specularPower;
        layout.reasons[Channel::Specular] =
            std::string(!oneModel(scene, used) ? "every used Blinn-Phong material"
                                               : "every used material") +
            " has specular intensity " + std::to_string(firstBlinnPhong->specularIntensity) +
            " and power " + std::to_string(firstBlinnPhong->specularPower) +
            ": a constant, no plane";
    } else {
        layout.specular = SpecularEncoding::Material;
        layout.reasons[Channel::Specular] =
            "specular differs between the " + materialCount + " but not inside one: material index";
    }
    addMaterialModels(layout, scene, reads(stageReads, Channel::Specular), false);
    addEmission(layout, scene, reads(stageReads, Channel::Emission));
    return layout;
}

GBufferLayout presetLayout(const std::string& name, const scenes::Scene& scene) {
    GBufferLayout layout;
    layout.materials = materialTable(scene);
    const std::vector<Channel> everything = {Channel::Depth, Channel::Normal, Channel::Albedo,
                                             Channel::Specular, Channel::Emission};
    if (name == "reference") {
        layout = GBufferLayout::reference();
        layout.materials = materialTable(scene);
        addMaterialModels(layout, scene, true, false);
        addEmission(layout, scene, true);
        return layout;
    }
    if (name == "visibility") {
        // Which channels exist (emission or not, the material models) is the derived layout's
        // answer for a stage that reads everything; nothing but depth and the code is stored.
        layout = deriveLayout(scene, everything);
        layout.name = "visibility";
        layout.visibilityBuffer = true;
        layout.reasons[Channel::Depth] =
            "position is reconstructed from depth (float32, reversed Z); coverage too";
        const std::string fetched =
            "fetched from the visible triangle where the stage decodes the pixel (visibility "
            "buffer: ";
        layout.reasons[Channel::Normal] = fetched + "vertex normals interpolated at the pixel "
                                                    "centre, normal map applied)";
        layout.reasons[Channel::Albedo] = fetched + "material colour times its texture)";
        layout.reasons[Channel::Specular] = fetched + "material parameters and textures)";
        layout.reasons[Channel::Emission] = fetched + "material emission times its texture)";
        layout.planeReasons["triangle"] =
            "visible triangle index + back-face bit (Burns & Hunt 2013): every attribute is "
            "fetched from it at shading time, exactly as the G-buffer pass computes it";
        layout.notes.push_back("8 bytes per pixel whatever the materials; the cost moves to the "
                               "stages, which interpolate each pixel's attributes every time they "
                               "decode it");
        return layout;
    }
    if (name == "compact") {
        layout = deriveLayout(scene, everything);
        layout.name = "compact";
        layout.normals = kCompactNormals;
        layout.depth = kCompactDepth;
        layout.reasons[Channel::Normal] =
            "octahedral-precise:24: the smallest normal code under the "
            "compact error threshold (gbuffer/README.md)";
        layout.reasons[Channel::Depth] =
            "unorm24 standard Z: the smallest depth under the compact threshold";
        if (layout.roughnessMetallic == RoughnessMetallicEncoding::Float32)
            layout.roughnessMetallic = RoughnessMetallicEncoding::Unorm8;
        if (layout.occlusion == RoughnessMetallicEncoding::Float32)
            layout.occlusion = RoughnessMetallicEncoding::Unorm8;
        return layout;
    }
    layout.name = name;
    layout.albedo = AlbedoEncoding::Rgb8Srgb;
    layout.reasons[Channel::Albedo] = "RGB8 diffuse colour, as in the original";
    if (name == "stalker") { // S.T.A.L.K.E.R. (2005), thesis 3.1: 160 bits
        layout.depth = {DepthFormatKind::F16Linear, false};
        layout.position = PositionMethod::ViewRay;
        layout.normals = {NormalCodecKind::Xyz, 48};
        layout.specular = SpecularEncoding::Unorm8Log8;
        layout.unmodelled = {{"P.X,P.Y", "f16 x2", 32, "unmodelled"},
                             {"material-id", "f16", 16, "unmodelled"},
                             {"AO", "f16", 16, "unmodelled"}};
        layout.reasons = {
            {Channel::Depth, "RT0 position.z (f16); x and y follow from the view ray"},
            {Channel::Normal, "RT1 normal xyz (RGB16F; 16-bit SNORM here)"},
            {Channel::Specular, "RT2 alpha gloss (8 bits)"}};
        layout.notes = {"published 160 bits; +8 bits here: our BRDF also needs specular intensity",
                        "normals are RGB16F in the original, SNORM16 (xyz:48) here"};
    } else if (name == "clear-sky") { // S.T.A.L.K.E.R.: Clear Sky (2009), thesis 3.2: 96 bits
        layout.depth = {DepthFormatKind::F16Linear, false};
        layout.position = PositionMethod::ViewRay;
        layout.normals = {NormalCodecKind::XyReconstructZ, 32};
        layout.specular = SpecularEncoding::Unorm8Log8;
        layout.unmodelled = {{"material-id+AO", "f16 bit-packed", 16, "unmodelled"}};
        layout.reasons = {
            {Channel::Depth, "RT0 linear depth in one f16"},
            {Channel::Normal, "RT0 normal X,Y (2 x f16), Z reconstructed (16-bit SNORM here)"},
            {Channel::Specular, "RT1 alpha gloss (8 bits)"}};
        layout.notes = {"published 96 bits; +8 bits here: our BRDF also needs specular intensity"};
    } else if (name == "killzone2") { // Killzone 2 (2007), thesis 3.3: 4 x RGBA8 + D24S8
        layout.depth = {DepthFormatKind::Unorm24, false};
        layout.normals = {NormalCodecKind::XyReconstructZ, 32};
        layout.specular = SpecularEncoding::Unorm8Log8;
        layout.unmodelled = {{"stencil", "uint8", 8, "unmodelled"},
                             {"light-accumulation", "RGBA8", 32, "unmodelled"},
                             {"motion-vectors", "unorm8 x2", 16, "unmodelled"},
                             {"sun-occlusion", "unorm8", 8, "unmodelled"}};
        layout.reasons = {
            {Channel::Depth, "D24 hardware depth"},
            {Channel::Normal, "normal X,Y as FP16 (16-bit SNORM here), Z reconstructed"},
            {Channel::Specular, "spec-power and spec-intensity, 8 bits each"}};
        layout.notes = {
            "published 128 bits in 4 RGBA8 targets plus the D24S8 depth buffer (160 in all)"};
    } else if (name == "bf3") { // Battlefield 3 / Frostbite 2 (2011), thesis 3.4: 4 x RGBA8 + D24S8
        layout.depth = {DepthFormatKind::Unorm24, false};
        layout.normals = {NormalCodecKind::Xyz, 24};
        layout.specular = SpecularEncoding::Unorm8Log8;
        layout.unmodelled = {
            {"stencil", "uint8", 8, "unmodelled"},
            {"sky-visibility,envmap-id,material-param,material-id", "RGBA8", 32, "unmodelled"},
            {"irradiance", "RGBA8", 32, "unmodelled"}};
        layout.reasons = {
            {Channel::Depth, "D24 hardware depth"},
            {Channel::Normal, "GB0 normal xyz in RGB8"},
            {Channel::Specular, "GB0 alpha smoothness and GB1 alpha specular albedo"}};
        layout.notes = {
            "published 128 bits in 4 RGBA8 targets plus the D24S8 depth buffer (160 in all)"};
    } else if (name == "thesis") { // Ishmukhametov 2013, chapter 4: RGBA8 + RGBA16F + D24S8
        layout.depth = {DepthFormatKind::Unorm24, false};
        layout.normals = {NormalCodecKind::Xyz, 48};
        layout.specular = SpecularEncoding::Unorm8Half;
        layout.unmodelled = {{"stencil", "uint8", 8, "unmodelled"}};
        layout.reasons = {
            {Channel::Depth, "D24S8 hardware depth"},
            {Channel::Normal, "RT1 normal xyz (RGB16F; 16-bit SNORM here)"},
            {Channel::Specular, "RT0 alpha intensity (8 bits), RT1 alpha exponent (f16)"}};
        layout.notes = {"published: RGBA8 + RGBA16F + D24S8 = 128 bits"};
    } else if (name == "ue4") {
        // Unreal Engine 4's deferred base pass (4.18-era, DeferredShadingCommon.ush): D32 reversed
        // depth + S8, GBufferA R10G10B10A2 world-space normal + per-object data, GBufferB RGBA8
        // metallic, specular, roughness, shading model ID, GBufferC RGBA8 sRGB base colour + AO.
        // Emission is not in the G-buffer there: the base pass adds it into scene colour.
        layout.depth = {DepthFormatKind::F32Reversed, false};
        layout.normals = {NormalCodecKind::Xyz, 30};
        layout.normalSpace = NormalSpace::World;
        layout.specular = SpecularEncoding::Unorm8Log8;
        layout.unmodelled = {
            {"GBufferA.a", "unorm2 per-object data", 2, "unmodelled"},
            {"GBufferB.a", "uint8 shading model ID + output mask", 8, "unmodelled"},
            {"stencil", "uint8", 8, "unmodelled"}};
        layout.reasons = {
            {Channel::Depth, "D32 reversed-Z hardware depth (UE4 also keeps 8 stencil bits)"},
            {Channel::Normal, "GBufferA RGB10: world-space normal, 10 bits per component"},
            {Channel::Specular,
             "GBufferB: 8-bit specular and roughness (Blinn-Phong here: intensity and log power)"}};
        layout.notes = {"published: D32S8 + 3 x 32-bit targets (GBufferA-C) = 136 bits; GBufferD "
                        "(custom data), E (precomputed shadows) and velocity are optional and "
                        "left out",
                        "UE4 writes n * 0.5 + 0.5 as UNORM10; SNORM10 (xyz:30) here"};
    } else {
        std::string valid;
        for (const std::string& preset : layoutPresetNames())
            valid += (valid.empty() ? "" : ", ") + preset;
        throw std::invalid_argument("unknown G-buffer layout '" + name + "'; valid: " + valid +
                                    " (or none, to derive it from the scene and the stage)");
    }
    layout.reasons[Channel::Albedo] = name == "ue4" ? "GBufferC RGB8 sRGB base colour"
                                                    : "RGB8 diffuse colour, as in the original";
    addMaterialModels(layout, scene, true, true);
    addEmission(layout, scene, true);
    if (name == "ue4") {
        // GBufferB and GBufferC's channels are in the budget whether or not this scene uses them:
        // what a channel does not carry here is counted as unmodelled, so the size stays 136 bits.
        const bool onlyMetallicRoughness =
            !layout.modelPerMaterial &&
            layout.constant.model == scenes::MaterialModel::MetallicRoughness;
        // GBufferB stores roughness and metallic per pixel whatever the materials do.
        if (layout.roughnessMetallic == RoughnessMetallicEncoding::Constant ||
            layout.roughnessMetallic == RoughnessMetallicEncoding::Material)
            layout.roughnessMetallic = RoughnessMetallicEncoding::Unorm8;
        if (onlyMetallicRoughness) {
            layout.specular = SpecularEncoding::None;
            layout.unmodelled.push_back(
                {"GBufferB.g", "unorm8 specular (glTF fixes F0 at 0.04)", 8, "unmodelled"});
        }
        if (layout.roughnessMetallic == RoughnessMetallicEncoding::None)
            layout.unmodelled.push_back({"GBufferB.r",
                                         "unorm8 metallic (no metallic-roughness material)", 8,
                                         "unmodelled"});
        if (layout.modelPerMaterial)
            layout.notes.push_back("+8 bits: both material models are used, so GBufferB holds "
                                   "Blinn-Phong intensity and power beside roughness and metallic");
        if (layout.occlusion == RoughnessMetallicEncoding::None)
            layout.unmodelled.push_back(
                {"GBufferC.a", "unorm8 ambient occlusion", 8, "unmodelled"});
        else
            layout.reasons[Channel::Specular] += "; GBufferC.a ambient occlusion (8 bits)";
    }
    if (layout.emission == EmissionEncoding::Float32)
        layout.notes.push_back("+96 bits: emitted radiance (float32 RGB) for the scene's emissive "
                               "textures; the original added emission into its light buffer "
                               "(scene colour) during the geometry pass");
    if (layout.roughnessMetallic == RoughnessMetallicEncoding::Unorm8 && name != "ue4")
        layout.notes.push_back("+16 bits: roughness and metallic (8 bits each) for the scene's "
                               "metallic-roughness materials, which the original did not model");
    return layout;
}

GBufferLayout makeLayout(const scenes::Scene& scene, const std::vector<Channel>& stageReads,
                         const std::string& stageName, const LayoutRequest& request) {
    GBufferLayout layout = request.preset.empty() ? deriveLayout(scene, stageReads)
                                                  : presetLayout(request.preset, scene);
    if (layout.visibilityBuffer && (request.normals || request.normalSpace))
        throw std::invalid_argument(
            "G-buffer layout 'visibility' stores no normals (they are interpolated from the "
            "visible triangle where the stage shades): --normals and --normal-space do not apply");
    if (request.normals) {
        if (!reads(stageReads, Channel::Normal) && !layout.hasNormals) {
            layout.notes.push_back("stage '" + stageName +
                                   "' does not read normals: the normal encoding " +
                                   request.normals->text() + " is not stored");
        } else {
            layout.normals = *request.normals;
            layout.reasons[Channel::Normal] =
                "normal encoding " + request.normals->text() + " (requested)";
        }
    }
    if (request.depth) {
        layout.depth = *request.depth;
        layout.reasons[Channel::Depth] = "depth format " + request.depth->text() + " (requested)";
        if (!request.position)
            layout.position = request.depth->kind == DepthFormatKind::F16Linear
                                  ? PositionMethod::ViewRay
                                  : PositionMethod::InverseProjection;
    }
    if (request.position)
        layout.position = *request.position;
    if (request.normalSpace)
        layout.normalSpace = *request.normalSpace;
    if (layout.hasNormals && layout.normalSpace == NormalSpace::World &&
        !codecWorksInWorldSpace(layout.normals.kind))
        throw std::invalid_argument(
            "normal encoding " + layout.normals.text() +
            " assumes view-space normals facing the camera; it cannot store world-space normals");
    if (request.preset.empty() &&
        (request.normals || request.depth || request.position || request.normalSpace))
        layout.name = "derived+overrides";
    if (!request.preset.empty() &&
        (request.normals || request.depth || request.position || request.normalSpace))
        layout.name += "+overrides";
    for (Channel channel : stageReads)
        if (!layout.provides(channel))
            throw std::invalid_argument("stage '" + stageName + "' reads the " +
                                        channelName(channel) + " channel, which G-buffer layout '" +
                                        layout.name + "' does not store");
    return layout;
}

} // namespace gbuffer
