// GltfConverter: the pieces of the glTF loader (loadGltf, GltfLoader.cpp) that its files share:
// reading and parsing a file within the limits (GltfParse.cpp), and the converter from a parsed
// tinygltf::Model to a Scene, whose methods live in GltfLoader.cpp (nodes, cameras, lights,
// primitives), GltfMaterials.cpp (materials and textures) and GltfAccessors.cpp (accessor reads).
// Internal to scenes/gltf/: nothing outside this room includes it.
#pragma once

#include <bit>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <tiny_gltf.h>

#include "scenes/Scene.h"
#include "scenes/SceneLoader.h"

namespace scenes::gltf {

namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little,
              "glTF buffers are little-endian and are read with memcpy");

// Deeper node hierarchies are treated as malformed: real files nest a few dozen levels (deep
// skeletons a few hundred), and the bound keeps the recursive walk's stack small (~200 B/level).
constexpr int kMaxNodeDepth = 1024;
// glTF's infinite far plane (zfar absent) becomes at least this multiple of znear: depth is
// stored with finite precision downstream, and 1e4 keeps a 24-bit standard-Z buffer usable.
constexpr float kInfiniteFarOverNear = 1e4f;
// Extensions a file may require that the loader implements.
inline const std::set<std::string> kImplementedExtensions = {
    "KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_emissive_strength"};
// Markers in GltfConverter::mMeshOf for primitives not (yet) turned into a Mesh.
constexpr int kNotConverted = -1;
constexpr int kSkipped = -2;

[[noreturn]] inline void fail(const fs::path& path, const std::string& what) {
    throw SceneError(path.string() + ": " + what);
}

inline std::string str(size_t value) {
    return std::to_string(value);
}

// tinygltf's messages end lines with '\n'; a SceneError is one line.
inline std::string oneLine(const std::string& text) {
    std::string line;
    for (char c : text) {
        if (c != '\n')
            line += c;
        else if (!line.empty() && line.back() != ' ')
            line += "; ";
    }
    while (!line.empty() && (line.back() == ' ' || line.back() == ';'))
        line.pop_back();
    return line;
}

// What the image callbacks learn while tinygltf reads a file: why an image was not decoded (by
// image index), and the decoded texture memory granted so far (limits::kMaxTextureBytes).
struct ImageBudget {
    std::map<int, std::string> problems;
    uint64_t decodedBytes = 0;
};

// Reads an encoded image's header (stb_image, the decoder tinygltf uses) and grants its decoded
// size from the budget. Returns why it must not be decoded, or "" when it may be.
std::string admitImage(const unsigned char* bytes, int size, ImageBudget& budget);

// Reads and parses the file (glTF or GLB) within the limits; images are admitted against
// imageBudget before they are decoded. Throws SceneError naming the file.
tinygltf::Model parseModel(const fs::path& path, ImageBudget& imageBudget);

// Where an accessor's elements lie, once checked to be inside their bufferView and buffer.
struct AccessorData {
    const unsigned char* first = nullptr;
    size_t strideBytes = 0;
    size_t count = 0;
};

class GltfConverter {
public:
    GltfConverter(fs::path path, tinygltf::Model model, ImageBudget imageBudget)
        : mPath(std::move(path)), mModel(std::move(model)), mImageBudget(std::move(imageBudget)) {}

    Scene convert();

private:
    [[noreturn]] void fail(const std::string& what) const { gltf::fail(mPath, what); }
    void warn(const std::string& what);
    // value as a float, or a SceneError naming the field (its glTF JSON path, e.g.
    // "nodes[3].scale[0]") when it is not finite in float (scenes/input/FloatRange.h). Every
    // number the converter stores passes through here (issue 32, class 1).
    float narrow(double value, const std::string& field) const;
    // A problem of SceneChecks.h (or "") as a SceneError naming the element.
    void check(const std::string& problem, const std::string& element) const {
        if (!problem.empty())
            fail(element + ": " + problem);
    }

    void checkExtensions() const;
    void checkSizes() const;
    void readImages();
    std::vector<int> parentOfEachNode() const;
    std::vector<int> rootNodes(const std::vector<int>& parentOf) const;
    void visitNode(int nodeIndex, const glm::mat4& worldFromParent, int depth);
    glm::mat4 parentFromNode(int nodeIndex) const;
    void considerCamera(int cameraIndex, const glm::mat4& worldFromCamera);
    void addCamera(int cameraIndex, const glm::mat4& worldFromCamera);
    void setCameraBasis(Camera& camera, const glm::mat3& worldFromCamera, const std::string& field);
    void addLights();

    int meshFor(int meshIndex, size_t primitiveIndex);
    Mesh convertPrimitive(int meshIndex, size_t primitiveIndex);
    uint32_t materialFor(int materialIndex);
    int textureFor(int textureIndex, bool srgb);
    int textureFor(int textureIndex, int texCoord, const tinygltf::ExtensionMap& extensions,
                   bool srgb, const std::string& where, TextureMapping& mapping);

    const tinygltf::Accessor& accessorAt(int accessorIndex, const std::string& what) const;
    AccessorData accessorData(const tinygltf::Accessor& accessor, const std::string& where) const;
    template <int N>
    std::vector<glm::vec<N, float>> readVectors(int accessorIndex, const std::string& what,
                                                bool allowNormalizedIntegers = false) const;
    std::vector<uint32_t> readIndices(int accessorIndex, const std::string& what,
                                      size_t vertexCount) const;

    fs::path mPath;
    tinygltf::Model mModel;
    ImageBudget mImageBudget; // images not decoded (and why), decoded bytes granted
    Scene mScene;
    std::set<std::string> mWarned;
    std::vector<bool> mOnPath;             // per node: on the path from the root being walked
    std::vector<std::vector<int>> mMeshOf; // [mesh][primitive] -> Scene::meshes index or marker
    std::vector<int> mMaterialOf;          // per glTF material -> Scene::materials, -1 = not yet
    int mDefaultMaterial = -1;             // Scene::materials index of the default, -1 = none
    std::map<std::pair<int, bool>, int> mTextureOf;        // (image, srgb) -> Scene::textures index
    std::vector<std::pair<int, glm::mat4>> mPlacedCameras; // (camera, worldFromCamera), walk order
    std::vector<std::pair<int, glm::mat4>> mPlacedLights;  // (KHR light, worldFromLight)
    std::map<int, Aabb> mBoundsOfMesh; // Scene::meshes index -> object-space bounds, once each
};

} // namespace scenes::gltf
