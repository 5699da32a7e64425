#include "scenes/gltf/GltfConverter.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <set>
#include <system_error>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <stb/stb_image.h>
#include <tiny_gltf.h>

#include "scenes/SceneChecks.h"
#include "scenes/Viewpoints.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/mesh/Tangents.h"

namespace scenes::gltf {

// A glTF material: the metallic-roughness model with its factors, textures (each with its uv set
// and KHR_texture_transform), alpha mode and KHR_materials_emissive_strength. The Blinn-Phong pair
// is the approximation setBlinnPhongFromMetallicRoughness gives, for studies that force
// Blinn-Phong.
uint32_t GltfConverter::materialFor(int materialIndex) {
    if (materialIndex < 0) {
        // A primitive without a material gets a plain white dielectric (Material's defaults,
        // roughness 0.5) rather than glTF's default (fully metallic, fully rough), which the
        // Blinn-Phong approximation draws badly.
        if (mDefaultMaterial < 0) {
            mDefaultMaterial = int(mScene.materials.size());
            Material material;
            material.name = "default";
            material.model = MaterialModel::MetallicRoughness;
            mScene.materials.push_back(material);
        }
        return uint32_t(mDefaultMaterial);
    }
    if (size_t(materialIndex) >= mModel.materials.size())
        fail("material " + std::to_string(materialIndex) + " out of range");
    if (mMaterialOf[size_t(materialIndex)] >= 0)
        return uint32_t(mMaterialOf[size_t(materialIndex)]);

    const tinygltf::Material& source = mModel.materials[size_t(materialIndex)];
    const tinygltf::PbrMetallicRoughness& pbr = source.pbrMetallicRoughness;
    const std::string where = "material " + std::to_string(materialIndex);
    const std::string field = "materials[" + std::to_string(materialIndex) + "]";
    Material material;
    material.name = source.name.empty() ? where : source.name;
    material.model = MaterialModel::MetallicRoughness;
    if (pbr.baseColorFactor.size() != 4)
        fail(where + ": baseColorFactor needs 4 numbers");
    for (int c = 0; c < 4; ++c)
        material.baseColorFactor[c] =
            narrow(pbr.baseColorFactor[size_t(c)],
                   field + ".pbrMetallicRoughness.baseColorFactor[" + std::to_string(c) + "]");
    if (!(pbr.metallicFactor >= 0.0 && pbr.metallicFactor <= 1.0))
        fail(where + ": metallicFactor outside [0, 1]");
    if (!(pbr.roughnessFactor >= 0.0 && pbr.roughnessFactor <= 1.0))
        fail(where + ": roughnessFactor outside [0, 1]");
    material.metallic = float(pbr.metallicFactor);
    material.roughness = float(pbr.roughnessFactor);
    setBlinnPhongFromMetallicRoughness(material);

    // Colour textures are sRGB, data textures linear (glTF 2.0, "Materials").
    material.baseColorTexture = textureFor(
        pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
        true, where + " baseColorTexture", material.baseColorMapping);
    material.metallicRoughnessTexture =
        textureFor(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                   pbr.metallicRoughnessTexture.extensions, false,
                   where + " metallicRoughnessTexture", material.metallicRoughnessMapping);
    material.normalTexture = textureFor(source.normalTexture.index, source.normalTexture.texCoord,
                                        source.normalTexture.extensions, false,
                                        where + " normalTexture", material.normalMapping);
    material.occlusionTexture =
        textureFor(source.occlusionTexture.index, source.occlusionTexture.texCoord,
                   source.occlusionTexture.extensions, false, where + " occlusionTexture",
                   material.occlusionMapping);
    material.emissiveTexture =
        textureFor(source.emissiveTexture.index, source.emissiveTexture.texCoord,
                   source.emissiveTexture.extensions, true, where + " emissiveTexture",
                   material.emissiveMapping);

    material.normalScale = narrow(source.normalTexture.scale, field + ".normalTexture.scale");
    if (!(source.occlusionTexture.strength >= 0.0 && source.occlusionTexture.strength <= 1.0))
        fail(where + ": occlusionTexture.strength outside [0, 1]");
    material.occlusionStrength = float(source.occlusionTexture.strength);
    if (source.emissiveFactor.size() != 3)
        fail(where + ": emissiveFactor needs 3 numbers");
    for (double component : source.emissiveFactor)
        if (!(component >= 0.0 && component <= 1.0))
            fail(where + ": emissiveFactor outside [0, 1]");
    material.emissiveFactor =
        glm::vec3(source.emissiveFactor[0], source.emissiveFactor[1], source.emissiveFactor[2]);
    const auto strength = source.extensions.find("KHR_materials_emissive_strength");
    if (strength != source.extensions.end()) {
        const tinygltf::Value& value = strength->second;
        if (!value.IsObject())
            fail(where + ": KHR_materials_emissive_strength is not an object");
        if (value.Has("emissiveStrength")) {
            const tinygltf::Value& number = value.Get("emissiveStrength");
            if (!number.IsNumber() || !(number.GetNumberAsDouble() >= 0.0) ||
                !std::isfinite(number.GetNumberAsDouble()))
                fail(where + ": KHR_materials_emissive_strength.emissiveStrength must be a "
                             "finite number >= 0");
            material.emissiveStrength =
                narrow(number.GetNumberAsDouble(),
                       field + ".extensions.KHR_materials_emissive_strength.emissiveStrength");
        }
    }

    if (source.alphaMode == "OPAQUE")
        material.alphaMode = AlphaMode::Opaque;
    else if (source.alphaMode == "MASK")
        material.alphaMode = AlphaMode::Mask;
    else if (source.alphaMode == "BLEND")
        material.alphaMode = AlphaMode::Blend;
    else
        fail(where + ": alphaMode '" + source.alphaMode + "' (expected OPAQUE, MASK or BLEND)");
    if (!(source.alphaCutoff >= 0.0) || !std::isfinite(source.alphaCutoff))
        fail(where + ": alphaCutoff must be a finite number >= 0");
    material.alphaCutoff = narrow(source.alphaCutoff, field + ".alphaCutoff");
    material.doubleSided = source.doubleSided;
    check(materialProblem(material), field + " ('" + material.name + "')");

    mMaterialOf[size_t(materialIndex)] = int(mScene.materials.size());
    mScene.materials.push_back(material);
    return uint32_t(mMaterialOf[size_t(materialIndex)]);
}

// A texture slot of a material: the texture (see textureFor below) and its mapping, the texCoord
// set and KHR_texture_transform (whose texCoord, when given, overrides the slot's). A texture
// reading a uv set past TEXCOORD_1 is dropped with a warning: the factor alone applies.
int GltfConverter::textureFor(int textureIndex, int texCoord,
                              const tinygltf::ExtensionMap& extensions, bool srgb,
                              const std::string& where, TextureMapping& mapping) {
    if (textureIndex < 0)
        return -1;
    const auto transform = extensions.find("KHR_texture_transform");
    if (transform != extensions.end()) {
        const tinygltf::Value& value = transform->second;
        if (!value.IsObject())
            fail(where + ": KHR_texture_transform is not an object");
        auto number = [&](const tinygltf::Value& v, const std::string& field) {
            if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
                fail(where + ": KHR_texture_transform." + field + " must be a finite number");
            // Finite in double is not enough: an offset of 1e39 is +Inf as the float the uvs
            // are mapped with, and every lookup would fall back to white.
            return narrow(v.GetNumberAsDouble(), where + ": KHR_texture_transform." + field);
        };
        auto pair = [&](const std::string& field, glm::vec2& into) {
            if (!value.Has(field))
                return;
            const tinygltf::Value& array = value.Get(field);
            if (!array.IsArray() || array.ArrayLen() != 2)
                fail(where + ": KHR_texture_transform." + field + " needs 2 numbers");
            into =
                glm::vec2(number(array.Get(0), field + "[0]"), number(array.Get(1), field + "[1]"));
        };
        pair("offset", mapping.offset);
        pair("scale", mapping.scale);
        if (value.Has("rotation"))
            mapping.rotationRadians = number(value.Get("rotation"), "rotation");
        if (value.Has("texCoord")) {
            if (!value.Get("texCoord").IsInt())
                fail(where + ": KHR_texture_transform.texCoord must be an integer");
            texCoord = value.Get("texCoord").Get<int>();
        }
    }
    if (texCoord < 0)
        fail(where + ": texCoord " + std::to_string(texCoord) + " is negative");
    if (texCoord > 1) {
        warn(where + " reads TEXCOORD_" + std::to_string(texCoord) +
             "; only TEXCOORD_0 and TEXCOORD_1 are kept, so the texture is not used");
        return -1;
    }
    mapping.texCoord = texCoord;
    return textureFor(textureIndex, srgb);
}

// Scene::textures index for a glTF texture, -1 (fall back to the factor) when its image could
// not be read. Colour and data uses of one image are separate Textures, as srgb differs.
int GltfConverter::textureFor(int textureIndex, bool srgb) {
    if (textureIndex < 0)
        return -1;
    if (size_t(textureIndex) >= mModel.textures.size())
        fail("texture " + std::to_string(textureIndex) + " out of range");
    const int imageIndex = mModel.textures[size_t(textureIndex)].source;
    if (imageIndex < 0) {
        warn("texture " + std::to_string(textureIndex) +
             " has no image source we can read; materials using it fall back to their factors");
        return -1;
    }
    if (size_t(imageIndex) >= mModel.images.size())
        fail("texture " + std::to_string(textureIndex) + ": image " + std::to_string(imageIndex) +
             " out of range");
    const tinygltf::Image& image = mModel.images[size_t(imageIndex)];
    if (image.image.empty())
        return -1; // readImages warned
    const auto cached = mTextureOf.find({imageIndex, srgb});
    if (cached != mTextureOf.end())
        return cached->second;

    Texture texture;
    texture.name = image.uri.empty() ? "image " + std::to_string(imageIndex) : image.uri;
    texture.width = image.width;
    texture.height = image.height;
    texture.srgb = srgb;
    const size_t pixelCount = size_t(image.width) * size_t(image.height);
    const size_t components = size_t(image.component);
    texture.rgba8.resize(pixelCount * 4);
    // 16-bit channels keep their high byte (stb returns native-endian, here little-endian).
    const size_t bytesPerChannel = size_t(image.bits / 8);
    auto channel = [&](size_t pixel, size_t c) {
        return image.image[(pixel * components + c) * bytesPerChannel + bytesPerChannel - 1];
    };
    for (size_t p = 0; p < pixelCount; ++p) {
        uint8_t* out = &texture.rgba8[p * 4];
        // 1 component is grey, 2 grey + alpha, 3 RGB, 4 RGBA.
        const bool grey = components <= 2;
        out[0] = channel(p, 0);
        out[1] = grey ? out[0] : channel(p, 1);
        out[2] = grey ? out[0] : channel(p, 2);
        out[3] = components == 2 ? channel(p, 1) : components == 4 ? channel(p, 3) : 255;
    }
    const int index = int(mScene.textures.size());
    mScene.textures.push_back(std::move(texture));
    mTextureOf[{imageIndex, srgb}] = index;
    return index;
}

} // namespace scenes::gltf
