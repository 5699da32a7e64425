// JsonScene: loadJsonScene() reads the JSON scene format documented in scenes/README.md: glTF
// models and procedural objects placed with transforms, a camera, explicit lights and a
// deterministic point-light generator.
//
// Conventions: those of Scene.h (right-handed, metres, cameras look down -Z); angles in the file
// are in degrees; relative paths are relative to the JSON file. The reader is strict: an unknown
// key, a key that does not apply (a range on a directional light), a wrong type or a value out of
// range is one SceneError naming the file and the field path (e.g. "lights[2].range").
// Objects contribute their geometry (meshes, materials, textures, instances) and their own
// lights (a procedural object's ambient/sun options, a glTF file's KHR_lights_punctual), moved
// by their transform; a procedural object's camera is used when the file sets none. A glTF file
// placed several times is loaded once and instanced. Material entries then change the objects'
// materials by name (model, base colour, metallic/roughness or specular, emissive, alpha mode).
// Thread safety: each call is independent.
#include "scenes/SceneLoader.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <system_error>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "scenes/SceneChecks.h"
#include "scenes/Viewpoints.h"
#include "scenes/input/DuplicateKeys.h"
#include "scenes/input/FloatRange.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/input/WholeFile.h"
#include "scenes/procedural/LightGenerator.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace scenes {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// A camera path is expanded into one view per frame; 10^4 frames is minutes of animation.
constexpr int64_t kMaxCameraPathFrames = 10000;
// Camera defaults when the file leaves them out (documented in scenes/README.md).
constexpr float kDefaultFovYDegrees = 60.0f;
constexpr float kDefaultNearMetres = 0.1f;
constexpr float kDefaultFarMetres = 1000.0f;
// Wider pinhole views are mostly stretched periphery, and Scene's validate() refuses 3.1 rad.
constexpr float kMaxFovYDegrees = 170.0f;

std::string commaSeparated(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names)
        text += (text.empty() ? "" : ", ") + name;
    return text;
}

std::string fieldOf(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
}

std::string elementOf(const std::string& parent, size_t index) {
    return parent + "[" + std::to_string(index) + "]";
}

const Json* member(const Json& object, const char* key) {
    const auto found = object.find(key);
    return found == object.end() ? nullptr : &*found;
}

// The average linear scale of a transform (exact for uniform scale): lengths such as a light's
// range or a camera's near plane scale by it when their object is scaled.
float averageScale(const glm::mat4& worldFromObject) {
    return std::cbrt(std::abs(glm::determinant(glm::mat3(worldFromObject))));
}

// What placing an object adds to a scene, once its meshes are in it: instances of those meshes
// (numbered from meshOffset) and the object's lights, both in the object's space.
struct Placeable {
    uint32_t meshOffset = 0;
    std::vector<Instance> instances;
    std::vector<Light> lights;
    // Triangles one placement draws, an instance counting at least 1 (limits::kMaxTriangles).
    uint64_t drawnTriangles = 0;
    // Object-space bounds of the part's meshes (by the part's mesh index): each placement's
    // composed transforms are checked against them (SceneChecks.h) before they are stored.
    std::vector<Aabb> meshBounds;
};

// Moves `part`'s textures, materials, meshes and warnings into `scene`, rebasing their indices;
// returns what placing the part adds (its cameras are the caller's business).
Placeable addResources(Scene& scene, Scene&& part) {
    const uint32_t materialOffset = uint32_t(scene.materials.size());
    const int textureOffset = int(scene.textures.size());
    for (Texture& texture : part.textures)
        scene.textures.push_back(std::move(texture));
    for (Material& material : part.materials) {
        for (int* texture : material.textureSlots())
            if (*texture >= 0)
                *texture += textureOffset;
        scene.materials.push_back(std::move(material));
    }
    Placeable placeable{uint32_t(scene.meshes.size()), std::move(part.instances),
                        std::move(part.lights)};
    for (const Instance& instance : placeable.instances)
        placeable.drawnTriangles +=
            std::max<uint64_t>(1, part.meshes.at(instance.mesh).triangleCount());
    for (Mesh& mesh : part.meshes) {
        placeable.meshBounds.push_back(boundsOf(mesh));
        mesh.material += materialOffset;
        scene.meshes.push_back(std::move(mesh));
    }
    for (std::string& warning : part.warnings)
        scene.warnings.push_back(std::move(warning));
    return placeable;
}

void place(Scene& scene, const Placeable& object, const glm::mat4& worldFromObject) {
    for (const Instance& instance : object.instances)
        scene.instances.push_back(
            {instance.mesh + object.meshOffset, worldFromObject * instance.worldFromObject});
    for (Light light : object.lights) {
        light.positionWorld = glm::vec3(worldFromObject * glm::vec4(light.positionWorld, 1.0f));
        light.directionWorld = glm::normalize(glm::mat3(worldFromObject) * light.directionWorld);
        light.rangeMetres *= averageScale(worldFromObject);
        scene.lights.push_back(light);
    }
}

