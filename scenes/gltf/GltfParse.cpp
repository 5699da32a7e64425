#include "scenes/gltf/GltfConverter.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
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

#include "scenes/Viewpoints.h"
#include "scenes/input/DuplicateKeys.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/input/WholeFile.h"
#include "scenes/mesh/Tangents.h"

namespace scenes::gltf {

namespace {

std::vector<unsigned char> readFile(const fs::path& path) {
    std::vector<unsigned char> bytes;
    if (const std::string problem = readWholeFile(path, &bytes); !problem.empty())
        fail(path, problem);
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

// tinygltf's ReadWholeFile (external buffers and images), through the same checked read as the
// model itself: a regular file within limits::kMaxFileBytes, checked before allocating.
bool readWholeFileWithinLimit(std::vector<unsigned char>* out, std::string* error,
                              const std::string& path, void*) {
    if (const std::string problem = readWholeFile(path, out); !problem.empty()) {
        *error += "'" + path + "' " + problem + "\n";
        return false;
    }
    return true;
}

// The checks every JSON reader makes on the text tinygltf is about to parse: the nesting bound
// (limits::kMaxNestingDepth) and no key twice in an object (tinygltf would keep the last).
void checkJsonText(const fs::path& path, std::string_view json) {
    NestingViolation violation;
    if (jsonNestsDeeperThan(json, limits::kMaxNestingDepth, &violation))
        fail(path, "JSON nests deeper than " + std::to_string(limits::kMaxNestingDepth) +
                       " levels (line " + str(violation.line) + ")");
    if (const std::string problem = jsonDuplicateKeyProblem(json); !problem.empty())
        fail(path, problem);
}

} // namespace

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
        checkJsonText(
            path, std::string_view(reinterpret_cast<const char*>(bytes.data()) + 20, jsonBytes));
        loaded = parser.LoadBinaryFromMemory(&model, &error, &ignoredWarnings, bytes.data(),
                                             unsigned(bytes.size()), baseDir);
    } else {
        if (path.extension() == ".glb")
            fail(path, "not a GLB file (it does not start with 'glTF')");
        checkJsonText(path,
                      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
        loaded = parser.LoadASCIIFromString(&model, &error, &ignoredWarnings,
                                            reinterpret_cast<const char*>(bytes.data()),
                                            unsigned(bytes.size()), baseDir);
    }
    if (!loaded)
        fail(path, error.empty() ? "tinygltf cannot parse the file" : oneLine(error));
    return model;
}

} // namespace scenes::gltf
