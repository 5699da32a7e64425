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
// Limits (scenes/input/Limits.h) are checked before the memory they bound is allocated: the JSON's
// nesting before tinygltf parses it (tinygltf converts JSON recursively), every file's size
// before it is read (external buffers and images must be regular files), an image's declared
// size before it is decoded, and the vertices and drawn triangles every primitive would add
// before any is converted.
// Thread safety: each call owns its tinygltf instance; calls may run concurrently.
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
#include "scenes/input/FloatRange.h"
#include "scenes/input/Limits.h"
#include "scenes/input/MessageText.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/mesh/Tangents.h"

namespace scenes::gltf {

namespace {

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

} // namespace

float GltfConverter::narrow(double value, const std::string& field) const {
    if (const std::string problem = floatRangeProblem(value); !problem.empty())
        fail(field + ": " + problem);
    return float(value);
}

void GltfConverter::warn(const std::string& what) {
    const std::string warning = mPath.string() + ": " + what;
    if (!mWarned.insert(warning).second)
        return;
    std::cerr << "warning: " << escapeControlCharacters(warning) << '\n';
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
    // Each node's transform is finite in float (parentFromNode); their product may not be.
    const std::string nodeField = "nodes[" + std::to_string(nodeIndex) + "]";
    check(transformProblem(worldFromNode), nodeField + " (composed with its ancestors)");
    if (node.mesh >= int(mModel.meshes.size()))
        fail("node " + std::to_string(nodeIndex) + ": mesh " + std::to_string(node.mesh) +
             " out of range");
    if (node.mesh >= 0) {
        for (size_t p = 0; p < mModel.meshes[size_t(node.mesh)].primitives.size(); ++p) {
            const int mesh = meshFor(node.mesh, p);
            if (mesh < 0)
                continue;
            auto bounds = mBoundsOfMesh.find(mesh);
            if (bounds == mBoundsOfMesh.end())
                bounds = mBoundsOfMesh.emplace(mesh, boundsOf(mScene.meshes[size_t(mesh)])).first;
            check(placedBoundsProblem(bounds->second, worldFromNode),
                  nodeField + " (composed with its ancestors), mesh " + std::to_string(node.mesh) +
                      " primitive " + str(p));
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
    const std::string field = "nodes[" + std::to_string(nodeIndex) + "].";
    // Every number as the float it is used as (narrow names the field: "nodes[2].scale[1]").
    auto floats = [&](const std::vector<double>& values, const char* name) {
        std::vector<float> narrowed;
        for (size_t i = 0; i < values.size(); ++i)
            narrowed.push_back(narrow(values[i], field + name + "[" + str(i) + "]"));
        return narrowed;
    };
    const std::vector<float> matrix = floats(node.matrix, "matrix");
    const std::vector<float> translation = floats(node.translation, "translation");
    const std::vector<float> rotationXyzw = floats(node.rotation, "rotation");
    const std::vector<float> scale = floats(node.scale, "scale");
    if (!matrix.empty()) {
        if (matrix.size() != 16)
            fail(where + ": matrix needs 16 numbers");
        glm::mat4 parentFromNode;
        std::copy(matrix.begin(), matrix.end(), glm::value_ptr(parentFromNode));
        return parentFromNode;
    }
    glm::mat4 transform(1.0f);
    if (!translation.empty()) {
        if (translation.size() != 3)
            fail(where + ": translation needs 3 numbers");
        transform =
            glm::translate(transform, glm::vec3(translation[0], translation[1], translation[2]));
    }
    if (!rotationXyzw.empty()) {
        if (rotationXyzw.size() != 4)
            fail(where + ": rotation needs 4 numbers");
        // glTF stores quaternions as (x, y, z, w); glm's constructor takes w first. Exporters
        // write them to a few digits, so they are renormalised rather than required to be unit.
        // A quaternion of huge components has an infinite float length: scaled down first.
        glm::vec4 xyzw(rotationXyzw[0], rotationXyzw[1], rotationXyzw[2], rotationXyzw[3]);
        const float largest = glm::max(glm::max(std::abs(xyzw.x), std::abs(xyzw.y)),
                                       glm::max(std::abs(xyzw.z), std::abs(xyzw.w)));
        if (largest > 0.0f)
            xyzw /= largest;
        const glm::quat rotation(xyzw.w, xyzw.x, xyzw.y, xyzw.z);
        if (!(glm::length(rotation) > 0.0f))
            fail(where + ": rotation is a zero quaternion");
        transform *= glm::mat4_cast(glm::normalize(rotation));
    }
    if (!scale.empty()) {
        if (scale.size() != 3)
            fail(where + ": scale needs 3 numbers");
        transform = glm::scale(transform, glm::vec3(scale[0], scale[1], scale[2]));
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
    const std::string field = "cameras[" + std::to_string(cameraIndex) + "]";
    Camera camera;
    camera.name = source.name.empty() ? "camera " + std::to_string(cameraIndex) : source.name;
    camera.positionWorld = glm::vec3(worldFromCamera[3]);
    setCameraBasis(camera, glm::mat3(worldFromCamera), field);
    camera.verticalFovRadians = narrow(lens.yfov, field + ".perspective.yfov");
    camera.nearMetres = narrow(lens.znear, field + ".perspective.znear");
    // zfar absent (0) means infinite; see kInfiniteFarOverNear. The far plane also reaches past
    // the farthest point of the model so that nothing of it is clipped.
    float farMetres = narrow(lens.zfar, field + ".perspective.zfar");
    if (!(farMetres > 0.0f)) {
        const Aabb bounds = mScene.boundsWorld();
        const glm::vec3 farthestCorner = glm::max(glm::abs(bounds.min - camera.positionWorld),
                                                  glm::abs(bounds.max - camera.positionWorld));
        farMetres =
            std::max(kInfiniteFarOverNear * camera.nearMetres, 2.0f * glm::length(farthestCorner));
    }
    camera.farMetres = farMetres;
    check(cameraProblem(camera), field + " ('" + camera.name + "')");
    mScene.cameras.push_back(camera);
}

// The camera looks down its node's -Z with +Y up (glTF). A transform that flattens -Z leaves no
// viewing direction: an error. One that flattens +Y (a zero scale, or a shear onto the view
// axis) leaves the view defined but not the image's vertical: up is then taken from +X (up =
// X x forward), as a camera rolled by the transform's X axis would have it, with a warning.
// Otherwise up is +Y made perpendicular to the view (Gram-Schmidt; what lookAt does anyway).
void GltfConverter::setCameraBasis(Camera& camera, const glm::mat3& worldFromCamera,
                                   const std::string& field) {
    const glm::vec3 forward = worldFromCamera * glm::vec3(0.0f, 0.0f, -1.0f);
    const float forwardLength = glm::length(forward);
    if (!(forwardLength > 0.0f) || !std::isfinite(forwardLength))
        fail(field + ": the world transform of its node flattens the camera's viewing axis (-Z), "
                     "so it has no viewing direction");
    camera.forwardWorld = forward / forwardLength;
    // The part of an axis perpendicular to the view, if it is long enough to give a direction.
    auto perpendicular = [&](const glm::vec3& axis) -> std::optional<glm::vec3> {
        const float axisLength = glm::length(axis);
        if (!(axisLength > 0.0f) || !std::isfinite(axisLength))
            return std::nullopt;
        const glm::vec3 unit = axis / axisLength;
        const glm::vec3 across = unit - glm::dot(unit, camera.forwardWorld) * camera.forwardWorld;
        if (!(glm::length(across) >= kMinUpViewSine))
            return std::nullopt;
        return glm::normalize(across);
    };
    if (const std::optional<glm::vec3> up = perpendicular(worldFromCamera[1])) {
        camera.upWorld = *up;
        return;
    }
    const std::optional<glm::vec3> right = perpendicular(worldFromCamera[0]);
    if (!right)
        fail(field + ": the world transform of its node flattens the camera's up (+Y) and right "
                     "(+X) axes onto its viewing axis, so the image has no orientation");
    camera.upWorld = glm::normalize(glm::cross(*right, camera.forwardWorld));
    warn(field + ": the world transform of its node flattens the camera's up axis (+Y) or makes "
                 "it parallel to the view; up is taken from the camera's right axis (+X)");
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
        const std::string field =
            "extensions.KHR_lights_punctual.lights[" + std::to_string(lightIndex) + "]";
        if (!source.color.empty()) {
            if (source.color.size() != 3 ||
                !std::all_of(source.color.begin(), source.color.end(), finiteNonNegative))
                fail(where + ": color needs 3 finite numbers >= 0");
            light.color = glm::vec3(narrow(source.color[0], field + ".color[0]"),
                                    narrow(source.color[1], field + ".color[1]"),
                                    narrow(source.color[2], field + ".color[2]"));
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
        light.intensity = narrow(source.intensity, field + ".intensity");
        light.positionWorld = glm::vec3(worldFromLight[3]);
        light.directionWorld =
            glm::normalize(glm::mat3(worldFromLight) * glm::vec3(0.0f, 0.0f, -1.0f));
        const glm::vec3 farthestCorner = glm::max(glm::abs(bounds.min - light.positionWorld),
                                                  glm::abs(bounds.max - light.positionWorld));
        light.rangeMetres = source.range > 0.0 ? narrow(source.range, field + ".range")
                                               : 1.01f * glm::length(farthestCorner);
        light.spotInnerCos = float(std::cos(source.spot.innerConeAngle));
        light.spotOuterCos = float(std::cos(source.spot.outerConeAngle));
        // Derived in float: colour x intensity, and a position or range the placement overflowed.
        check(lightProblem(light), field);
        // Every punctual light of a glTF file casts shadows (issue 29: the file has no flag).
        light.castsShadows = true;
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

} // namespace scenes::gltf

namespace scenes {

Scene loadGltf(const std::filesystem::path& path) {
    try {
        gltf::ImageBudget imageBudget;
        tinygltf::Model model = gltf::parseModel(path, imageBudget);
        return gltf::GltfConverter(path, std::move(model), std::move(imageBudget)).convert();
    } catch (const SceneError&) {
        throw;
    } catch (const std::exception& error) {
        // tinygltf and its JSON parser may throw (bad_alloc, out_of_range on odd input).
        gltf::fail(path, error.what());
    }
}

} // namespace scenes