// A camera that moves with its object, so it sees the placed object as it saw the original.
Camera movedCamera(Camera camera, const glm::mat4& worldFromObject) {
    const glm::mat3 linear(worldFromObject);
    camera.positionWorld = glm::vec3(worldFromObject * glm::vec4(camera.positionWorld, 1.0f));
    camera.forwardWorld = glm::normalize(linear * camera.forwardWorld);
    camera.upWorld = glm::normalize(linear * camera.upWorld);
    camera.nearMetres *= averageScale(worldFromObject);
    camera.farMetres *= averageScale(worldFromObject);
    return camera;
}

class JsonSceneReader {
public:
    JsonSceneReader(fs::path path, const SceneRequest& request)
        : mPath(std::move(path)), mRequest(request) {}

    Scene read();

private:
    [[noreturn]] void fail(const std::string& field, const std::string& what) const;
    void expectKeys(const Json& object, const std::string& field,
                    const std::vector<std::string>& validKeys) const;
    float number(const Json& value, const std::string& field) const;
    float positive(const Json& value, const std::string& field) const;
    glm::vec3 vec3(const Json& value, const std::string& field) const;
    glm::vec3 direction(const Json& value, const std::string& field) const;
    std::string text(const Json& value, const std::string& field) const;

    glm::mat4 transform(const Json& value, const std::string& field) const;
    void addObject(const Json& value, const std::string& field, Scene& scene,
                   std::optional<Camera>& objectCamera);
    Camera camera(const Json& value, const std::string& field) const;
    void addViews(const Json& root, const std::optional<Camera>& objectCamera, Scene& scene) const;
    Light light(const Json& value, const std::string& field) const;
    LightShadow lightShadow(const Json& value, const std::string& field) const;
    void applyMaterial(const Json& value, const std::string& field, Scene& scene) const;
    glm::vec4 colour(const Json& value, const std::string& field, bool alphaAllowed) const;
    void generateLights(const Json* generator, Scene& scene) const;
    void placeWithinLimits(Scene& scene, const Placeable& object, const glm::mat4& worldFromObject,
                           const std::string& field);

    fs::path mPath;
    const SceneRequest& mRequest;
    // glTF files already in the scene, by canonical path: placing one again adds only instances
    // and lights, so a model placed many times is loaded, and its textures stored, once.
    std::map<fs::path, Placeable> mModels;
    // Triangles the placements so far draw (each instance at least 1): a model placed many
    // times multiplies its instances, so the limit is checked before each placement is copied.
    uint64_t mDrawnTriangles = 0;
};

void JsonSceneReader::placeWithinLimits(Scene& scene, const Placeable& object,
                                        const glm::mat4& worldFromObject,
                                        const std::string& field) {
    if (mDrawnTriangles + object.drawnTriangles > limits::kMaxTriangles)
        fail(field, "the objects placed so far and this one draw " +
                        std::to_string(mDrawnTriangles + object.drawnTriangles) +
                        " triangles, over the limit of " + std::to_string(limits::kMaxTriangles));
    if (scene.lights.size() + object.lights.size() > size_t(limits::kMaxLights))
        fail(field, "the objects placed so far and this one bring more than " +
                        std::to_string(limits::kMaxLights) + " lights");
    // The object's own transforms composed with this placement, checked in float (SceneChecks.h)
    // before anything is stored: a model's node scale times the object's scale may overflow.
    for (size_t i = 0; i < object.instances.size(); ++i) {
        const Instance& instance = object.instances[i];
        const std::string problem = placedBoundsProblem(object.meshBounds.at(instance.mesh),
                                                        worldFromObject * instance.worldFromObject);
        if (!problem.empty())
            fail(fieldOf(field, "transform"),
                 "composed with the object's own transforms, its instance " + std::to_string(i) +
                     " (mesh '" + scene.meshes.at(object.meshOffset + instance.mesh).name +
                     "'): " + problem);
    }
    mDrawnTriangles += object.drawnTriangles;
    const size_t firstLight = scene.lights.size();
    place(scene, object, worldFromObject);
    for (size_t i = firstLight; i < scene.lights.size(); ++i)
        if (const std::string problem = lightProblem(scene.lights[i]); !problem.empty())
            fail(fieldOf(field, "transform"),
                 "moves the object's light " + std::to_string(i - firstLight) + ": " + problem);
}

void JsonSceneReader::fail(const std::string& field, const std::string& what) const {
    throw SceneError(mPath.string() + ": " + (field.empty() ? "" : field + ": ") + what);
}

void JsonSceneReader::expectKeys(const Json& object, const std::string& field,
                                 const std::vector<std::string>& validKeys) const {
    if (!object.is_object())
        fail(field, std::string("expected an object, got ") + object.type_name());
    for (const auto& [key, value] : object.items())
        if (std::find(validKeys.begin(), validKeys.end(), key) == validKeys.end())
            fail(field,
                 "unknown key '" + key + "' (valid keys: " + commaSeparated(validKeys) + ")");
}

float JsonSceneReader::number(const Json& value, const std::string& field) const {
    if (!value.is_number())
        fail(field, std::string("expected a number, got ") + value.type_name());
    const double number = value.get<double>();
    if (const std::string problem = floatRangeProblem(number); !problem.empty())
        fail(field, problem);
    return float(number);
}

float JsonSceneReader::positive(const Json& value, const std::string& field) const {
    const float result = number(value, field);
    if (!(result > 0.0f))
        fail(field, "expected a positive number");
    return result;
}

