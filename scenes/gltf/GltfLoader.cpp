// GltfLoader: loadGltf() turns a glTF 2.0 file into a Scene, through tinygltf. A file that starts
// with the GLB magic is read as binary glTF, any other as JSON text (a .glb without it is an
// error).
//
// What is read: the node hierarchy of the default scene (else scene 0, else every root node)
// with matrix or TRS transforms; every TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive
// becomes one Mesh (one per primitive, stored once however many nodes use it, one Instance per
// node that uses it); POSITION, NORMAL, TANGENT, TEXCOORD_0, TEXCOORD_1 (when a material's
// texture reads it) and indices; every perspective camera met in the walk (Viewpoints.h);
// KHR_lights_punctual lights; metallic-roughness materials (see materialFor) with every texture's
// texCoord and KHR_texture_transform, and KHR_materials_emissive_strength. Tangents absent from a
// primitive whose material has a normal texture are generated (Tangents.h).
// What is not: animations, skins and morph targets (the bind pose is drawn), sparse accessors
// (an error), texture coordinate sets past 1 (the texture is dropped with a warning), samplers
// (Texture always wraps). Points and lines are skipped with a warning.
//
// Conventions: glTF's own, which are Scene's (right-handed, metres, +Y up, cameras look down
// -Z, counter-clockwise front faces); matrices are column-major like glm.
// Robustness: tinygltf parses the JSON and reads buffers and images but does not check that
// accessors fit their buffers, that indices fit the vertices, or that the node graph is a tree;
// this file checks all of it before reading, so a malformed file gives one SceneError naming the
// file, never a crash or a hang. An image that cannot be read is not an error: it gives one
// warning naming it (Scene::warnings and stderr) and materials fall back to their factors.
// Limits (scenes/Limits.h) are checked before the memory they bound is allocated: the JSON's
// nesting before tinygltf parses it (tinygltf converts JSON recursively), every file's size
// before it is read (external buffers and images must be regular files), an image's declared
// size before it is decoded, and the vertices and drawn triangles every primitive would add
// before any is converted.
// Thread safety: each call owns its tinygltf instance; calls may run concurrently.
#include "scenes/SceneLoader.h"

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

#include "scenes/Limits.h"
#include "scenes/NestingDepth.h"
#include "scenes/Tangents.h"
#include "scenes/Viewpoints.h"

