// ProceduralScenes: the built-in scenes (atrium, wall, spheres, glass) and their registry.
//
// Conventions: world space is right-handed, metres, +Y up (Scene.h). Every scene keeps its
// options in one table (key, default, valid range, meaning); unknown keys and malformed values
// are SceneErrors that list the valid keys, never ignored. Lights come from scatterPointLights()
// with request.seed, so a request always gives bitwise the same lights. Building is
// single-threaded and allocates only the scene; the atrium at detail=1 takes a few tens of
// milliseconds.
#include "scenes/procedural/ProceduralScenes.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string_view>

#include <glm/gtc/matrix_transform.hpp>

#include "scenes/mesh/MeshBuilder.h"
#include "scenes/procedural/LightGenerator.h"

namespace scenes {

namespace {

// Uniform floats in [lo, hi) from a splitmix64 stream: the procedural scenes' own random numbers,
// the same on every platform and standard library (std's distributions are not).
class SplitMix64Uniform {
public:
    explicit SplitMix64Uniform(uint64_t seed) : mState(seed) {}
    float operator()(float lo, float hi) {
        uint64_t z = (mState += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        z ^= z >> 31;
        return lo + (hi - lo) * float(double(z >> 11) * 0x1.0p-53);
    }

private:
    uint64_t mState;
};

// ---------------------------------------------------------------------------------------------
// Options

std::string describe(const std::vector<SceneOption>& specs) {
    std::string text;
    for (const SceneOption& spec : specs) {
        if (!text.empty())
            text += ", ";
        const std::string values =
            spec.minValue == 0 && spec.maxValue == 1
                ? "0|1"
                : std::to_string(spec.minValue) + ".." + std::to_string(spec.maxValue);
        text += spec.key + "=" + values + " (default " + std::to_string(spec.defaultValue) + ": " +
                spec.meaning + ")";
    }
    return text;
}

// Every spec's value (the default when not given). Throws for a key without a spec, or a value
// that is not a plain decimal integer in the spec's range.
std::map<std::string, int> readOptions(const std::string& sceneName, const SceneRequest& request,
                                       const std::vector<SceneOption>& specs) {
    for (const auto& [key, value] : request.options) {
        const bool known =
            std::any_of(specs.begin(), specs.end(),
                        [&name = key](const SceneOption& spec) { return spec.key == name; });
        if (!known)
            throw SceneError(sceneName + ": unknown option '" + key +
                             "'; valid options: " + describe(specs));
    }
    std::map<std::string, int> values;
    for (const SceneOption& spec : specs) {
        const auto given = request.options.find(spec.key);
        if (given == request.options.end()) {
            values[spec.key] = spec.defaultValue;
            continue;
        }
        const std::string& text = given->second;
        int value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error != std::errc() || end != text.data() + text.size() || value < spec.minValue ||
            value > spec.maxValue)
            throw SceneError(sceneName + ": option " + spec.key + "='" + text +
                             "' is not an integer in " + std::to_string(spec.minValue) + ".." +
                             std::to_string(spec.maxValue) + " (" + spec.meaning + ")");
        values[spec.key] = value;
    }
    return values;
}

// ---------------------------------------------------------------------------------------------
// Shared pieces

// Appends a Lambert + Blinn-Phong material; returns its index.
uint32_t addMaterial(Scene& scene, const std::string& name, const glm::vec3& albedo,
                     float specularIntensity, float specularPower) {
    Material material;
    material.name = name;
    material.baseColorFactor = glm::vec4(albedo, 1.0f);
    material.specularIntensity = specularIntensity;
    material.specularPower = specularPower;
    material.roughness = roughnessForSpecularPower(specularPower);
    scene.materials.push_back(material);
    return uint32_t(scene.materials.size() - 1);
}

// A new empty mesh with the given material; returns its index.
uint32_t addMesh(Scene& scene, const std::string& name, uint32_t material) {
    Mesh mesh;
    mesh.name = name;
    mesh.material = material;
    scene.meshes.push_back(std::move(mesh));
    return uint32_t(scene.meshes.size() - 1);
}

void addInstance(Scene& scene, uint32_t mesh, const glm::mat4& worldFromObject = glm::mat4(1.0f)) {
    scene.instances.push_back(Instance{mesh, worldFromObject});
}

// Rotation by quarterTurns * 90 degrees about +Y (counter-clockwise seen from above), then a
// translation. Built from exact 0/1 entries rather than trigonometry, so that axis-aligned
// geometry stays exactly axis-aligned.
glm::mat4 placeTurnedY(const glm::vec3& translationWorld, int quarterTurns) {
    // Image of the object's +X after 0..3 quarter turns. +Z is +X turned three quarters, so its
    // image is three entries further on (a right-handed rotation, determinant +1).
    constexpr glm::vec3 kTurnedX[4] = {{1, 0, 0}, {0, 0, -1}, {-1, 0, 0}, {0, 0, 1}};
    glm::mat4 worldFromObject(1.0f);
    worldFromObject[0] = glm::vec4(kTurnedX[quarterTurns % 4], 0.0f);
    worldFromObject[2] = glm::vec4(kTurnedX[(quarterTurns + 3) % 4], 0.0f);
    worldFromObject[3] = glm::vec4(translationWorld, 1.0f);
    return worldFromObject;
}

Camera makeCamera(const std::string& name, const glm::vec3& positionWorld,
                  const glm::vec3& targetWorld, float farMetres) {
    Camera camera;
    camera.name = name;
    camera.positionWorld = positionWorld;
    camera.forwardWorld = glm::normalize(targetWorld - positionWorld);
    camera.verticalFovRadians = float(std::numbers::pi / 3.0); // 60 degrees
    camera.nearMetres = 0.1f;
    camera.farMetres = farMetres;
    return camera;
}

// One weak sky-coloured ambient light and one warm sun. Position and range do not apply to
// these types and keep their defaults.
void addAmbientAndSun(Scene& scene, bool ambient, bool sun) {
    if (ambient) {
        Light light;
        light.type = LightType::Ambient;
        light.color = glm::vec3(0.55f, 0.65f, 0.85f);
        light.intensity = 0.05f;
        scene.lights.push_back(light);
    }
    if (sun) {
        Light light;
        light.type = LightType::Directional;
        light.directionWorld = glm::normalize(glm::vec3(0.35f, -1.0f, -0.25f));
        light.color = glm::vec3(1.0f, 0.92f, 0.8f);
        light.intensity = 1.0f;
        scene.lights.push_back(light);
    }
}

// A scene's own options plus the ambient and sun switches every scene has.
std::vector<SceneOption> withAmbientAndSun(std::vector<SceneOption> specs, int defaultValue) {
    specs.push_back({"ambient", defaultValue, 0, 1, "add one weak ambient light"});
    specs.push_back({"sun", defaultValue, 0, 1, "add one directional sun light"});
    return specs;
}

// Most clutter objects wall accepts: 500 is one per 1.3 m^2 of the 640 m^2 they stand on, with
// about 30% of it covered (the densest layout tested, beside 1000 lights); far denser, placing
// by rejection without overlap would slow down and then fail.
constexpr int kMaxWallClutter = 500;

// The option tables of the scenes, for a request of `lightCount` generated lights.
std::vector<SceneOption> atriumOptions(int) {
    return withAmbientAndSun(
        {{"detail", 1, 1, 16, "tessellation multiplier; triangles grow about linearly with it"}},
        1);
}
std::vector<SceneOption> wallOptions(int lightCount) {
    return withAmbientAndSun(
        {{"behind", 0, 0, lightCount, "how many of the light count go behind the wall"},
         {"clutter", 0, 0, kMaxWallClutter,
          "street furniture objects (crates, benches, pillars, posts) on both sides"}},
        0);
}
std::vector<SceneOption> glassOptions(int) {
    return withAmbientAndSun(
        {{"opaque_panes", 0, 0, 1,
          "1: the three panes drawn opaque, so a multisampled frame's edge layer (msaa.complex) "
          "holds their silhouettes: a mask for measuring the panes' edges, not a glass scene"}},
        0);
}
std::vector<SceneOption> spheresOptions(int) {
    return withAmbientAndSun(
        {{"segments", 64, 4, 1024, "longitude segments per sphere; latitude gets half"}}, 0);
}

// ---------------------------------------------------------------------------------------------
// atrium: a Sponza-like courtyard. x across the nave, y up, z along it; the camera stands at the
// +Z end looking down -Z. Interior: 16 m wide, 36 m long, walls 14 m high. Along each long side
// a two-storey colonnade: 12 columns carrying arches in a wall (ground floor, spandrels filled)
// under a gallery floor with a parapet, then 12 slimmer columns carrying free ring arches under
// the gallery roof. Banners hang from the gallery edge into each ground-floor bay.

// A column standing on its object origin: square plinth, round shaft, square capital.
struct ColumnShape {
    float plinthHalfWidth, plinthHeight;
    float shaftRadius, shaftHeight;
    float capitalHalfWidth, capitalHeight;
    constexpr float height() const { return plinthHeight + shaftHeight + capitalHeight; }
};

constexpr float kAtriumHalfWidth = 8.0f;
constexpr float kAtriumHalfLength = 18.0f;
constexpr float kAtriumWallHeight = 14.0f;
constexpr float kColonnadeX = 4.8f; // column axes; leaves a 9.6 m nave and 3.2 m aisles
constexpr int kColumnsPerSide = 12;
constexpr ColumnShape kGroundColumn{0.35f, 0.35f, 0.28f, 3.3f, 0.4f, 0.35f}; // 4.0 m
constexpr ColumnShape kUpperColumn{0.3f, 0.3f, 0.22f, 2.7f, 0.35f, 0.3f};    // 3.3 m
// The end columns' capitals touch the end walls, so the arcade closes against them.
constexpr float kEndColumnZ = kAtriumHalfLength - kGroundColumn.capitalHalfWidth;
constexpr float kBaySpacing = 2.0f * kEndColumnZ / float(kColumnsPerSide - 1); // 3.2 m
constexpr float kArchOuterRadius = 0.5f * kBaySpacing; // neighbouring arches meet on a column
constexpr float kGroundColumnTop = kGroundColumn.height();
constexpr float kGalleryFloorBottom = kGroundColumnTop + kArchOuterRadius; // on the arch tops
constexpr float kGalleryFloorTop = kGalleryFloorBottom + 0.3f;
constexpr float kUpperColumnTop = kGalleryFloorTop + kUpperColumn.height();
constexpr float kRoofBottom = kUpperColumnTop + kArchOuterRadius;
constexpr float kGroundArchDepth = 0.7f;
constexpr float kArcadeFaceX = kColonnadeX - 0.5f * kGroundArchDepth; // nave face of the arcade
// Base cell size of flat surfaces at detail=1 (metres): about the size of the column and arch
// cells, so that triangles are comparable in area across the scene.
constexpr float kAtriumCellMetres = 0.25f;

// Appends a column standing on the object origin.
void appendColumn(Mesh& mesh, const ColumnShape& shape, float scale) {
    // Shafts get 32 sides for a round silhouette; heights and boxes about 15 cm cells.
    const float cellMetres = 0.15f / scale;
    const float w = shape.plinthHalfWidth;
    appendBox(mesh, Aabb{{-w, 0.0f, -w}, {w, shape.plinthHeight, w}}, cellMetres);
    appendCylinder(mesh, glm::vec3(0.0f, shape.plinthHeight, 0.0f), shape.shaftRadius,
                   shape.shaftHeight, int(std::lround(32 * scale)),
                   int(std::ceil(shape.shaftHeight / cellMetres)));
    const float c = shape.capitalHalfWidth, capitalBottom = shape.plinthHeight + shape.shaftHeight;
    appendBox(mesh, Aabb{{-c, capitalBottom, -c}, {c, capitalBottom + shape.capitalHeight, c}},
              cellMetres);
}

// Cells along a length for flat surfaces at this detail.
int cellsAlong(float lengthMetres, float scale) {
    return std::max(1, int(std::lround(lengthMetres / kAtriumCellMetres * scale)));
}

Scene buildAtrium(const SceneRequest& request) {
    Scene scene;
    scene.name = "atrium";
    const std::map<std::string, int> options =
        readOptions(scene.name, request, atriumOptions(request.lightCount.value_or(0)));
    // Cells per unit length grow with sqrt(detail), so cell counts grow with detail.
    const float scale = std::sqrt(float(options.at("detail")));

    const uint32_t floorStone =
        addMaterial(scene, "floor-stone", {0.46f, 0.42f, 0.37f}, 0.06f, 24.0f);
    const uint32_t marble =
        addMaterial(scene, "column-marble", {0.78f, 0.75f, 0.68f}, 0.30f, 120.0f);
    const uint32_t plaster = addMaterial(scene, "wall-plaster", {0.72f, 0.63f, 0.50f}, 0.02f, 6.0f);
    const uint32_t sandstone =
        addMaterial(scene, "arch-sandstone", {0.66f, 0.44f, 0.30f}, 0.08f, 16.0f);
    const uint32_t limestone =
        addMaterial(scene, "slab-limestone", {0.58f, 0.56f, 0.52f}, 0.12f, 40.0f);
    const uint32_t clothMaterials[3] = {
        addMaterial(scene, "cloth-red", {0.55f, 0.05f, 0.04f}, 0.03f, 4.0f),
        addMaterial(scene, "cloth-green", {0.06f, 0.40f, 0.10f}, 0.04f, 5.0f),
        addMaterial(scene, "cloth-blue", {0.05f, 0.10f, 0.50f}, 0.05f, 3.0f),
    };

    const float width = 2.0f * kAtriumHalfWidth, length = 2.0f * kAtriumHalfLength;
    // Floor and walls: single-sided surfaces facing into the courtyard (their outsides are
    // never seen), so no triangles are spent on hidden faces.
    const uint32_t floor = addMesh(scene, "floor", floorStone);
    appendQuad(scene.meshes[floor], {-kAtriumHalfWidth, 0.0f, kAtriumHalfLength},
               {width, 0.0f, 0.0f}, {0.0f, 0.0f, -length}, cellsAlong(width, scale),
               cellsAlong(length, scale));
    addInstance(scene, floor);

    const uint32_t walls = addMesh(scene, "walls", plaster);
    {
        Mesh& mesh = scene.meshes[walls];
        const glm::vec3 up(0.0f, kAtriumWallHeight, 0.0f);
        const int rows = cellsAlong(kAtriumWallHeight, scale);
        const float x = kAtriumHalfWidth, z = kAtriumHalfLength;
        appendQuad(mesh, {x, 0, -z}, {0, 0, length}, up, cellsAlong(length, scale), rows);
        appendQuad(mesh, {-x, 0, z}, {0, 0, -length}, up, cellsAlong(length, scale), rows);
        appendQuad(mesh, {-x, 0, -z}, {width, 0, 0}, up, cellsAlong(width, scale), rows);
        appendQuad(mesh, {x, 0, z}, {-width, 0, 0}, up, cellsAlong(width, scale), rows);
    }
    addInstance(scene, walls);

    // Gallery floors, parapets and roofs: closed boxes on both sides, world space.
    const uint32_t slabs = addMesh(scene, "gallery-slabs", limestone);
    for (const float side : {1.0f, -1.0f}) {
        auto slab = [&](float xNear, float xFar, float yBottom, float yTop) {
            const float x0 = side * xNear, x1 = side * xFar;
            appendBox(scene.meshes[slabs],
                      Aabb{{std::min(x0, x1), yBottom, -kAtriumHalfLength},
                           {std::max(x0, x1), yTop, kAtriumHalfLength}},
                      kAtriumCellMetres / scale);
        };
        slab(kArcadeFaceX, kAtriumHalfWidth, kGalleryFloorBottom, kGalleryFloorTop);
        slab(kArcadeFaceX, kArcadeFaceX + 0.2f, kGalleryFloorTop, kGalleryFloorTop + 0.9f);
        slab(kArcadeFaceX, kAtriumHalfWidth, kRoofBottom, kRoofBottom + 0.3f);
    }
    addInstance(scene, slabs);

    // One mesh per repeated element, instanced along both colonnades (object +Z of arches and
    // banners turned to face the nave).
    const uint32_t groundColumn = addMesh(scene, "ground-column", marble);
    appendColumn(scene.meshes[groundColumn], kGroundColumn, scale);
    const uint32_t upperColumn = addMesh(scene, "upper-column", marble);
    appendColumn(scene.meshes[upperColumn], kUpperColumn, scale);

    ArchShape arch;
    arch.outerRadiusMetres = kArchOuterRadius;
    arch.arcSegmentCount = 4 * int(std::lround(8 * scale));
    arch.bandSegmentCount = int(std::lround(4 * scale));
    arch.depthSegmentCount = int(std::lround(7 * scale));
    const uint32_t groundArch = addMesh(scene, "ground-arch", sandstone);
    arch.innerRadiusMetres = kArchOuterRadius - kGroundColumn.capitalHalfWidth;
    arch.depthMetres = kGroundArchDepth;
    arch.outline = ArchOutline::Square;
    appendArch(scene.meshes[groundArch], arch);
    const uint32_t upperArch = addMesh(scene, "upper-arch", sandstone);
    arch.innerRadiusMetres = kArchOuterRadius - kUpperColumn.capitalHalfWidth;
    arch.depthMetres = 0.6f;
    arch.outline = ArchOutline::Ring;
    appendArch(scene.meshes[upperArch], arch);

    uint32_t banners[3];
    for (int b = 0; b < 3; ++b) {
        banners[b] = addMesh(scene, "banner-" + std::to_string(b), clothMaterials[b]);
        ClothShape cloth;
        cloth.widthMetres = 2.0f;
        cloth.heightMetres = 3.4f;
        cloth.amplitudeMetres = 0.12f;
        cloth.waveCount = 1.0f + 0.5f * float(b);
        cloth.phaseRadians = 2.1f * float(b);
        cloth.cellCountU = int(std::lround(20 * scale));
        cloth.cellCountV = int(std::lround(34 * scale));
        appendCloth(scene.meshes[banners[b]], cloth);
    }

    for (int sideIndex = 0; sideIndex < 2; ++sideIndex) {
        const float side = sideIndex == 0 ? 1.0f : -1.0f;
        const int towardsNave = sideIndex == 0 ? 3 : 1; // quarter turns taking +Z to -side X
        for (int c = 0; c < kColumnsPerSide; ++c) {
            const float z = -kEndColumnZ + kBaySpacing * float(c);
            addInstance(scene, groundColumn,
                        glm::translate(glm::mat4(1.0f), {side * kColonnadeX, 0.0f, z}));
            addInstance(scene, upperColumn,
                        glm::translate(glm::mat4(1.0f), {side * kColonnadeX, kGalleryFloorTop, z}));
            if (c + 1 == kColumnsPerSide)
                continue;
            const float bayZ = z + 0.5f * kBaySpacing;
            addInstance(scene, groundArch,
                        placeTurnedY({side * kColonnadeX, kGroundColumnTop, bayZ}, towardsNave));
            addInstance(scene, upperArch,
                        placeTurnedY({side * kColonnadeX, kUpperColumnTop, bayZ}, towardsNave));
            // Hung 5 cm under the gallery floor, 25 cm in front of the arcade.
            addInstance(
                scene, banners[(c + sideIndex) % 3],
                placeTurnedY({side * (kArcadeFaceX - 0.25f), kGalleryFloorBottom - 0.05f, bayZ},
                             towardsNave));
        }
    }

    // Eye height, 1.2 m from the near end wall, looking down the nave and slightly up; the far
    // plane is a little beyond the farthest corner (about 37 m away).
    scene.cameras.push_back(makeCamera("nave", {0.0f, 1.7f, kAtriumHalfLength - 1.2f},
                                       {0.0f, 5.0f, -kAtriumHalfLength}, 45.0f));

    // Lights fill the courtyard 0.3 m inside the walls, from the floor to under the wall tops.
    // Ranges 1.5-5 m: the mean sphere is about 185 m^3 in a 7,000 m^3 volume, so with 1000
    // lights a point inside sees about 25 of them.
    PointLightScatter scatter;
    scatter.region.min = {-kAtriumHalfWidth + 0.3f, 0.2f, -kAtriumHalfLength + 0.3f};
    scatter.region.max = {kAtriumHalfWidth - 0.3f, kAtriumWallHeight - 0.3f,
                          kAtriumHalfLength - 0.3f};
    scatter.minRangeMetres = 1.5f;
    scatter.maxRangeMetres = 5.0f;
    scatter.minIntensity = 0.3f;
    scatter.maxIntensity = 1.5f;
    const int lightCount = request.lightCount.value_or(0);
    scatterPointLights(scene, scatterForDensity(scatter, request.lightDensity, lightCount),
                       lightCount, request.seed);
    addAmbientAndSun(scene, options.at("ambient") == 1, options.at("sun") == 1);
    // More views (Viewpoints.h): back down the nave from the far end,
    // from gallery height above the nave edge across to the far arcade, and from high above the
    // near end looking down into the courtyard.
    scene.cameras.push_back(makeCamera("far-end", {0.0f, 1.7f, -kAtriumHalfLength + 1.2f},
                                       {0.0f, 5.0f, kAtriumHalfLength}, 45.0f));
    scene.cameras.push_back(makeCamera("gallery", {3.0f, kGalleryFloorTop + 1.6f, 12.0f},
                                       {-kAtriumHalfWidth, 2.0f, -8.0f}, 45.0f));
    scene.cameras.push_back(makeCamera("overhead", {0.0f, kAtriumWallHeight - 1.0f, 16.0f},
                                       {0.0f, 0.0f, -2.0f}, 50.0f));
    return scene;
}

// ---------------------------------------------------------------------------------------------
// wall: a 40 m x 6 m x 0.3 m wall along X on a floor, its visible face at z = +0.15 towards the
// camera, which stands 9 m from it at 45 degrees. Lights are uniform in a box near the wall
// (front: in front of it; behind: behind it, see placeBehind) restricted to the camera's view
// frustum at aspect 1, the narrowest aspect we render, so frustum culling alone keeps them all.

constexpr float kWallHalfLength = 20.0f;
constexpr float kWallHeight = 6.0f;
constexpr float kWallHalfThickness = 0.15f;
constexpr float kWallFaceZ = kWallHalfThickness; // the face the camera sees
// Behind-lights are this fraction of their range behind the visible face: their spheres cross
// the wall and reach the tiles on its face, yet the whole face looks away from them.
constexpr float kBehindMinFraction = 0.25f;
constexpr float kBehindMaxFraction = 0.85f;
constexpr float kBehindMinRange = 1.5f; // 0.25 * 1.5 > 0.3: centres clear the wall's back face
constexpr float kBehindMaxRange = 3.0f;
// Behind-lights keep their spheres above the floor (y >= range) and below the wall top, so they
// light nothing the camera can see: no floor, no top face, no end faces.
constexpr float kBehindMaxHeight = kWallHeight - 0.15f;

// Front lights crowd into the part of the box the camera sees: with 1000 of them, ranges of
// 1-3 m put a visible point within range of about 30.
constexpr float kFrontMinRange = 1.0f;
constexpr float kFrontMaxRange = 3.0f;

bool insideViewAtAspectOne(const Camera& camera, const glm::vec3& pointWorld) {
    const glm::vec3 pointView = glm::vec3(camera.viewFromWorld() * glm::vec4(pointWorld, 1.0f));
    const float depth = -pointView.z;
    const float halfExtent = depth * std::tan(0.5f * camera.verticalFovRadians);
    return depth > camera.nearMetres && depth < camera.farMetres &&
           std::abs(pointView.x) <= halfExtent && std::abs(pointView.y) <= halfExtent;
}

// Appends `count` lights: the first `count` candidates of scatterPointLights(seed) that
// place(light) accepts (it may move them). Since the scatter's sequence does not depend on its
// count, the result does not depend on the batch sizes tried.
template <class Place>
void scatterAccepted(Scene& scene, const PointLightScatter& scatter, int count, uint64_t seed,
                     Place&& place) {
    if (count == 0)
        return;
    // The regions used here accept a third to two thirds of the candidates; the cap only turns
    // a broken layout into an error instead of a hang.
    const int64_t maxCandidates =
        std::min<int64_t>(64 * int64_t(count) + 4096, std::numeric_limits<int>::max());
    std::vector<Light> accepted;
    for (int64_t batch = 2 * int64_t(count) + 16;; batch = std::min(2 * batch, maxCandidates)) {
        Scene candidates;
        candidates.name = scene.name;
        scatterPointLights(candidates, scatter, int(batch), seed);
        accepted.clear();
        for (Light& light : candidates.lights) {
            if (place(light))
                accepted.push_back(light);
            if (int(accepted.size()) == count)
                break;
        }
        if (int(accepted.size()) == count)
            break;
        if (batch == maxCandidates)
            throw SceneError(scene.name + ": cannot place lights inside the camera's view");
    }
    scene.lights.insert(scene.lights.end(), accepted.begin(), accepted.end());
    scene.generatedLightCount += count;
}

// Clutter: street furniture that gives every light casters near it, so that a light's
// shadow-casting set is a small part of a scene of many objects (lighting/shadows/README.md).
// Each object is its own instance of one of five shared meshes, standing on the floor, turned by
// quarter turns (exact, so boxes stay axis-aligned). Heights and lengths 0.3-1.5 m.
constexpr float kClutterMaxHeight = 1.5f;
// Where clutter stands: behind the wall along its length (to 4.5 m behind it), in front along it
// (the 4 m band the front lights fill) and across the floor in front (to 12 m in front of the
// wall, past the camera); never within kClutterGap of the wall or of another object, nor within
// kClutterLightClearance of a light's centre, nor within kClutterCameraClearance of a camera's
// foot (an object there would hide most of its view).
constexpr float kClutterAlongMax = kWallHalfLength - 0.5f;
constexpr float kClutterBehindFar = -4.5f;
constexpr float kClutterFrontFar = 12.0f;
// Shares of the objects: behind the wall; in front along it (the band the front lights are in,
// so that they have casters near them too); the rest across the floor in front.
constexpr float kClutterBehindShare = 0.4f;
constexpr float kClutterAlongWallShare = 0.3f;
constexpr float kClutterAlongWallDepth = 4.0f;
constexpr float kClutterGap = 0.15f;
// How close a light's centre may come to an object (a light inside a crate would light nothing;
// the front lights crowd the band along the wall, so a wider clearance would empty it).
constexpr float kClutterLightClearance = 0.02f;
constexpr float kClutterCameraClearance = 3.0f;

void addWallClutter(Scene& scene, int count, uint64_t seed) {
    if (count == 0)
        return; // no materials or meshes either: the default scene is unchanged
    const uint32_t wood = addMaterial(scene, "clutter-wood", {0.52f, 0.38f, 0.22f}, 0.04f, 12.0f);
    const uint32_t metal = addMaterial(scene, "clutter-metal", {0.30f, 0.32f, 0.34f}, 0.4f, 96.0f);
    const uint32_t stone = addMaterial(scene, "clutter-stone", {0.62f, 0.60f, 0.56f}, 0.06f, 20.0f);

    std::vector<Aabb> footprints; // per mesh, object space
    auto addBoxMesh = [&](const char* name, uint32_t material, const Aabb& box) {
        appendBox(scene.meshes[addMesh(scene, name, material)], box, 0.5f);
        footprints.push_back(box);
    };
    addBoxMesh("crate-small", wood, Aabb{{-0.25f, 0.0f, -0.25f}, {0.25f, 0.5f, 0.25f}});
    addBoxMesh("crate-large", wood, Aabb{{-0.45f, 0.0f, -0.4f}, {0.45f, 0.8f, 0.4f}});
    // A bench: seat and backrest as one closed box (1.5 m long, 0.45 m deep, 0.9 m high).
    addBoxMesh("bench", wood, Aabb{{-0.75f, 0.0f, -0.225f}, {0.75f, 0.9f, 0.225f}});
    addBoxMesh("pillar", stone, Aabb{{-0.2f, 0.0f, -0.2f}, {0.2f, kClutterMaxHeight, 0.2f}});
    const uint32_t post = addMesh(scene, "post", metal);
    appendCylinder(scene.meshes[post], glm::vec3(0.0f), 0.06f, 1.2f, 12, 3);
    footprints.push_back(Aabb{{-0.06f, 0.0f, -0.06f}, {0.06f, 1.2f, 0.06f}});
    const uint32_t firstMesh = uint32_t(scene.meshes.size() - footprints.size());

    // Its own splitmix64 stream from the request's seed: the lights' streams stay untouched.
    SplitMix64Uniform uniform(seed ^ 0xC1A77E4C1A77E4ull);
    std::vector<Aabb> placed; // world bounds, grown by half the gap
    // Rejection sampling; the cap turns a layout too crowded to place into an error, not a hang.
    const int64_t maxCandidates = 200 * int64_t(count) + 1000;
    int64_t candidates = 0;
    while (int(placed.size()) < count) {
        if (++candidates > maxCandidates)
            throw SceneError(scene.name + ": cannot place " + std::to_string(count) +
                             " clutter objects without overlap");
        const uint32_t shape = std::min(uint32_t(uniform(0.0f, 5.0f)), 4u);
        const int quarterTurns = std::min(int(uniform(0.0f, 4.0f)), 3);
        const float side = uniform(0.0f, 1.0f);
        const float x = uniform(-kClutterAlongMax, kClutterAlongMax);
        const float z = side < kClutterBehindShare ? uniform(kClutterBehindFar, -kWallHalfThickness)
                        : side < kClutterBehindShare + kClutterAlongWallShare
                            ? uniform(kWallFaceZ, kWallFaceZ + kClutterAlongWallDepth)
                            : uniform(kWallFaceZ, kWallFaceZ + kClutterFrontFar);
        const glm::mat4 worldFromObject = placeTurnedY({x, 0.0f, z}, quarterTurns);
        Aabb bounds;
        for (int k = 0; k < 8; ++k) {
            const Aabb& f = footprints[shape];
            const glm::vec3 corner(k & 1 ? f.max.x : f.min.x, k & 2 ? f.max.y : f.min.y,
                                   k & 4 ? f.max.z : f.min.z);
            bounds.extend(glm::vec3(worldFromObject * glm::vec4(corner, 1.0f)));
        }
        const glm::vec3 halfGap(0.5f * kClutterGap, 0.0f, 0.5f * kClutterGap);
        bounds.min -= halfGap;
        bounds.max += halfGap;
        auto overlaps = [&](const Aabb& other) {
            return bounds.min.x < other.max.x && other.min.x < bounds.max.x &&
                   bounds.min.z < other.max.z && other.min.z < bounds.max.z;
        };
        const Aabb wallZone{
            {-kWallHalfLength, 0.0f, -kWallHalfThickness - 0.5f * kClutterGap},
            {kWallHalfLength, kWallHeight, kWallHalfThickness + 0.5f * kClutterGap}};
        if (overlaps(wallZone) || std::any_of(placed.begin(), placed.end(), overlaps))
            continue;
        const bool nearCamera =
            std::any_of(scene.cameras.begin(), scene.cameras.end(), [&](const Camera& camera) {
                const glm::vec2 toCamera(camera.positionWorld.x - x, camera.positionWorld.z - z);
                return glm::length(toCamera) < kClutterCameraClearance;
            });
        if (nearCamera)
            continue;
        const bool holdsLight =
            std::any_of(scene.lights.begin(), scene.lights.end(), [&](const Light& light) {
                const glm::vec3 p = light.positionWorld;
                const float c = kClutterLightClearance - 0.5f * kClutterGap;
                return p.x > bounds.min.x - c && p.x < bounds.max.x + c && p.z > bounds.min.z - c &&
                       p.z < bounds.max.z + c && p.y < bounds.max.y + kClutterLightClearance;
            });
        if (holdsLight)
            continue; // a light inside a crate lights nothing
        placed.push_back(bounds);
        addInstance(scene, firstMesh + shape, worldFromObject);
    }
}

Scene buildWall(const SceneRequest& request) {
    Scene scene;
    scene.name = "wall";
    const std::map<std::string, int> options =
        readOptions(scene.name, request, wallOptions(request.lightCount.value_or(0)));

    const uint32_t brick = addMaterial(scene, "wall-brick", {0.60f, 0.32f, 0.22f}, 0.05f, 16.0f);
    const uint32_t concrete =
        addMaterial(scene, "floor-concrete", {0.45f, 0.45f, 0.43f}, 0.08f, 32.0f);
    const uint32_t wall = addMesh(scene, "wall", brick);
    appendBox(scene.meshes[wall],
              Aabb{{-kWallHalfLength, 0.0f, -kWallHalfThickness},
                   {kWallHalfLength, kWallHeight, kWallHalfThickness}},
              0.4f);
    addInstance(scene, wall);
    const uint32_t floor = addMesh(scene, "floor", concrete);
    appendQuad(scene.meshes[floor], {-30.0f, 0.0f, 25.0f}, {60.0f, 0.0f, 0.0f},
               {0.0f, 0.0f, -45.0f}, 60, 45);
    addInstance(scene, floor);

    // 9 m from a point at mid-height on the visible face, at 45 degrees to it.
    const glm::vec3 target(0.0f, 2.5f, kWallFaceZ);
    const float away = 9.0f * float(std::numbers::sqrt2 / 2.0);
    scene.cameras.push_back(
        makeCamera("wall-45", target + glm::vec3(-away, 0.0f, away), target, 100.0f));
    const Camera& camera = scene.cameras[0];

    const int behindCount = options.at("behind");
    const int frontCount = request.lightCount.value_or(0) - behindCount;
    const float alongMin = -kWallHalfLength + 0.5f, alongMax = kWallHalfLength - 0.5f;

    PointLightScatter front;
    front.region.min = {alongMin, 0.3f, kWallFaceZ + 0.3f};
    front.region.max = {alongMax, kWallHeight - 0.3f, kWallFaceZ + 4.0f};
    front.minRangeMetres = kFrontMinRange;
    front.maxRangeMetres = kFrontMaxRange;
    front = scatterForDensity(front, request.lightDensity, frontCount);
    scatterAccepted(scene, front, frontCount, request.seed, [&](Light& light) {
        return insideViewAtAspectOne(camera, light.positionWorld);
    });

    // placeBehind: the scatter's y and z in [0,1] are uniform variates for the height and the
    // depth behind the face, which depend on each light's range.
    PointLightScatter behindScatter;
    behindScatter.region.min = {alongMin, 0.0f, 0.0f};
    behindScatter.region.max = {alongMax, 1.0f, 1.0f};
    behindScatter.minRangeMetres = kBehindMinRange;
    behindScatter.maxRangeMetres = kBehindMaxRange;
    behindScatter = scatterForDensity(behindScatter, request.lightDensity, behindCount);
    auto placeBehind = [&](Light& light) {
        const float range = light.rangeMetres;
        const float heightVariate = light.positionWorld.y, depthVariate = light.positionWorld.z;
        light.positionWorld.y = range + heightVariate * (kBehindMaxHeight - range);
        light.positionWorld.z =
            kWallFaceZ -
            range * (kBehindMinFraction + depthVariate * (kBehindMaxFraction - kBehindMinFraction));
        return insideViewAtAspectOne(camera, light.positionWorld);
    };
    // A different stream from the front lights', so that changing `behind` moves no front light
    // into the place of another.
    scatterAccepted(scene, behindScatter, behindCount, request.seed ^ 0x9E3779B97F4A7C15ull,
                    placeBehind);

    addAmbientAndSun(scene, options.at("ambient") == 1, options.at("sun") == 1);
    // More views (Viewpoints.h), added after the lights (which are placed in wall-45's view):
    // square-on, grazing along the face, and from behind (the side the "behind" lights are on).
    scene.cameras.push_back(
        makeCamera("wall-front", target + glm::vec3(0.0f, 0.0f, 9.0f), target, 100.0f));
    scene.cameras.push_back(
        makeCamera("wall-grazing", {-12.0f, 1.7f, 4.0f}, {6.0f, 2.5f, kWallFaceZ}, 100.0f));
    scene.cameras.push_back(makeCamera("wall-behind", {away, 2.5f, -kWallHalfThickness - away},
                                       {0.0f, 2.5f, -kWallHalfThickness}, 100.0f));
    // After the lights and cameras, which it keeps clear of.
    addWallClutter(scene, options.at("clutter"), request.seed);
    return scene;
}

// ---------------------------------------------------------------------------------------------
// spheres: analytic UV spheres of radii 0.25-1.4 m resting on a 24 m ground plane, from matte to
// mirror-like Blinn-Phong, seen from 9 m. Each sphere is its own mesh centred on its object
// origin and placed by a translation, so its object-space vertices lie exactly on the sphere.

struct SphereSpec {
    const char* name;
    float radiusMetres;
    float x, z;
    glm::vec3 albedo;
    float specularIntensity, specularPower;
};

constexpr SphereSpec kSpheres[] = {
    {"polished-red", 1.0f, -3.5f, 0.0f, {0.70f, 0.08f, 0.06f}, 0.50f, 256.0f},
    {"matte-white", 0.6f, -1.6f, 1.4f, {0.80f, 0.80f, 0.80f}, 0.02f, 2.0f},
    {"gold", 1.4f, 0.3f, -0.8f, {0.90f, 0.65f, 0.25f}, 0.90f, 1024.0f},
    {"blue-plastic", 0.4f, 1.5f, 1.8f, {0.10f, 0.20f, 0.70f}, 0.25f, 64.0f},
    {"green-matte", 0.8f, 3.0f, 0.4f, {0.15f, 0.50f, 0.15f}, 0.03f, 4.0f},
    {"chrome", 0.25f, 0.0f, 2.6f, {0.60f, 0.60f, 0.60f}, 0.95f, 4096.0f},
};

Scene buildSpheres(const SceneRequest& request) {
    Scene scene;
    scene.name = "spheres";
    const std::map<std::string, int> options =
        readOptions(scene.name, request, spheresOptions(request.lightCount.value_or(0)));
    const int longitudeCount = options.at("segments");

    const uint32_t ground =
        addMesh(scene, "ground", addMaterial(scene, "ground", {0.50f, 0.50f, 0.50f}, 0.04f, 16.0f));
    appendQuad(scene.meshes[ground], {-12.0f, 0.0f, 12.0f}, {24.0f, 0.0f, 0.0f},
               {0.0f, 0.0f, -24.0f}, 60, 60);
    addInstance(scene, ground);
    for (const SphereSpec& spec : kSpheres) {
        const std::string name = std::string("sphere-") + spec.name;
        const uint32_t material =
            addMaterial(scene, name, spec.albedo, spec.specularIntensity, spec.specularPower);
        const uint32_t mesh = addMesh(scene, name, material);
        appendUvSphere(scene.meshes[mesh], glm::vec3(0.0f), spec.radiusMetres, longitudeCount,
                       longitudeCount / 2);
        // Resting on the ground at y = 0.
        addInstance(scene, mesh,
                    glm::translate(glm::mat4(1.0f), {spec.x, spec.radiusMetres, spec.z}));
    }
    scene.cameras.push_back(makeCamera("front", {0.0f, 2.6f, 9.0f}, {0.0f, 0.8f, 0.0f}, 40.0f));

    PointLightScatter scatter;
    scatter.region.min = {-8.0f, 0.1f, -6.0f};
    scatter.region.max = {8.0f, 4.5f, 6.0f};
    scatter.minRangeMetres = 1.0f;
    scatter.maxRangeMetres = 3.0f;
    scatter.minIntensity = 0.3f;
    scatter.maxIntensity = 1.5f;
    scatterPointLights(scene, scatter, request.lightCount.value_or(0), request.seed);
    addAmbientAndSun(scene, options.at("ambient") == 1, options.at("sun") == 1);
    // More views (Viewpoints.h): from above, low from the side (grazing the ground), from behind.
    scene.cameras.push_back(makeCamera("above", {0.0f, 9.0f, 4.5f}, {0.0f, 0.5f, 0.0f}, 40.0f));
    scene.cameras.push_back(makeCamera("low-side", {-8.5f, 0.6f, 1.5f}, {0.0f, 0.8f, 0.0f}, 40.0f));
    scene.cameras.push_back(makeCamera("back", {1.5f, 2.2f, -8.5f}, {0.0f, 0.8f, 0.0f}, 40.0f));
    return scene;
}

// ---------------------------------------------------------------------------------------------
// glass: the transparency test scene (glTF alphaMode, lighting/README.md "Transparency"). An
// opaque room corner (ground, back wall, a box) seen through:
// - a MASK fence (cut-out vertical stripes: a texture whose alpha alternates 1 and 0, cutoff 0.5);
// - a MASK "ghost" pane whose factor alpha 0.3 is below its cutoff: every stage sees through it;
// - three overlapping BLEND panes: a parallel pair at different depths (the front one's alpha
//   from a texture gradient, 0.2 at the left to 0.8 at the right) and a tilted one that cuts
//   through the second, where no per-object or per-triangle order is right everywhere (the
//   stages' sorting artefacts show against the reference's per-pixel sort there).
// The panes are tessellated (cells of ~0.25 m) so that per-triangle sorting has triangles to
// sort. All materials Blinn-Phong.

// A texture of width x height texels (sRGB colour, linear alpha) from a function of the texel.
template <class TexelFn>
int addTexture(Scene& scene, const std::string& name, int width, int height, TexelFn texel) {
    Texture texture;
    texture.name = name;
    texture.width = width;
    texture.height = height;
    texture.srgb = true;
    texture.rgba8.resize(size_t(width) * height * 4);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const glm::u8vec4 value = texel(x, y);
            for (int c = 0; c < 4; ++c)
                texture.rgba8[(size_t(y) * width + x) * 4 + size_t(c)] = value[c];
        }
    scene.textures.push_back(std::move(texture));
    return int(scene.textures.size() - 1);
}

Scene buildGlass(const SceneRequest& request) {
    Scene scene;
    scene.name = "glass";
    const std::map<std::string, int> options =
        readOptions(scene.name, request, glassOptions(request.lightCount.value_or(0)));

    auto addQuadMesh = [&](const std::string& name, uint32_t material, const glm::vec3& corner,
                           const glm::vec3& edgeU, const glm::vec3& edgeV) {
        const uint32_t mesh = addMesh(scene, name, material);
        const int cellsU = std::max(1, int(std::ceil(glm::length(edgeU) / 0.25f)));
        const int cellsV = std::max(1, int(std::ceil(glm::length(edgeV) / 0.25f)));
        appendQuad(scene.meshes[mesh], corner, edgeU, edgeV, cellsU, cellsV);
        addInstance(scene, mesh);
    };
    addQuadMesh("ground", addMaterial(scene, "ground", {0.5f, 0.5f, 0.5f}, 0.04f, 16.0f),
                {-6.0f, 0.0f, 6.0f}, {12.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -12.0f});
    addQuadMesh("back-wall", addMaterial(scene, "back-wall", {0.7f, 0.65f, 0.55f}, 0.04f, 8.0f),
                {-6.0f, 0.0f, -3.0f}, {12.0f, 0.0f, 0.0f}, {0.0f, 4.0f, 0.0f});
    const uint32_t box =
        addMesh(scene, "box", addMaterial(scene, "box", {0.3f, 0.5f, 0.7f}, 0.2f, 64.0f));
    appendBox(scene.meshes[box], Aabb{{-0.5f, 0.0f, -1.2f}, {0.5f, 1.0f, -0.2f}}, 0.25f);
    addInstance(scene, box);

    // The fence: 8 stripes across, alternately solid (alpha 1) and cut out (alpha 0).
    const uint32_t fence = addMaterial(scene, "fence", {1.0f, 1.0f, 1.0f}, 0.1f, 32.0f);
    scene.materials[fence].baseColorTexture =
        addTexture(scene, "fence-stripes", 8, 2,
                   [](int x, int) { return glm::u8vec4(150, 110, 70, x % 2 == 0 ? 255 : 0); });
    scene.materials[fence].alphaMode = AlphaMode::Mask;
    addQuadMesh("fence", fence, {-4.0f, 0.0f, -1.5f}, {3.0f, 0.0f, 0.0f}, {0.0f, 2.5f, 0.0f});
    const uint32_t ghost = addMaterial(scene, "ghost", {0.9f, 0.9f, 0.9f}, 0.5f, 64.0f);
    scene.materials[ghost].baseColorFactor.a = 0.3f;
    scene.materials[ghost].alphaMode = AlphaMode::Mask;
    addQuadMesh("ghost", ghost, {1.5f, 0.0f, -0.5f}, {2.5f, 0.0f, 0.0f}, {0.0f, 2.5f, 0.0f});

    auto addPane = [&](const std::string& name, const glm::vec3& tint, float alpha) {
        const uint32_t material = addMaterial(scene, name, tint, 0.3f, 128.0f);
        scene.materials[material].baseColorFactor.a = alpha;
        scene.materials[material].alphaMode =
            options.at("opaque_panes") == 1 ? AlphaMode::Opaque : AlphaMode::Blend;
        return material;
    };
    const uint32_t red = addPane("glass-red", {0.9f, 0.25f, 0.2f}, 1.0f);
    scene.materials[red].baseColorTexture =
        addTexture(scene, "alpha-gradient", 16, 1, [](int x, int) {
            return glm::u8vec4(255, 255, 255, uint8_t(51 + x * 153 / 15));
        });
    addQuadMesh("glass-red", red, {-2.5f, 0.3f, 0.5f}, {3.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f});
    addQuadMesh("glass-blue", addPane("glass-blue", {0.2f, 0.3f, 0.9f}, 0.5f), {-1.0f, 0.6f, 1.2f},
                {3.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f});
    addQuadMesh("glass-green", addPane("glass-green", {0.2f, 0.85f, 0.3f}, 0.55f),
                {0.2f, 0.2f, 0.4f}, {2.5f, 0.0f, 2.0f}, {0.0f, 2.2f, 0.0f});

    scene.cameras.push_back(makeCamera("front", {0.3f, 1.7f, 6.5f}, {0.0f, 1.1f, 0.0f}, 40.0f));
    PointLightScatter scatter;
    scatter.region.min = {-5.0f, 0.1f, -2.8f};
    scatter.region.max = {5.0f, 3.5f, 3.5f};
    scatter.minRangeMetres = 1.5f;
    scatter.maxRangeMetres = 4.0f;
    scatter.minIntensity = 0.3f;
    scatter.maxIntensity = 1.5f;
    scatterPointLights(scene, scatter, request.lightCount.value_or(0), request.seed);
    addAmbientAndSun(scene, options.at("ambient") == 1, options.at("sun") == 1);
    scene.cameras.push_back(makeCamera("side", {4.5f, 1.5f, 4.5f}, {0.0f, 1.1f, 0.0f}, 40.0f));
    return scene;
}

// ---------------------------------------------------------------------------------------------
// foliage: alpha-masked leaf cards, the anti-aliasing hard case "alpha-masked foliage" (issue 28)
// and the scene alpha-to-coverage is measured on (raster/AlphaToCoverage.h). Twelve MASK cards
// (cutoff 0.5) of 2 m x 2 m stand in three rows 4.5 to 9 m from the `front` camera, turned up to
// +-25 degrees about +Y, all facing it (front faces: the draws cull back faces), before an opaque
// ground and back wall. Their texture is 256 x 256 texels of leaves (ellipses 6..16 texels wide,
// 24..48 long) whose alpha falls from 1 to 0 over one texel at the leaf outline, as an authored
// cut-out texture does: at 1280 x 720 a card spans about 170..310 pixels, so a texel is about a
// pixel and a leaf a few pixels wide, where the per-pixel alpha test aliases and the alpha ramp is
// about a pixel (what alpha-to-coverage turns into coverage). Blinn-Phong materials.
std::vector<SceneOption> foliageOptions(int) {
    return withAmbientAndSun({}, 1);
}

Scene buildFoliage(const SceneRequest& request) {
    Scene scene;
    scene.name = "foliage";
    const std::map<std::string, int> options =
        readOptions(scene.name, request, foliageOptions(request.lightCount.value_or(0)));
    // A fixed splitmix64 stream: the scene never depends on the request's seed (the lights do).
    SplitMix64Uniform uniform(0xf011a6eULL);

    auto addQuadMesh = [&](const std::string& name, uint32_t material, const glm::vec3& corner,
                           const glm::vec3& edgeU, const glm::vec3& edgeV, int cells) {
        const uint32_t mesh = addMesh(scene, name, material);
        appendQuad(scene.meshes[mesh], corner, edgeU, edgeV, cells, cells);
        addInstance(scene, mesh);
    };
    addQuadMesh("ground", addMaterial(scene, "ground", {0.45f, 0.4f, 0.32f}, 0.04f, 16.0f),
                {-8.0f, 0.0f, 6.0f}, {16.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -12.0f}, 16);
    addQuadMesh("back-wall", addMaterial(scene, "back-wall", {0.75f, 0.72f, 0.65f}, 0.04f, 8.0f),
                {-8.0f, 0.0f, -6.0f}, {16.0f, 0.0f, 0.0f}, {0.0f, 6.0f, 0.0f}, 8);

    // The leaf texture: each texel takes the alpha and colour of the leaf whose outline it is
    // deepest inside; alpha = clamp(0.5 - distance outside the ellipse in texels, 0, 1).
    struct Leaf {
        glm::vec2 centre, axis; // texels; axis = unit direction of the long semi-axis
        float length, width;    // semi-axes, texels
        glm::u8vec3 colour;     // sRGB
    };
    constexpr int kTexels = 256;
    std::vector<Leaf> leaves;
    for (int i = 0; i < 70; ++i) {
        Leaf leaf;
        leaf.length = uniform(12.0f, 24.0f);
        leaf.width = uniform(3.0f, 8.0f);
        const float margin = leaf.length + 2.0f;
        leaf.centre = {uniform(margin, kTexels - margin), uniform(margin, kTexels - margin)};
        const float angle = uniform(0.0f, float(std::numbers::pi));
        leaf.axis = {std::cos(angle), std::sin(angle)};
        leaf.colour = {uint8_t(uniform(40.0f, 90.0f)), uint8_t(uniform(100.0f, 160.0f)),
                       uint8_t(uniform(25.0f, 60.0f))};
        leaves.push_back(leaf);
    }
    const int leafTexture = addTexture(scene, "leaves", kTexels, kTexels, [&](int x, int y) {
        const glm::vec2 p(float(x) + 0.5f, float(y) + 0.5f);
        float best = -1.0f;
        glm::u8vec3 colour(60, 120, 40);
        for (const Leaf& leaf : leaves) {
            const glm::vec2 d = p - leaf.centre;
            const float along = glm::dot(d, leaf.axis) / leaf.length;
            const float across = (d.x * -leaf.axis.y + d.y * leaf.axis.x) / leaf.width;
            // Distance outside the outline, in texels, to first order (the radial excess scaled
            // by the semi-axis it runs along the most).
            const float radial = std::sqrt(along * along + across * across);
            const float outside =
                (radial - 1.0f) * (std::abs(across) > std::abs(along) ? leaf.width : leaf.length);
            const float alpha = std::clamp(0.5f - outside, 0.0f, 1.0f);
            if (alpha > best) {
                best = alpha;
                colour = leaf.colour;
            }
        }
        return glm::u8vec4(colour, uint8_t(std::lround(best * 255.0f)));
    });
    const uint32_t leavesMaterial = addMaterial(scene, "leaves", {1.0f, 1.0f, 1.0f}, 0.1f, 24.0f);
    scene.materials[leavesMaterial].baseColorTexture = leafTexture;
    scene.materials[leavesMaterial].alphaMode = AlphaMode::Mask;

    // Three rows of four cards, back to front; each card's lower-left corner, its turn about +Y
    // (its front, +Z when unturned, stays towards the camera).
    constexpr float kCardMetres = 2.0f;
    int card = 0;
    for (int row = 0; row < 3; ++row) {
        const float z = -2.5f + 1.5f * float(row);
        for (int column = 0; column < 4; ++column) {
            const float x = -5.0f + 2.6f * float(column) + uniform(-0.4f, 0.4f) + 0.8f * row;
            const float turn = uniform(-0.44f, 0.44f); // radians, about +-25 degrees
            const glm::vec3 edgeU = kCardMetres * glm::vec3(std::cos(turn), 0.0f, -std::sin(turn));
            const glm::vec3 corner(x, uniform(0.0f, 0.6f), z + uniform(-0.3f, 0.3f));
            addQuadMesh("card-" + std::to_string(card++), leavesMaterial, corner, edgeU,
                        {0.0f, kCardMetres, 0.0f}, 1);
        }
    }

    scene.cameras.push_back(makeCamera("front", {0.0f, 1.6f, 4.5f}, {0.0f, 1.2f, -2.0f}, 40.0f));
    PointLightScatter scatter;
    scatter.region.min = {-6.0f, 0.2f, -5.0f};
    scatter.region.max = {6.0f, 4.0f, 3.5f};
    scatter.minRangeMetres = 1.5f;
    scatter.maxRangeMetres = 4.0f;
    scatter.minIntensity = 0.3f;
    scatter.maxIntensity = 1.5f;
    scatterPointLights(scene, scatter, request.lightCount.value_or(0), request.seed);
    addAmbientAndSun(scene, options.at("ambient") == 1, options.at("sun") == 1);
    scene.cameras.push_back(makeCamera("side", {4.5f, 1.8f, 3.5f}, {0.0f, 1.0f, -2.0f}, 40.0f));
    return scene;
}

// ---------------------------------------------------------------------------------------------
// Registry

struct ProceduralScene {
    std::string_view name;
    Scene (*build)(const SceneRequest&);
    std::vector<SceneOption> (*options)(int lightCount);
};

constexpr ProceduralScene kProceduralScenes[] = {
    {"atrium", buildAtrium, atriumOptions},    {"wall", buildWall, wallOptions},
    {"spheres", buildSpheres, spheresOptions}, {"glass", buildGlass, glassOptions},
    {"foliage", buildFoliage, foliageOptions},
};
static_assert(kProceduralScenes[0].name == kDefaultSceneName, "the default scene comes first");

} // namespace