glm::vec3 JsonSceneReader::vec3(const Json& value, const std::string& field) const {
    if (!value.is_array() || value.size() != 3)
        fail(field, "expected an array of 3 numbers");
    return glm::vec3(number(value[0], field + "[0]"), number(value[1], field + "[1]"),
                     number(value[2], field + "[2]"));
}

glm::vec3 JsonSceneReader::direction(const Json& value, const std::string& field) const {
    const glm::vec3 vector = vec3(value, field);
    if (!(glm::length(vector) > 0.0f))
        fail(field, "expected a non-zero direction");
    return glm::normalize(vector);
}

std::string JsonSceneReader::text(const Json& value, const std::string& field) const {
    if (!value.is_string())
        fail(field, std::string("expected a string, got ") + value.type_name());
    return value.get<std::string>();
}

Scene JsonSceneReader::read() {
    if (!mRequest.options.empty())
        fail("", "option '" + mRequest.options.begin()->first +
                     "' is not valid: a JSON scene takes its options from the file");
    if (mRequest.lightCount.value_or(0) < 0)
        fail("", "light count must be >= 0, got " + std::to_string(*mRequest.lightCount));
    std::string bytes;
    if (const std::string problem = readWholeFile(mPath, &bytes); !problem.empty())
        fail("", problem);
    // nlohmann::json parses and destroys iteratively, but the bound keeps every reader of the
    // document (and of the glTF files it names) within one documented limit.
    NestingViolation violation;
    if (jsonNestsDeeperThan(bytes, limits::kMaxNestingDepth, &violation))
        fail("", "JSON nests deeper than " + std::to_string(limits::kMaxNestingDepth) +
                     " levels (line " + std::to_string(violation.line) + ")");
    if (const std::string problem = jsonDuplicateKeyProblem(bytes); !problem.empty())
        fail("", problem);
    Json root;
    try {
        root = Json::parse(bytes);
    } catch (const Json::exception& parseError) { // parse_error, or out_of_range for 1e999
        fail("", std::string("invalid JSON: ") + parseError.what());
    }
    expectKeys(root, "",
               {"name", "camera", "cameras", "cameraPath", "objects", "lights", "lightGenerator",
                "materials"});

    Scene scene;
    scene.name = member(root, "name") ? text(root["name"], "name") : mPath.stem().string();

    const Json* objects = member(root, "objects");
    if (!objects)
        fail("", "missing key 'objects'");
    if (!objects->is_array() || objects->empty())
        fail("objects", "expected a non-empty array of objects");
    std::optional<Camera> objectCamera;
    for (size_t i = 0; i < objects->size(); ++i)
        addObject((*objects)[i], elementOf("objects", i), scene, objectCamera);
    if (const Json* materials = member(root, "materials")) {
        if (!materials->is_array())
            fail("materials", "expected an array of material entries");
        for (size_t i = 0; i < materials->size(); ++i)
            applyMaterial((*materials)[i], elementOf("materials", i), scene);
    }

    addViews(root, objectCamera, scene);

    if (const Json* lights = member(root, "lights")) {
        if (!lights->is_array())
            fail("lights", "expected an array of lights");
        for (size_t i = 0; i < lights->size(); ++i)
            scene.lights.push_back(light((*lights)[i], elementOf("lights", i)));
    }
    generateLights(member(root, "lightGenerator"), scene);

    try {
        validate(scene);
    } catch (const SceneError& invalid) {
        fail("", invalid.what());
    }
    return scene;
}

// worldFromObject = translate * rotate * scale; rotateDegrees turns about X, then Y, then Z.
glm::mat4 JsonSceneReader::transform(const Json& value, const std::string& field) const {
    expectKeys(value, field, {"translate", "rotateDegrees", "axisAngle", "scale"});
    glm::mat4 worldFromObject(1.0f);
    if (const Json* translate = member(value, "translate"))
        worldFromObject =
            glm::translate(worldFromObject, vec3(*translate, fieldOf(field, "translate")));

    const Json* euler = member(value, "rotateDegrees");
    const Json* axisAngle = member(value, "axisAngle");
    if (euler && axisAngle)
        fail(field, "give rotateDegrees or axisAngle, not both");
    if (euler) {
        const glm::vec3 degrees = vec3(*euler, fieldOf(field, "rotateDegrees"));
        worldFromObject = glm::rotate(worldFromObject, glm::radians(degrees.z), glm::vec3(0, 0, 1));
        worldFromObject = glm::rotate(worldFromObject, glm::radians(degrees.y), glm::vec3(0, 1, 0));
        worldFromObject = glm::rotate(worldFromObject, glm::radians(degrees.x), glm::vec3(1, 0, 0));
    }
    if (axisAngle) {
        const std::string axisAngleField = fieldOf(field, "axisAngle");
        expectKeys(*axisAngle, axisAngleField, {"axis", "degrees"});
        if (!member(*axisAngle, "axis") || !member(*axisAngle, "degrees"))
            fail(axisAngleField, "needs both 'axis' and 'degrees'");
        const glm::vec3 axis = direction((*axisAngle)["axis"], fieldOf(axisAngleField, "axis"));
        const float degrees = number((*axisAngle)["degrees"], fieldOf(axisAngleField, "degrees"));
        worldFromObject = glm::rotate(worldFromObject, glm::radians(degrees), axis);
    }

    if (const Json* scaleValue = member(value, "scale")) {
        // Positive only: a mirroring scale would turn counter-clockwise front faces clockwise.
        const std::string scaleField = fieldOf(field, "scale");
        const glm::vec3 scale = scaleValue->is_array() ? vec3(*scaleValue, scaleField)
                                                       : glm::vec3(number(*scaleValue, scaleField));
        if (!(glm::min(scale.x, glm::min(scale.y, scale.z)) > 0.0f))
            fail(scaleField, "expected a positive number or an array of 3 positive numbers");
        worldFromObject = glm::scale(worldFromObject, scale);
    }
    if (const std::string problem = transformProblem(worldFromObject); !problem.empty())
        fail(field, problem);
    return worldFromObject;
}