namespace scenes {

namespace {

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
const std::set<std::string> kImplementedExtensions = {
    "KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_emissive_strength"};
// Markers in GltfConverter::mMeshOf for primitives not (yet) turned into a Mesh.
constexpr int kNotConverted = -1;
constexpr int kSkipped = -2;

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw SceneError(path.string() + ": " + what);
}

std::string str(size_t value) {
    return std::to_string(value);
}

// tinygltf's messages end lines with '\n'; a SceneError is one line.
std::string oneLine(const std::string& text) {
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

std::vector<unsigned char> readFile(const fs::path& path) {
    std::error_code error;
    if (!fs::exists(path, error))
        fail(path, "file not found");
    if (!fs::is_regular_file(path, error))
        fail(path, "not a regular file");
    const uintmax_t size = fs::file_size(path, error);
    if (error)
        fail(path, "cannot read the size: " + error.message());
    if (size > limits::kMaxFileBytes)
        fail(path, "the file has " + str(size) + " bytes, more than the limit of " +
                       str(limits::kMaxFileBytes));
    std::vector<unsigned char> bytes(size);
    std::ifstream in(path, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
        fail(path, "cannot be read");
    return bytes;
}

bool isGlb(const std::vector<unsigned char>& bytes) {
    return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// tinygltf 2.7 checks the BIN chunk's length without counting its 8-byte header, so a truncated
// GLB can make it read past the end of the file; the layout is checked here first.
void checkGlbLayout(const fs::path& path, const std::vector<unsigned char>& bytes) {
    auto word = [&](size_t offset) {
        uint32_t value;
        std::memcpy(&value, bytes.data() + offset, 4);
        return value;
    };
    constexpr uint32_t kJsonChunk = 0x4E4F534A; // "JSON"
    if (bytes.size() < 20)
        fail(path, "GLB file shorter than its 20-byte header");
    if (word(4) != 2)
        fail(path, "GLB version " + str(word(4)) + " (expected 2)");
    if (word(8) != bytes.size())
        fail(path, "GLB header gives a length of " + str(word(8)) + " bytes, the file has " +
                       str(bytes.size()));
    if (word(16) != kJsonChunk)
        fail(path, "the first GLB chunk is not JSON");
    const uint64_t jsonEnd = 20 + uint64_t(word(12));
    if (jsonEnd > bytes.size())
        fail(path, "the GLB JSON chunk runs past the end of the file");
    if (jsonEnd == bytes.size())
        return; // no BIN chunk
    if (jsonEnd + 8 > bytes.size())
        fail(path, "truncated GLB chunk header after the JSON chunk");
    if (jsonEnd + 8 + word(size_t(jsonEnd)) > bytes.size())
        fail(path, "the GLB BIN chunk runs past the end of the file");
}

// What the image callbacks learn while tinygltf reads a file: why an image was not decoded (by
// image index), and the decoded texture memory granted so far (limits::kMaxTextureBytes).
struct ImageBudget {
    std::map<int, std::string> problems;
    uint64_t decodedBytes = 0;
};

// Reads an encoded image's header (stb_image, the decoder tinygltf uses) and grants its decoded
// size from the budget. Returns why it must not be decoded, or "" when it may be.
std::string admitImage(const unsigned char* bytes, int size, ImageBudget& budget) {
    int width = 0, height = 0, components = 0;
    if (size <= 0 || !stbi_info_from_memory(bytes, size, &width, &height, &components))
        return "could not be decoded";
    const uint64_t pixels = uint64_t(width) * uint64_t(height);
    if (width > limits::kMaxTextureSide || height > limits::kMaxTextureSide ||
        pixels > limits::kMaxTexturePixels)
        return "is " + std::to_string(width) + "x" + std::to_string(height) +
               ", over the texture limit (sides up to " + std::to_string(limits::kMaxTextureSide) +
               ", " + std::to_string(limits::kMaxTexturePixels) + " pixels)";
    const uint64_t rgba8Bytes = 4 * pixels;
    if (budget.decodedBytes + rgba8Bytes > limits::kMaxTextureBytes)
        return "would take the scene's decoded textures past " +
               std::to_string(limits::kMaxTextureBytes) + " bytes";
    budget.decodedBytes += rgba8Bytes;
    return "";
}

// tinygltf calls this for every image it could read from a file or data URI. Decoding failures
// are recorded instead of failing the whole load: an undecodable texture is only a warning.
bool decodeImage(tinygltf::Image* image, int imageIndex, std::string*, std::string*, int width,
                 int height, const unsigned char* bytes, int size, void* budgetPointer) {
    // Images stored in bufferViews reach here before anything checked that the bufferView lies
    // inside its buffer; GltfConverter::readImages decodes them once it has.
    if (image->bufferView >= 0)
        return true;
    ImageBudget& budget = *static_cast<ImageBudget*>(budgetPointer);
    std::string problem = admitImage(bytes, size, budget);
    std::string error;
    if (problem.empty() && !tinygltf::LoadImageData(image, imageIndex, &error, nullptr, width,
                                                    height, bytes, size, nullptr))
        problem = "could not be decoded";
    if (!problem.empty())
        budget.problems[imageIndex] = problem;
    return true;
}

// tinygltf looks for external files beside the model and then in the working directory; the
// latter would silently pick up an unrelated file of the same name, so it is refused. Paths
// searched in the working directory are the ones tinygltf builds as "./" + uri. Only regular
// files exist for us: tinygltf's own test (fopen) accepts a folder, whose size then reads as
// 2^63 - 1 bytes.
bool fileExistsBesideModel(const std::string& path, void*) {
    std::error_code error;
    return path.rfind("./", 0) != 0 && fs::is_regular_file(path, error);
}

// tinygltf's ReadWholeFile, with the size checked against limits::kMaxFileBytes before the
// buffer is allocated.
bool readWholeFileWithinLimit(std::vector<unsigned char>* out, std::string* error,
                              const std::string& path, void*) {
    std::error_code code;
    const uintmax_t size = fs::is_regular_file(path, code) ? fs::file_size(path, code) : 0;
    if (code || !fs::is_regular_file(path, code)) {
        *error += "'" + path + "' is not a readable regular file\n";
        return false;
    }
    if (size > limits::kMaxFileBytes) {
        *error += "'" + path + "' has " + str(size) + " bytes, more than the limit of " +
                  str(limits::kMaxFileBytes) + "\n";
        return false;
    }
    out->resize(size);
    std::ifstream in(path, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size))) {
        *error += "'" + path + "' cannot be read\n";
        return false;
    }
    return true;
}

// The nesting bound (limits::kMaxNestingDepth) on the JSON text tinygltf is about to parse.
void checkJsonNesting(const fs::path& path, std::string_view json) {
    NestingViolation violation;
    if (jsonNestsDeeperThan(json, limits::kMaxNestingDepth, &violation))
        fail(path, "JSON nests deeper than " + std::to_string(limits::kMaxNestingDepth) +
                       " levels (line " + str(violation.line) + ")");
}

tinygltf::Model parseModel(const fs::path& path, ImageBudget& imageBudget) {
    std::vector<unsigned char> bytes = readFile(path);
    tinygltf::TinyGLTF parser;
    parser.SetImageLoader(decodeImage, &imageBudget);
    parser.SetFsCallbacks({fileExistsBesideModel, tinygltf::ExpandFilePath,
                           readWholeFileWithinLimit, tinygltf::WriteWholeFile, nullptr});
    // tinygltf wants an absolute base directory; its warnings are all about images, which
    // GltfConverter::readImages reports in its own words, so they are not kept.
    const std::string baseDir = fs::absolute(path).parent_path().string();
    tinygltf::Model model;
    std::string error, ignoredWarnings;
    bool loaded;
    if (isGlb(bytes)) {
        checkGlbLayout(path, bytes);
        uint32_t jsonBytes;
        std::memcpy(&jsonBytes, bytes.data() + 12, 4);
        checkJsonNesting(
            path, std::string_view(reinterpret_cast<const char*>(bytes.data()) + 20, jsonBytes));
        loaded = parser.LoadBinaryFromMemory(&model, &error, &ignoredWarnings, bytes.data(),
                                             unsigned(bytes.size()), baseDir);
    } else {
        if (path.extension() == ".glb")
            fail(path, "not a GLB file (it does not start with 'glTF')");
        checkJsonNesting(
            path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
        loaded = parser.LoadASCIIFromString(&model, &error, &ignoredWarnings,
                                            reinterpret_cast<const char*>(bytes.data()),
                                            unsigned(bytes.size()), baseDir);
    }
    if (!loaded)
        fail(path, error.empty() ? "tinygltf cannot parse the file" : oneLine(error));
    return model;
}

const char* modeName(int mode) {
    switch (mode) {
    case TINYGLTF_MODE_POINTS:
        return "POINTS";
    case TINYGLTF_MODE_LINE:
        return "LINES";
    case TINYGLTF_MODE_LINE_LOOP:
        return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP:
        return "LINE_STRIP";
    default:
        return "unknown";
    }
}

// Cross products have length twice the triangle's area, so summing them weights by area.
std::vector<glm::vec3> areaWeightedNormals(const Mesh& mesh) {
    std::vector<glm::vec3> normals(mesh.positions.size(), glm::vec3(0.0f));
    for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
        const uint32_t a = mesh.indices[i], b = mesh.indices[i + 1], c = mesh.indices[i + 2];
        const glm::vec3 faceNormal = glm::cross(mesh.positions[b] - mesh.positions[a],
                                                mesh.positions[c] - mesh.positions[a]);
        normals[a] += faceNormal;
        normals[b] += faceNormal;
        normals[c] += faceNormal;
    }
    for (glm::vec3& normal : normals) {
        // A vertex only on zero-area triangles (or on none) is never drawn: any unit vector does.
        const float length = glm::length(normal);
        normal = length > 0.0f ? normal / length : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    return normals;
}

// The glTF specification's rules for strips and fans keep every triangle counter-clockwise.
std::vector<uint32_t> triangleList(int mode, std::vector<uint32_t> v) {
    if (mode == TINYGLTF_MODE_TRIANGLES)
        return v;
    std::vector<uint32_t> list;
    for (size_t i = 0; i + 2 < v.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP)
            list.insert(list.end(), {v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]});
        else
            list.insert(list.end(), {v[i + 1], v[i + 2], v[0]});
    }
    return list;
}

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
    [[noreturn]] void fail(const std::string& what) const { scenes::fail(mPath, what); }
    void warn(const std::string& what);