std::vector<std::string> proceduralSceneNames() {
    std::vector<std::string> names;
    for (const ProceduralScene& scene : kProceduralScenes)
        names.emplace_back(scene.name);
    return names;
}

bool isProceduralScene(const std::string& name) {
    return std::any_of(std::begin(kProceduralScenes), std::end(kProceduralScenes),
                       [&](const ProceduralScene& scene) { return scene.name == name; });
}

std::vector<SceneOption> proceduralSceneOptions(const std::string& name, int lightCount) {
    for (const ProceduralScene& entry : kProceduralScenes)
        if (entry.name == name)
            return entry.options(lightCount);
    throw SceneError("unknown procedural scene '" + name + "'");
}

Scene buildProceduralScene(const std::string& name, const SceneRequest& request) {
    for (const ProceduralScene& entry : kProceduralScenes) {
        if (entry.name != name)
            continue;
        if (request.lightCount.value_or(0) < 0)
            throw SceneError(name + ": light count must be >= 0, got " +
                             std::to_string(*request.lightCount));
        Scene scene = entry.build(request);
        validate(scene);
        return scene;
    }
    std::string valid;
    for (const std::string& known : proceduralSceneNames())
        valid += (valid.empty() ? "" : ", ") + known;
    throw SceneError("unknown procedural scene '" + name + "'; valid names: " + valid);
}

} // namespace scenes