void JsonSceneReader::addObject(const Json& value, const std::string& field, Scene& scene,
                                std::optional<Camera>& objectCamera) {
    expectKeys(value, field, {"gltf", "procedural", "options", "transform"});
    const Json* gltf = member(value, "gltf");
    const Json* procedural = member(value, "procedural");
    if (bool(gltf) == bool(procedural))
        fail(field, "give exactly one of 'gltf' and 'procedural'");
    const glm::mat4 worldFromObject =
        member(value, "transform") ? transform(value["transform"], fieldOf(field, "transform"))
                                   : glm::mat4(1.0f);

    if (gltf) {
        if (member(value, "options"))
            fail(field, "'options' apply to procedural objects only");
        const std::string gltfField = fieldOf(field, "gltf");
        const fs::path modelPath = mPath.parent_path() / fs::path(text(*gltf, gltfField));
        std::error_code error;
        fs::path key = fs::weakly_canonical(modelPath, error);
        if (error)
            key = modelPath.lexically_normal();
        auto model = mModels.find(key);
        if (model == mModels.end()) {
            Scene part;
            try {
                part = loadGltf(modelPath);
            } catch (const SceneError& loadError) {
                fail(gltfField, loadError.what());
            }
            model = mModels.emplace(key, addResources(scene, std::move(part))).first;
        }
        placeWithinLimits(scene, model->second, worldFromObject, field);
    } else {
        const std::string name = text(*procedural, fieldOf(field, "procedural"));
        if (!isProceduralScene(name))
            fail(fieldOf(field, "procedural"), "unknown procedural scene '" + name + "' (valid: " +
                                                   commaSeparated(proceduralSceneNames()) + ")");
        // Generated lights are the file's business (lightGenerator), so none are asked for here.
        SceneRequest request;
        if (const Json* options = member(value, "options")) {
            const std::string optionsField = fieldOf(field, "options");
            if (!options->is_object())
                fail(optionsField, "expected an object");
            for (const auto& [key, option] : options->items()) {
                // Booleans become the 1/0 that procedural switches take.
                if (option.is_boolean())
                    request.options[key] = option.get<bool>() ? "1" : "0";
                else if (option.is_string())
                    request.options[key] = option.get<std::string>();
                else if (option.is_number())
                    request.options[key] = option.dump();
                else
                    fail(fieldOf(optionsField, key), "expected a string, number or boolean");
            }
        }
        Scene part;
        try {
            part = buildProceduralScene(name, request);
        } catch (const SceneError& error) {
            fail(field, error.what());
        }
        if (!objectCamera && !part.cameras.empty()) {
            objectCamera = movedCamera(part.cameras.front(), worldFromObject);
            if (const std::string problem = cameraProblem(*objectCamera); !problem.empty())
                fail(fieldOf(field, "transform"),
                     "moves the object's camera '" + objectCamera->name + "': " + problem);
        }
        placeWithinLimits(scene, addResources(scene, std::move(part)), worldFromObject, field);
    }
}

Camera JsonSceneReader::camera(const Json& value, const std::string& field) const {
    expectKeys(value, field,
               {"name", "position", "target", "forward", "up", "fovYDegrees", "near", "far"});
    const Json* target = member(value, "target");
    const Json* forward = member(value, "forward");
    if (!member(value, "position"))
        fail(field, "missing key 'position'");
    if (bool(target) == bool(forward))
        fail(field, "give exactly one of 'target' and 'forward'");

    Camera camera;
    camera.name = member(value, "name") ? text(value["name"], fieldOf(field, "name")) : "camera";
    camera.positionWorld = vec3(value["position"], fieldOf(field, "position"));
    if (target) {
        const glm::vec3 toTarget = vec3(*target, fieldOf(field, "target")) - camera.positionWorld;
        if (!(glm::length(toTarget) > 0.0f))
            fail(fieldOf(field, "target"), "same point as the position");
        camera.forwardWorld = glm::normalize(toTarget);
    } else {
        camera.forwardWorld = direction(*forward, fieldOf(field, "forward"));
    }
    if (const Json* up = member(value, "up"))
        camera.upWorld = direction(*up, fieldOf(field, "up"));
    if (!(glm::length(glm::cross(camera.forwardWorld, camera.upWorld)) >= kMinUpViewSine))
        fail(fieldOf(field, "up"), "parallel to the viewing direction (within 0.057 degrees)");

    const float fovYDegrees = member(value, "fovYDegrees")
                                  ? number(value["fovYDegrees"], fieldOf(field, "fovYDegrees"))
                                  : kDefaultFovYDegrees;
    if (!(fovYDegrees > 0.0f && fovYDegrees <= kMaxFovYDegrees))
        fail(fieldOf(field, "fovYDegrees"),
             "expected a number in (0, " + std::to_string(int(kMaxFovYDegrees)) + "]");
    camera.verticalFovRadians = glm::radians(fovYDegrees);
    camera.nearMetres = member(value, "near") ? positive(value["near"], fieldOf(field, "near"))
                                              : kDefaultNearMetres;
    camera.farMetres =
        member(value, "far") ? positive(value["far"], fieldOf(field, "far")) : kDefaultFarMetres;
    if (!(camera.farMetres > camera.nearMetres))
        fail(field, "'far' must exceed 'near'");
    if (const std::string problem = lengthProblem(camera.farMetres); !problem.empty())
        fail(fieldOf(field, "far"), problem);
    // What the fields allow one by one may still make an unusable camera (SceneChecks.h).
    if (const std::string problem = cameraProblem(camera); !problem.empty())
        fail(field, problem);
    return camera;
}