    void checkExtensions() const;
    void checkSizes() const;
    void readImages();
    std::vector<int> parentOfEachNode() const;
    std::vector<int> rootNodes(const std::vector<int>& parentOf) const;
    void visitNode(int nodeIndex, const glm::mat4& worldFromParent, int depth);
    glm::mat4 parentFromNode(int nodeIndex) const;
    void considerCamera(int cameraIndex, const glm::mat4& worldFromCamera);
    void addCamera(int cameraIndex, const glm::mat4& worldFromCamera);
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
};

void GltfConverter::warn(const std::string& what) {
    const std::string warning = mPath.string() + ": " + what;
    if (!mWarned.insert(warning).second)
        return;
    std::cerr << "warning: " << warning << '\n';
    mScene.warnings.push_back(warning);
}

Scene GltfConverter::convert() {
    mScene.name = mPath.stem().string();
    checkExtensions();
    checkSizes();
    readImages();
    mOnPath.assign(mModel.nodes.size(), false);
    mMeshOf.resize(mModel.meshes.size());
    for (size_t m = 0; m < mModel.meshes.size(); ++m)
        mMeshOf[m].assign(mModel.meshes[m].primitives.size(), kNotConverted);
    mMaterialOf.assign(mModel.materials.size(), -1);

    for (int root : rootNodes(parentOfEachNode()))
        visitNode(root, glm::mat4(1.0f), 0);
    if (mScene.triangleCount() == 0)
        fail("the scene has no triangles to draw");

    addLights();
    for (const auto& [cameraIndex, worldFromCamera] : mPlacedCameras)
        addCamera(cameraIndex, worldFromCamera);
    if (mScene.cameras.empty()) {
        // No camera of its own: the framing camera, then three orbit views of the same bounds
        // (taken before any camera is added: Scene::boundsWorld includes camera positions).
        const Aabb geometryBounds = mScene.boundsWorld();
        mScene.cameras.push_back(cameraFramingBounds(geometryBounds));
        for (const Camera& view : orbitViews(mScene.cameras.front(), geometryBounds))
            mScene.cameras.push_back(view);
    }
    makeViewNamesUnique(mScene.cameras);
    try {
        validate(mScene);
    } catch (const SceneError& error) {
        fail(error.what());
    }
    return std::move(mScene);
}

// A required extension we do not implement would be silently misdrawn (e.g. compressed
// geometry that has no plain accessors), so it is an error.
void GltfConverter::checkExtensions() const {
    for (const std::string& extension : mModel.extensionsRequired)
        if (!kImplementedExtensions.count(extension))
            fail("requires the unsupported extension " + extension);
}