// The scene's views (Viewpoints.h), in this order: `camera`, then the `cameras` list; when neither
// is given, the first procedural object's camera or else a camera framing the bounds; then the
// frames of `cameraPath`. Names are made unique.
void JsonSceneReader::addViews(const Json& root, const std::optional<Camera>& objectCamera,
                               Scene& scene) const {
    if (const Json* cameraValue = member(root, "camera"))
        scene.cameras.push_back(camera(*cameraValue, "camera"));
    if (const Json* cameras = member(root, "cameras")) {
        if (!cameras->is_array() || cameras->empty())
            fail("cameras", "expected a non-empty array of cameras");
        for (size_t i = 0; i < cameras->size(); ++i) {
            Camera view = camera((*cameras)[i], elementOf("cameras", i));
            if (!member((*cameras)[i], "name"))
                view.name = "camera " + std::to_string(i);
            scene.cameras.push_back(view);
        }
    }
    if (scene.cameras.empty())
        scene.cameras.push_back(objectCamera ? *objectCamera
                                             : cameraFramingBounds(scene.boundsWorld()));
    if (const Json* path = member(root, "cameraPath")) {
        expectKeys(*path, "cameraPath", {"name", "frames", "keys"});
        const std::string name =
            member(*path, "name") ? text((*path)["name"], "cameraPath.name") : "path";
        const Json* frames = member(*path, "frames");
        if (!frames || !frames->is_number_integer() || frames->get<int64_t>() < 2 ||
            frames->get<int64_t>() > kMaxCameraPathFrames)
            fail("cameraPath.frames",
                 "expected an integer in [2, " + std::to_string(kMaxCameraPathFrames) + "]");
        const Json* keys = member(*path, "keys");
        if (!keys || !keys->is_array() || keys->size() < 2)
            fail("cameraPath.keys", "expected an array of at least 2 cameras");
        std::vector<Camera> keyCameras;
        for (size_t i = 0; i < keys->size(); ++i)
            keyCameras.push_back(camera((*keys)[i], elementOf("cameraPath.keys", i)));
        std::vector<Camera> frameCameras;
        try {
            frameCameras = cameraPath(name, keyCameras, int(frames->get<int64_t>()));
        } catch (const SceneError& error) {
            fail("cameraPath", error.what());
        }
        for (const Camera& view : frameCameras) {
            // Interpolated up and forward may come close to parallel between two keys.
            if (const std::string problem = cameraProblem(view); !problem.empty())
                fail("cameraPath", "frame '" + view.name + "': " + problem);
            scene.cameras.push_back(view);
        }
    }
    makeViewNamesUnique(scene.cameras);
}

Light JsonSceneReader::light(const Json& value, const std::string& field) const {
    if (!value.is_object())
        fail(field, "expected an object");
    if (!member(value, "type"))
        fail(field, "missing key 'type'");
    const std::string type = text(value["type"], fieldOf(field, "type"));

    // Keys each type requires; color and intensity are optional for every type, castsShadows and
    // shadow for every type but ambient.
    Light light;
    std::vector<std::string> required;
    if (type == "point") {
        light.type = LightType::Point;
        required = {"position", "range"};
    } else if (type == "spot") {
        light.type = LightType::Spot;
        required = {"position", "direction", "range", "innerConeDegrees", "outerConeDegrees"};
    } else if (type == "directional") {
        light.type = LightType::Directional;
        required = {"direction"};
    } else if (type == "ambient") {
        light.type = LightType::Ambient;
    } else {
        fail(fieldOf(field, "type"),
             "unknown light type '" + type + "' (valid: point, spot, directional, ambient)");
    }
    std::vector<std::string> valid = required;
    valid.insert(valid.end(), {"type", "color", "intensity"});
    if (light.type != LightType::Ambient)
        valid.insert(valid.end(), {"castsShadows", "shadow"});
    expectKeys(value, field, valid);
    for (const std::string& key : required)
        if (!member(value, key.c_str()))
            fail(field, "a " + type + " light needs '" + key + "'");

    if (const Json* color = member(value, "color")) {
        light.color = vec3(*color, fieldOf(field, "color"));
        if (!(glm::min(light.color.r, glm::min(light.color.g, light.color.b)) >= 0.0f))
            fail(fieldOf(field, "color"), "components must not be negative");
    }
    if (const Json* intensity = member(value, "intensity")) {
        light.intensity = number(*intensity, fieldOf(field, "intensity"));
        if (!(light.intensity >= 0.0f))
            fail(fieldOf(field, "intensity"), "must not be negative");
    }
    if (const Json* position = member(value, "position"))
        light.positionWorld = vec3(*position, fieldOf(field, "position"));
    if (const Json* directionValue = member(value, "direction"))
        light.directionWorld = direction(*directionValue, fieldOf(field, "direction"));
    if (const Json* range = member(value, "range"))
        light.rangeMetres = positive(*range, fieldOf(field, "range"));
    if (const Json* casts = member(value, "castsShadows")) {
        if (!casts->is_boolean())
            fail(fieldOf(field, "castsShadows"), "expected true or false");
        light.castsShadows = casts->get<bool>();
    }
    if (const Json* shadow = member(value, "shadow")) {
        // Settings for maps the light would not get are an error, not silently unused.
        if (!light.castsShadows)
            fail(fieldOf(field, "shadow"), "needs \"castsShadows\": true on the light");
        light.shadow = lightShadow(*shadow, fieldOf(field, "shadow"));
    }
    if (light.type == LightType::Spot) {
        const float inner = number(value["innerConeDegrees"], fieldOf(field, "innerConeDegrees"));
        const float outer = number(value["outerConeDegrees"], fieldOf(field, "outerConeDegrees"));
        if (!(inner >= 0.0f && inner <= outer && outer < 90.0f))
            fail(field, "need 0 <= innerConeDegrees <= outerConeDegrees < 90");
        light.spotInnerCos = std::cos(glm::radians(inner));
        light.spotOuterCos = std::cos(glm::radians(outer));
    }
    // Derived in float: colour x intensity (each finite alone), position and range limits.
    if (const std::string problem = lightProblem(light); !problem.empty())
        fail(field, problem);
    return light;
}

// A light's "shadow": {"mapSize": N, "bias": [constant, slope], "filter": name, "normalOffset":
// x}, every key optional, the names and ranges of the CLI's --shadow-map-size, --shadow-bias
// and --shadow-filter (LightShadow.h).
LightShadow JsonSceneReader::lightShadow(const Json& value, const std::string& field) const {
    expectKeys(value, field, {"mapSize", "bias", "filter", "normalOffset"});
    LightShadow shadow;
    if (const Json* size = member(value, "mapSize")) {
        if (!size->is_number_integer() || size->get<int64_t>() < kMinShadowMapSize ||
            size->get<int64_t>() > kMaxShadowMapSize)
            fail(fieldOf(field, "mapSize"),
                 "expected an integer in [" + std::to_string(kMinShadowMapSize) + ", " +
                     std::to_string(kMaxShadowMapSize) + "] (texels per face side)");
        shadow.mapSize = int(size->get<int64_t>());
    }
    auto bounded = [&](const Json& number_, const std::string& name) {
        const float result = number(number_, name);
        if (!(result >= 0.0f && result <= kMaxShadowBias))
            fail(name, "expected a number in [0, " + std::to_string(int(kMaxShadowBias)) + "]");
        return result;
    };
    if (const Json* bias = member(value, "bias")) {
        if (!bias->is_array() || bias->size() != 2)
            fail(fieldOf(field, "bias"),
                 "expected [constant, slope] (metres, texels), e.g. [0.005, 1.5]");
        shadow.biasConstant = bounded((*bias)[0], fieldOf(field, "bias") + "[0]");
        shadow.biasSlope = bounded((*bias)[1], fieldOf(field, "bias") + "[1]");
    }
    if (const Json* filter = member(value, "filter")) {
        const std::string name = text(*filter, fieldOf(field, "filter"));
        shadow.filter = parseShadowFilter(name);
        if (!shadow.filter)
            fail(fieldOf(field, "filter"),
                 "unknown filter '" + name + "' (valid: " + std::string(kShadowFilterNames) + ")");
    }
    if (const Json* offset = member(value, "normalOffset"))
        shadow.normalOffset = bounded(*offset, fieldOf(field, "normalOffset"));
    return shadow;
}

// [r, g, b] or, with alphaAllowed, [r, g, b, a]: non-negative linear values (alpha at most 1).
glm::vec4 JsonSceneReader::colour(const Json& value, const std::string& field,
                                  bool alphaAllowed) const {
    if (!value.is_array() || !(value.size() == 3 || (alphaAllowed && value.size() == 4)))
        fail(field, alphaAllowed ? "expected an array of 3 or 4 numbers"
                                 : "expected an array of 3 numbers");
    glm::vec4 result(1.0f);
    for (size_t c = 0; c < value.size(); ++c) {
        result[int(c)] = number(value[c], field + "[" + std::to_string(c) + "]");
        if (!(result[int(c)] >= 0.0f))
            fail(field, "components must not be negative");
    }
    if (!(result.a <= 1.0f))
        fail(field, "alpha must be in [0, 1]");
    return result;
}