// The vertices the converted primitives will store and the triangles their instances will draw,
// from the accessors' declared counts, before any accessor is read (limits::kMaxVertices,
// kMaxTriangles): primitives may share one large accessor, so a small file can ask for far more
// than its buffers hold. A mesh counts once per node that uses it, reachable from the scene or
// not, which can only over-estimate. Sums are in double: the counts are the file's and may be
// absurd.
void GltfConverter::checkSizes() const {
    std::vector<double> uses(mModel.meshes.size(), 0.0);
    for (const tinygltf::Node& node : mModel.nodes)
        if (node.mesh >= 0 && size_t(node.mesh) < uses.size())
            uses[size_t(node.mesh)] += 1.0;
    auto countOf = [&](int accessor) {
        return accessor >= 0 && size_t(accessor) < mModel.accessors.size()
                   ? double(mModel.accessors[size_t(accessor)].count)
                   : 0.0;
    };
    double vertices = 0.0, triangles = 0.0;
    for (size_t m = 0; m < mModel.meshes.size(); ++m) {
        if (uses[m] == 0.0)
            continue;
        for (const tinygltf::Primitive& primitive : mModel.meshes[m].primitives) {
            const int mode = primitive.mode;
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                mode != TINYGLTF_MODE_TRIANGLE_FAN)
                continue;
            const auto position = primitive.attributes.find("POSITION");
            const double vertexCount =
                position == primitive.attributes.end() ? 0.0 : countOf(position->second);
            const double indexCount =
                primitive.indices >= 0 ? countOf(primitive.indices) : vertexCount;
            vertices += vertexCount;
            triangles +=
                uses[m] * (mode == TINYGLTF_MODE_TRIANGLES ? std::floor(indexCount / 3.0)
                                                           : std::max(indexCount - 2.0, 0.0));
        }
    }
    auto gib = [](double bytes) {
        char text[32];
        std::snprintf(text, sizeof text, "%.1f", bytes / double(uint64_t(1) << 30));
        return std::string(text);
    };
    if (vertices > double(limits::kMaxVertices))
        fail("the meshes would store " + std::to_string(uint64_t(std::min(vertices, 1e19))) +
             " vertices (about " + gib(vertices * double(limits::kBytesPerVertex)) +
             " GiB), over the limit of " + str(limits::kMaxVertices));
    if (triangles > double(limits::kMaxTriangles))
        fail("the instances would draw " + std::to_string(uint64_t(std::min(triangles, 1e19))) +
             " triangles (about " + gib(triangles * double(limits::kBytesPerDrawnTriangle)) +
             " GiB per frame), over the limit of " + str(limits::kMaxTriangles));
}

// Images tinygltf could not read (missing file, undecodable data) get one warning each, whether
// or not a material slot we map uses them: the user should know the file is incomplete.
void GltfConverter::readImages() {
    for (size_t i = 0; i < mModel.images.size(); ++i) {
        tinygltf::Image& image = mModel.images[i];
        const std::string label = !image.uri.empty() ? image.uri : image.name;
        const std::string name = "image " + str(i) + (label.empty() ? "" : " '" + label + "'");
        std::string problem;
        if (image.bufferView >= 0) {
            if (size_t(image.bufferView) >= mModel.bufferViews.size())
                fail(name + ": bufferView " + std::to_string(image.bufferView) + " out of range");
            const tinygltf::BufferView& view = mModel.bufferViews[size_t(image.bufferView)];
            if (view.buffer < 0 || size_t(view.buffer) >= mModel.buffers.size())
                fail(name + ": buffer " + std::to_string(view.buffer) + " out of range");
            const std::vector<unsigned char>& data = mModel.buffers[size_t(view.buffer)].data;
            if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset ||
                view.byteLength > size_t(std::numeric_limits<int>::max()))
                fail(name + ": bufferView " + std::to_string(image.bufferView) +
                     " runs past the end of its buffer");
            const unsigned char* bytes = data.data() + view.byteOffset;
            problem = admitImage(bytes, int(view.byteLength), mImageBudget);
            std::string error;
            if (problem.empty() && !tinygltf::LoadImageData(&image, int(i), &error, nullptr, 0, 0,
                                                            bytes, int(view.byteLength), nullptr))
                problem = "could not be decoded";
        } else if (const auto found = mImageBudget.problems.find(int(i));
                   found != mImageBudget.problems.end()) {
            problem = found->second;
        } else if (image.image.empty()) {
            std::error_code error;
            const fs::path file = mPath.parent_path() / image.uri;
            problem = fs::is_regular_file(file, error) ? "could not be read"
                      : fs::exists(file, error)        ? "is not a regular file"
                                                       : "file not found";
        }
        const bool layoutKnown = image.width > 0 && image.height > 0 && image.component >= 1 &&
                                 image.component <= 4 && (image.bits == 8 || image.bits == 16);
        if (problem.empty() &&
            (!layoutKnown || image.image.size() != size_t(image.width) * size_t(image.height) *
                                                       size_t(image.component) *
                                                       size_t(image.bits / 8)))
            problem = "has an unsupported pixel layout";
        if (!problem.empty()) {
            image.image.clear();
            warn(name + " " + problem + "; materials using it fall back to their factors");
        }
    }
}

// Every node has at most one parent (glTF nodes form strict trees). Checking it up front also
// bounds the walk: a node shared by two parents at every level would be visited 2^depth times.
std::vector<int> GltfConverter::parentOfEachNode() const {
    std::vector<int> parentOf(mModel.nodes.size(), -1);
    for (size_t n = 0; n < mModel.nodes.size(); ++n) {
        for (int child : mModel.nodes[n].children) {
            if (child < 0 || size_t(child) >= mModel.nodes.size())
                fail("node " + str(n) + ": child " + std::to_string(child) + " out of range");
            if (parentOf[size_t(child)] >= 0)
                fail("node " + str(size_t(child)) + " is a child of more than one node (nodes " +
                     str(size_t(parentOf[size_t(child)])) + " and " + str(n) + ")");
            parentOf[size_t(child)] = int(n);
        }
    }
    return parentOf;
}