// One entry of "materials": every material of the scene named `name` ("*": every material)
// takes the entry's values, in the order of the entries. Keys must suit the material's model
// after the entry (its "model", else the model it had).
void JsonSceneReader::applyMaterial(const Json& value, const std::string& field,
                                    Scene& scene) const {
    expectKeys(value, field,
               {"name", "model", "baseColor", "metallic", "roughness", "specularIntensity",
                "specularPower", "emissive", "emissiveStrength", "alphaMode", "alphaCutoff"});
    const Json* nameValue = member(value, "name");
    if (!nameValue)
        fail(field, "missing key 'name' (a material name, or \"*\" for every material)");
    const std::string name = text(*nameValue, fieldOf(field, "name"));
    std::optional<MaterialModel> model;
    if (const Json* modelValue = member(value, "model")) {
        const std::string modelName = text(*modelValue, fieldOf(field, "model"));
        for (MaterialModel candidate :
             {MaterialModel::BlinnPhong, MaterialModel::MetallicRoughness})
            if (modelName == materialModelName(candidate))
                model = candidate;
        if (!model)
            fail(fieldOf(field, "model"), "unknown material model '" + modelName +
                                              "' (valid: blinn-phong, metallic-roughness)");
    }
    auto unit = [&](const char* key) -> std::optional<float> {
        const Json* v = member(value, key);
        if (!v)
            return std::nullopt;
        const float result = number(*v, fieldOf(field, key));
        if (!(result >= 0.0f && result <= 1.0f))
            fail(fieldOf(field, key), "expected a number in [0, 1]");
        return result;
    };
    auto nonNegative = [&](const char* key) -> std::optional<float> {
        const Json* v = member(value, key);
        if (!v)
            return std::nullopt;
        const float result = number(*v, fieldOf(field, key));
        if (!(result >= 0.0f))
            fail(fieldOf(field, key), "must not be negative");
        return result;
    };
    const std::optional<float> metallic = unit("metallic"), roughness = unit("roughness");
    const std::optional<float> specularIntensity = unit("specularIntensity");
    std::optional<float> specularPower;
    if (const Json* power = member(value, "specularPower"))
        specularPower = positive(*power, fieldOf(field, "specularPower"));
    const std::optional<float> emissiveStrength = nonNegative("emissiveStrength");
    std::optional<AlphaMode> alphaMode;
    if (const Json* v = member(value, "alphaMode")) {
        const std::string modeName = text(*v, fieldOf(field, "alphaMode"));
        if (modeName == "OPAQUE")
            alphaMode = AlphaMode::Opaque;
        else if (modeName == "MASK")
            alphaMode = AlphaMode::Mask;
        else if (modeName == "BLEND")
            alphaMode = AlphaMode::Blend;
        else
            fail(fieldOf(field, "alphaMode"),
                 "unknown alpha mode '" + modeName + "' (valid: OPAQUE, MASK, BLEND)");
    }
    const std::optional<float> alphaCutoff = nonNegative("alphaCutoff");
    std::optional<glm::vec4> baseColor, emissive;
    if (const Json* v = member(value, "baseColor"))
        baseColor = colour(*v, fieldOf(field, "baseColor"), true);
    if (const Json* v = member(value, "emissive"))
        emissive = colour(*v, fieldOf(field, "emissive"), false);

    size_t matched = 0;
    for (Material& material : scene.materials) {
        if (name != "*" && material.name != name)
            continue;
        ++matched;
        material.model = model.value_or(material.model);
        const bool metallicRoughness = material.model == MaterialModel::MetallicRoughness;
        const char* wrongKey = metallicRoughness ? (specularIntensity ? "specularIntensity"
                                                    : specularPower   ? "specularPower"
                                                                      : nullptr)
                                                 : (metallic    ? "metallic"
                                                    : roughness ? "roughness"
                                                                : nullptr);
        if (wrongKey)
            fail(fieldOf(field, wrongKey), std::string("does not apply to material '") +
                                               material.name + "', whose model is " +
                                               materialModelName(material.model));
        if (baseColor)
            material.baseColorFactor = *baseColor;
        if (emissive)
            material.emissiveFactor = glm::vec3(*emissive);
        material.emissiveStrength = emissiveStrength.value_or(material.emissiveStrength);
        material.alphaMode = alphaMode.value_or(material.alphaMode);
        material.alphaCutoff = alphaCutoff.value_or(material.alphaCutoff);
        if (metallic || roughness) {
            material.metallic = metallic.value_or(material.metallic);
            material.roughness = roughness.value_or(material.roughness);
            // The Blinn-Phong pair stays the approximation of the new values (Material.h).
            setBlinnPhongFromMetallicRoughness(material);
        }
        material.specularIntensity = specularIntensity.value_or(material.specularIntensity);
        if (specularPower) {
            material.specularPower = *specularPower;
            material.roughness = roughnessForSpecularPower(*specularPower);
        }
        // Derived in float: emissive x emissiveStrength (each finite alone).
        if (const std::string problem = materialProblem(material); !problem.empty())
            fail(field, "material '" + material.name + "': " + problem);
    }
    if (matched == 0) {
        std::vector<std::string> names;
        for (const Material& material : scene.materials)
            if (std::find(names.begin(), names.end(), material.name) == names.end())
                names.push_back(material.name);
        fail(fieldOf(field, "name"),
             "no material named '" + name + "' (the scene's: " + commaSeparated(names) + ")");
    }
}

// Unset generator fields take defaultScatterFor(scene)'s values. The request's lightCount and
// seed, when the lightCount is set (0 included), replace the file's count and seed, and generate
// lights even when the file has no generator; unset, the file's generator decides (no generator:
// no generated lights). Every field is checked even when no light is generated.
void JsonSceneReader::generateLights(const Json* generator, Scene& scene) const {
    const std::string field = "lightGenerator";
    int count = 0;
    uint64_t seed = SceneRequest{}.seed;
    std::optional<Aabb> region;
    std::optional<float> minRange, maxRange, minIntensity, maxIntensity;
    if (generator) {
        expectKeys(*generator, field,
                   {"count", "seed", "regionMin", "regionMax", "minRange", "maxRange",
                    "minIntensity", "maxIntensity"});
        const Json* countValue = member(*generator, "count");
        if (!countValue)
            fail(field, "missing key 'count'");
        if (!countValue->is_number_integer() || countValue->get<int64_t>() < 0)
            fail(fieldOf(field, "count"), "expected a non-negative integer");
        if (countValue->get<int64_t>() > limits::kMaxLights)
            fail(fieldOf(field, "count"), std::to_string(countValue->get<int64_t>()) +
                                              " lights, over the limit of " +
                                              std::to_string(limits::kMaxLights));
        count = int(countValue->get<int64_t>());
        if (const Json* seedValue = member(*generator, "seed")) {
            if (!seedValue->is_number_unsigned())
                fail(fieldOf(field, "seed"), "expected a non-negative integer");
            seed = seedValue->get<uint64_t>();
        }
        const Json* regionMin = member(*generator, "regionMin");
        const Json* regionMax = member(*generator, "regionMax");
        if (bool(regionMin) != bool(regionMax))
            fail(field, "give both 'regionMin' and 'regionMax' or neither");
        if (regionMin) {
            region = Aabb{vec3(*regionMin, fieldOf(field, "regionMin")),
                          vec3(*regionMax, fieldOf(field, "regionMax"))};
            if (glm::any(glm::greaterThan(region->min, region->max)))
                fail(field, "'regionMin' exceeds 'regionMax'");
            for (const char* key : {"regionMin", "regionMax"})
                if (const std::string problem =
                        pointProblem(key == std::string("regionMin") ? region->min : region->max);
                    !problem.empty())
                    fail(fieldOf(field, key), problem);
        }
        auto optionalPositive = [&](const char* key, std::optional<float>& into) {
            if (const Json* value = member(*generator, key))
                into = positive(*value, fieldOf(field, key));
        };
        optionalPositive("minRange", minRange);
        optionalPositive("maxRange", maxRange);
        if (maxRange)
            if (const std::string problem = lengthProblem(*maxRange); !problem.empty())
                fail(fieldOf(field, "maxRange"), problem);
        optionalPositive("minIntensity", minIntensity);
        optionalPositive("maxIntensity", maxIntensity);
    }
    if (mRequest.lightCount) {
        count = *mRequest.lightCount;
        seed = mRequest.seed;
    }
    // Explicit and object lights count against the same limit as generated ones.
    if (uint64_t(count) + scene.lights.size() > uint64_t(limits::kMaxLights))
        fail(field, std::to_string(count) + " generated lights and " +
                        std::to_string(scene.lights.size()) + " others are over the limit of " +
                        std::to_string(limits::kMaxLights));
    // Defaults only when lights are generated: defaultScatterFor() refuses degenerate bounds.
    if (count == 0)
        return;
    PointLightScatter scatter;
    try {
        scatter = defaultScatterFor(scene);
    } catch (const SceneError& error) {
        fail(field, error.what());
    }
    scatter.region = region.value_or(scatter.region);
    scatter.minRangeMetres = minRange.value_or(scatter.minRangeMetres);
    scatter.maxRangeMetres = maxRange.value_or(scatter.maxRangeMetres);
    scatter.minIntensity = minIntensity.value_or(scatter.minIntensity);
    scatter.maxIntensity = maxIntensity.value_or(scatter.maxIntensity);
    if (!(scatter.minRangeMetres <= scatter.maxRangeMetres))
        fail(field, "minRange " + std::to_string(scatter.minRangeMetres) + " exceeds maxRange " +
                        std::to_string(scatter.maxRangeMetres));
    if (!(scatter.minIntensity <= scatter.maxIntensity))
        fail(field, "minIntensity " + std::to_string(scatter.minIntensity) +
                        " exceeds maxIntensity " + std::to_string(scatter.maxIntensity));
    scatterPointLights(scene, scatterForDensity(scatter, mRequest.lightDensity, count), count,
                       seed);
}

} // namespace

Scene loadJsonScene(const fs::path& path, const SceneRequest& request) {
    try {
        return JsonSceneReader(path, request).read();
    } catch (const SceneError&) {
        throw;
    } catch (const std::exception& error) {
        // nlohmann throws on cases the checks above do not foresee; report them as scene errors.
        throw SceneError(path.string() + ": " + error.what());
    }
}

} // namespace scenes