std::vector<int> GltfConverter::rootNodes(const std::vector<int>& parentOf) const {
    int sceneIndex = mModel.defaultScene;
    if (sceneIndex < 0 && !mModel.scenes.empty())
        sceneIndex = 0;
    if (sceneIndex >= int(mModel.scenes.size()))
        fail("default scene " + std::to_string(sceneIndex) + " out of range");
    if (sceneIndex >= 0)
        return mModel.scenes[size_t(sceneIndex)].nodes;
    std::vector<int> roots;
    for (size_t n = 0; n < parentOf.size(); ++n)
        if (parentOf[n] < 0)
            roots.push_back(int(n));
    return roots;
}

void GltfConverter::visitNode(int nodeIndex, const glm::mat4& worldFromParent, int depth) {
    if (nodeIndex < 0 || size_t(nodeIndex) >= mModel.nodes.size())
        fail("scene node " + std::to_string(nodeIndex) + " out of range");
    if (mOnPath[size_t(nodeIndex)])
        fail("node " + std::to_string(nodeIndex) + " is its own ancestor (cyclic node graph)");
    if (depth > kMaxNodeDepth)
        fail("node hierarchy deeper than " + std::to_string(kMaxNodeDepth) + " levels");
    mOnPath[size_t(nodeIndex)] = true;

    const tinygltf::Node& node = mModel.nodes[size_t(nodeIndex)];
    const glm::mat4 worldFromNode = worldFromParent * parentFromNode(nodeIndex);
    if (node.mesh >= int(mModel.meshes.size()))
        fail("node " + std::to_string(nodeIndex) + ": mesh " + std::to_string(node.mesh) +
             " out of range");
    if (node.mesh >= 0) {
        for (size_t p = 0; p < mModel.meshes[size_t(node.mesh)].primitives.size(); ++p) {
            const int mesh = meshFor(node.mesh, p);
            if (mesh >= 0)
                mScene.instances.push_back({uint32_t(mesh), worldFromNode});
        }
    }
    if (node.camera >= int(mModel.cameras.size()))
        fail("node " + std::to_string(nodeIndex) + ": camera " + std::to_string(node.camera) +
             " out of range");
    if (node.camera >= 0)
        considerCamera(node.camera, worldFromNode);

    const auto lightExtension = node.extensions.find("KHR_lights_punctual");
    if (lightExtension != node.extensions.end()) {
        const tinygltf::Value& value = lightExtension->second;
        if (!value.IsObject() || !value.Get("light").IsInt())
            fail("node " + std::to_string(nodeIndex) + ": KHR_lights_punctual needs a light index");
        mPlacedLights.emplace_back(value.Get("light").Get<int>(), worldFromNode);
    }

    for (int child : node.children)
        visitNode(child, worldFromNode, depth + 1);
    mOnPath[size_t(nodeIndex)] = false;
}

glm::mat4 GltfConverter::parentFromNode(int nodeIndex) const {
    const tinygltf::Node& node = mModel.nodes[size_t(nodeIndex)];
    const std::string where = "node " + std::to_string(nodeIndex);
    auto finite = [](const std::vector<double>& values) {
        return std::all_of(values.begin(), values.end(), [](double x) { return std::isfinite(x); });
    };
    if (!finite(node.matrix) || !finite(node.translation) || !finite(node.rotation) ||
        !finite(node.scale))
        fail(where + ": transform is not finite");
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16)
            fail(where + ": matrix needs 16 numbers");
        glm::dmat4 matrix;
        std::copy(node.matrix.begin(), node.matrix.end(), glm::value_ptr(matrix));
        return glm::mat4(matrix);
    }
    glm::mat4 transform(1.0f);
    if (!node.translation.empty()) {
        if (node.translation.size() != 3)
            fail(where + ": translation needs 3 numbers");
        transform = glm::translate(
            transform, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
    }
    if (!node.rotation.empty()) {
        if (node.rotation.size() != 4)
            fail(where + ": rotation needs 4 numbers");
        // glTF stores quaternions as (x, y, z, w); glm's constructor takes w first. Exporters
        // write them to a few digits, so they are renormalised rather than required to be unit.
        const glm::quat rotation(float(node.rotation[3]), float(node.rotation[0]),
                                 float(node.rotation[1]), float(node.rotation[2]));
        if (!(glm::length(rotation) > 0.0f))
            fail(where + ": rotation is a zero quaternion");
        transform *= glm::mat4_cast(glm::normalize(rotation));
    }
    if (!node.scale.empty()) {
        if (node.scale.size() != 3)
            fail(where + ": scale needs 3 numbers");
        transform = glm::scale(transform, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
    }
    return transform;
}

// Every perspective camera met in the walk is kept, in walk order (the first is the default view);
// a camera node instanced twice gives two views. They are placed after the walk, when the bounds
// that an infinite far plane must reach are known.
void GltfConverter::considerCamera(int cameraIndex, const glm::mat4& worldFromCamera) {
    const tinygltf::Camera& source = mModel.cameras[size_t(cameraIndex)];
    if (source.type != "perspective")
        warn("camera " + std::to_string(cameraIndex) + " is " + source.type +
             "; only perspective cameras are used");
    else
        mPlacedCameras.emplace_back(cameraIndex, worldFromCamera);
}

void GltfConverter::addCamera(int cameraIndex, const glm::mat4& worldFromCamera) {
    const tinygltf::Camera& source = mModel.cameras[size_t(cameraIndex)];
    const tinygltf::PerspectiveCamera& lens = source.perspective;
    Camera camera;
    camera.name = source.name.empty() ? "camera " + std::to_string(cameraIndex) : source.name;
    const glm::mat3 linear(worldFromCamera);
    camera.positionWorld = glm::vec3(worldFromCamera[3]);
    camera.forwardWorld = glm::normalize(linear * glm::vec3(0.0f, 0.0f, -1.0f));
    camera.upWorld = glm::normalize(linear * glm::vec3(0.0f, 1.0f, 0.0f));
    camera.verticalFovRadians = float(lens.yfov);
    camera.nearMetres = float(lens.znear);
    // zfar absent (0) means infinite; see kInfiniteFarOverNear. The far plane also reaches past
    // the farthest point of the model so that nothing of it is clipped.
    float farMetres = float(lens.zfar);
    if (!(farMetres > 0.0f)) {
        const Aabb bounds = mScene.boundsWorld();
        const glm::vec3 farthestCorner = glm::max(glm::abs(bounds.min - camera.positionWorld),
                                                  glm::abs(bounds.max - camera.positionWorld));
        farMetres =
            std::max(kInfiniteFarOverNear * camera.nearMetres, 2.0f * glm::length(farthestCorner));
    }
    camera.farMetres = farMetres;
    mScene.cameras.push_back(camera);
}

// KHR_lights_punctual lights, placed once the geometry is known: a light without a range is
// unbounded in glTF, but ours need finite support, so it reaches just past the farthest corner
// of the model's bounds (the windowed falloff makes it slightly dimmer there than glTF's).
// Intensities are taken as they are (candela or lux in glTF, unitless here).
// What KHR_lights_punctual allows is checked here, with one error each: intensity and colour
// finite and non-negative, range positive and finite when given (tinygltf reads an absent range
// as 0, so 0 cannot be told from absent and means "no range"), and spot cones with
// 0 <= innerConeAngle < outerConeAngle <= pi/2 (radians), as the extension's specification says.
void GltfConverter::addLights() {
    if (mPlacedLights.size() > size_t(limits::kMaxLights))
        fail(str(mPlacedLights.size()) + " placed lights, over the limit of " +
             std::to_string(limits::kMaxLights));
    const Aabb bounds = mScene.boundsWorld();
    for (const auto& [lightIndex, worldFromLight] : mPlacedLights) {
        if (lightIndex < 0 || size_t(lightIndex) >= mModel.lights.size())
            fail("KHR_lights_punctual light " + std::to_string(lightIndex) + " out of range");
        const tinygltf::Light& source = mModel.lights[size_t(lightIndex)];
        const std::string where = "KHR_lights_punctual light " + std::to_string(lightIndex);
        Light light;
        if (source.type == "point")
            light.type = LightType::Point;
        else if (source.type == "spot")
            light.type = LightType::Spot;
        else if (source.type == "directional")
            light.type = LightType::Directional;
        else
            fail(where + ": unknown type '" + source.type + "'");
        auto finiteNonNegative = [](double x) { return std::isfinite(x) && x >= 0.0; };
        if (!source.color.empty()) {
            if (source.color.size() != 3 ||
                !std::all_of(source.color.begin(), source.color.end(), finiteNonNegative))
                fail(where + ": color needs 3 finite numbers >= 0");
            light.color = glm::vec3(source.color[0], source.color[1], source.color[2]);
        }
        if (!finiteNonNegative(source.intensity))
            fail(where + ": intensity must be a finite number >= 0");
        if (!finiteNonNegative(source.range))
            fail(where + ": range must be a finite number > 0 (or absent)");
        if (light.type == LightType::Spot) {
            const double inner = source.spot.innerConeAngle, outer = source.spot.outerConeAngle;
            if (!(inner >= 0.0 && inner < outer && outer <= 0.5 * std::numbers::pi))
                fail(where + ": spot cone angles must satisfy 0 <= innerConeAngle < " +
                     "outerConeAngle <= pi/2 (radians), got " + std::to_string(inner) + " and " +
                     std::to_string(outer));
        }
        light.intensity = float(source.intensity);
        light.positionWorld = glm::vec3(worldFromLight[3]);
        light.directionWorld =
            glm::normalize(glm::mat3(worldFromLight) * glm::vec3(0.0f, 0.0f, -1.0f));
        const glm::vec3 farthestCorner = glm::max(glm::abs(bounds.min - light.positionWorld),
                                                  glm::abs(bounds.max - light.positionWorld));
        light.rangeMetres =
            source.range > 0.0 ? float(source.range) : 1.01f * glm::length(farthestCorner);
        light.spotInnerCos = float(std::cos(source.spot.innerConeAngle));
        light.spotOuterCos = float(std::cos(source.spot.outerConeAngle));
        mScene.lights.push_back(light);
    }
}

int GltfConverter::meshFor(int meshIndex, size_t primitiveIndex) {
    int& converted = mMeshOf[size_t(meshIndex)][primitiveIndex];
    if (converted != kNotConverted)
        return converted;
    const int mode = mModel.meshes[size_t(meshIndex)].primitives[primitiveIndex].mode;
    if (mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
        mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        Mesh mesh = convertPrimitive(meshIndex, primitiveIndex);
        converted = int(mScene.meshes.size());
        mScene.meshes.push_back(std::move(mesh));
    } else {
        warn("mesh " + std::to_string(meshIndex) + " primitive " + str(primitiveIndex) + ": mode " +
             modeName(mode) + " skipped (only triangles are drawn)");
        converted = kSkipped;
    }
    return converted;
}

Mesh GltfConverter::convertPrimitive(int meshIndex, size_t primitiveIndex) {
    const tinygltf::Mesh& source = mModel.meshes[size_t(meshIndex)];
    const tinygltf::Primitive& primitive = source.primitives[primitiveIndex];
    const std::string where =
        "mesh " + std::to_string(meshIndex) + " primitive " + str(primitiveIndex);
    auto attribute = [&](const char* name) {
        const auto found = primitive.attributes.find(name);
        return found == primitive.attributes.end() ? -1 : found->second;
    };

    Mesh mesh;
    mesh.name = source.name.empty() ? "mesh " + std::to_string(meshIndex) : source.name;
    if (source.primitives.size() > 1)
        mesh.name += " #" + str(primitiveIndex);
    if (attribute("POSITION") < 0)
        fail(where + ": no POSITION attribute");
    mesh.positions = readVectors<3>(attribute("POSITION"), where + " POSITION");
    const size_t vertexCount = mesh.positions.size();
    if (vertexCount > std::numeric_limits<uint32_t>::max())
        fail(where + ": more than 2^32 vertices");
    auto readAttribute = [&](auto& into, const char* name, auto reader) {
        if (attribute(name) < 0)
            return;
        into = reader(attribute(name), where + " " + name);
        if (into.size() != vertexCount)
            fail(where + ": " + str(into.size()) + " " + name + " values for " + str(vertexCount) +
                 " positions");
    };
    readAttribute(mesh.normals, "NORMAL",
                  [&](int a, const std::string& w) { return readVectors<3>(a, w); });
    readAttribute(mesh.tangents, "TANGENT",
                  [&](int a, const std::string& w) { return readVectors<4>(a, w); });
    readAttribute(mesh.uvs, "TEXCOORD_0",
                  [&](int a, const std::string& w) { return readVectors<2>(a, w, true); });
    mesh.material = materialFor(primitive.material);
    const Material& material = mScene.materials[mesh.material];
    if (material.usesSecondUvSet())
        readAttribute(mesh.uvs1, "TEXCOORD_1",
                      [&](int a, const std::string& w) { return readVectors<2>(a, w, true); });

    std::vector<uint32_t> vertices;
    if (primitive.indices >= 0) {
        vertices = readIndices(primitive.indices, where + " indices", vertexCount);
    } else {
        vertices.resize(vertexCount);
        std::iota(vertices.begin(), vertices.end(), 0u);
    }
    if (primitive.mode == TINYGLTF_MODE_TRIANGLES && vertices.size() % 3 != 0)
        fail(where + ": " + str(vertices.size()) + " vertices do not make whole triangles");
    mesh.indices = triangleList(primitive.mode, std::move(vertices));

    if (mesh.normals.empty()) {
        mesh.normals = areaWeightedNormals(mesh);
    } else {
        // Zero-length normals occur in exported files; the geometry tells what they should be.
        std::vector<glm::vec3> computed;
        for (size_t v = 0; v < vertexCount; ++v) {
            const float length = glm::length(mesh.normals[v]);
            if (length > 0.0f) {
                mesh.normals[v] /= length;
                continue;
            }
            if (computed.empty())
                computed = areaWeightedNormals(mesh);
            mesh.normals[v] = computed[v];
        }
    }
    // Tangents matter only under a normal map; glTF wants them generated from the uvs the normal
    // texture reads. Without those uvs there is no tangent frame to speak of.
    const std::vector<glm::vec2>& normalUvs =
        material.normalMapping.texCoord == 1 ? mesh.uvs1 : mesh.uvs;
    if (mesh.tangents.empty() && material.normalTexture >= 0 && !normalUvs.empty())
        mesh.tangents = generateTangents(mesh.positions, mesh.normals, normalUvs, mesh.indices);
    return mesh;
}

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
    Material material;
    material.name = source.name.empty() ? where : source.name;
    material.model = MaterialModel::MetallicRoughness;
    if (pbr.baseColorFactor.size() != 4)
        fail(where + ": baseColorFactor needs 4 numbers");
    material.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                         pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
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

    if (!std::isfinite(source.normalTexture.scale))
        fail(where + ": normalTexture.scale is not finite");
    material.normalScale = float(source.normalTexture.scale);
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
            material.emissiveStrength = float(number.GetNumberAsDouble());
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
    material.alphaCutoff = float(source.alphaCutoff);
    material.doubleSided = source.doubleSided;

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
            return float(v.GetNumberAsDouble());
        };
        auto pair = [&](const std::string& field, glm::vec2& into) {
            if (!value.Has(field))
                return;
            const tinygltf::Value& array = value.Get(field);
            if (!array.IsArray() || array.ArrayLen() != 2)
                fail(where + ": KHR_texture_transform." + field + " needs 2 numbers");
            into = glm::vec2(number(array.Get(0), field), number(array.Get(1), field));
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

const tinygltf::Accessor& GltfConverter::accessorAt(int accessorIndex,
                                                    const std::string& what) const {
    if (accessorIndex < 0 || size_t(accessorIndex) >= mModel.accessors.size())
        fail(what + ": accessor " + std::to_string(accessorIndex) + " out of range");
    return mModel.accessors[size_t(accessorIndex)];
}

AccessorData GltfConverter::accessorData(const tinygltf::Accessor& accessor,
                                         const std::string& where) const {
    if (accessor.sparse.isSparse)
        fail(where + ": sparse accessors are not supported");
    if (accessor.bufferView < 0)
        fail(where + ": no bufferView (zero-filled accessors are not supported)");
    if (size_t(accessor.bufferView) >= mModel.bufferViews.size())
        fail(where + ": bufferView " + std::to_string(accessor.bufferView) + " out of range");
    const tinygltf::BufferView& view = mModel.bufferViews[size_t(accessor.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= mModel.buffers.size())
        fail(where + ": buffer " + std::to_string(view.buffer) + " out of range");
    const std::vector<unsigned char>& buffer = mModel.buffers[size_t(view.buffer)].data;
    if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
        fail(where + ": bufferView " + std::to_string(accessor.bufferView) + " (" +
             str(view.byteLength) + " bytes from byte " + str(view.byteOffset) +
             ") runs past the end of buffer " + std::to_string(view.buffer) + " (" +
             str(buffer.size()) + " bytes)");

    const int componentBytes = tinygltf::GetComponentSizeInBytes(uint32_t(accessor.componentType));
    const int components = tinygltf::GetNumComponentsInType(uint32_t(accessor.type));
    if (componentBytes <= 0 || components <= 0)
        fail(where + ": invalid componentType or type");
    const size_t elementBytes = size_t(componentBytes) * size_t(components);
    const size_t strideBytes = view.byteStride == 0 ? elementBytes : view.byteStride;
    if (strideBytes < elementBytes)
        fail(where + ": byteStride " + str(strideBytes) + " is smaller than an element (" +
             str(elementBytes) + " bytes)");
    if (accessor.count == 0)
        fail(where + ": count is 0");
    // Written with a division so that no product can overflow, whatever the file claims.
    const size_t available =
        accessor.byteOffset <= view.byteLength ? view.byteLength - accessor.byteOffset : 0;
    if (elementBytes > available || (accessor.count - 1) > (available - elementBytes) / strideBytes)
        fail(where + ": " + str(accessor.count) + " elements of " + str(elementBytes) +
             " bytes every " + str(strideBytes) + " bytes from byte " + str(accessor.byteOffset) +
             " run past the end of bufferView " + std::to_string(accessor.bufferView) + " (" +
             str(view.byteLength) + " bytes)");
    return {buffer.data() + view.byteOffset + accessor.byteOffset, strideBytes, accessor.count};
}

// Float vectors of N components; with allowNormalizedIntegers also normalized unsigned bytes and
// shorts (as glTF allows for texture coordinates). Every value must be finite.
template <int N>
std::vector<glm::vec<N, float>> GltfConverter::readVectors(int accessorIndex,
                                                           const std::string& what,
                                                           bool allowNormalizedIntegers) const {
    const tinygltf::Accessor& accessor = accessorAt(accessorIndex, what);
    const std::string where = what + " (accessor " + std::to_string(accessorIndex) + ")";
    constexpr int kType = N == 2   ? TINYGLTF_TYPE_VEC2
                          : N == 3 ? TINYGLTF_TYPE_VEC3
                                   : TINYGLTF_TYPE_VEC4;
    const int componentType = accessor.componentType;
    const bool normalizedInteger = allowNormalizedIntegers && accessor.normalized &&
                                   (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                    componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (accessor.type != kType ||
        (componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !normalizedInteger))
        fail(where + ": expected VEC" + std::to_string(N) + " of FLOAT" +
             (allowNormalizedIntegers ? " or normalized UNSIGNED_BYTE/UNSIGNED_SHORT" : ""));

    const AccessorData data = accessorData(accessor, where);
    std::vector<glm::vec<N, float>> values(data.count);
    for (size_t i = 0; i < data.count; ++i) {
        const unsigned char* element = data.first + i * data.strideBytes;
        for (int c = 0; c < N; ++c) {
            float value;
            if (componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
                std::memcpy(&value, element + 4 * c, 4);
            } else if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
                value = float(element[c]) / 255.0f;
            } else {
                uint16_t integer;
                std::memcpy(&integer, element + 2 * c, 2);
                value = float(integer) / 65535.0f;
            }
            if (!std::isfinite(value))
                fail(where + ": element " + str(i) + " is NaN or infinite");
            values[i][c] = value;
        }
    }
    return values;
}

std::vector<uint32_t> GltfConverter::readIndices(int accessorIndex, const std::string& what,
                                                 size_t vertexCount) const {
    const tinygltf::Accessor& accessor = accessorAt(accessorIndex, what);
    const std::string where = what + " (accessor " + std::to_string(accessorIndex) + ")";
    const int componentType = accessor.componentType;
    if (accessor.type != TINYGLTF_TYPE_SCALAR ||
        (componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
         componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
         componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(where + ": expected SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");

    const AccessorData data = accessorData(accessor, where);
    std::vector<uint32_t> indices(data.count);
    for (size_t i = 0; i < data.count; ++i) {
        const unsigned char* element = data.first + i * data.strideBytes;
        uint32_t index = 0;
        if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
            index = element[0];
        } else if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            uint16_t value;
            std::memcpy(&value, element, 2);
            index = value;
        } else {
            std::memcpy(&index, element, 4);
        }
        if (index >= vertexCount)
            fail(where + ": index " + std::to_string(index) + " (element " + str(i) +
                 ") out of range of " + str(vertexCount) + " vertices");
        indices[i] = index;
    }
    return indices;
}

} // namespace

Scene loadGltf(const fs::path& path) {
    try {
        ImageBudget imageBudget;
        tinygltf::Model model = parseModel(path, imageBudget);
        return GltfConverter(path, std::move(model), std::move(imageBudget)).convert();
    } catch (const SceneError&) {
        throw;
    } catch (const std::exception& error) {
        // tinygltf and its JSON parser may throw (bad_alloc, out_of_range on odd input).
        fail(path, error.what());
    }
}

} // namespace scenes
