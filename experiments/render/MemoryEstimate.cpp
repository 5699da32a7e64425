// A render's peak memory estimated before allocating; see MemoryEstimate.h for the terms.
#include "experiments/render/MemoryEstimate.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <sys/resource.h>
#include <unistd.h>

#include "experiments/render/RenderPlan.h"
#include "lighting/SupersampledReference.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace experiments {

namespace {

// Per-pixel figures, bytes (measured with ru_maxrss; see MemoryEstimate.h and the README).
// The stage's result (12 RGB + 8 light counts + 1), the rasterizer's depth and visibility, the
// stage's scratch and the outputs (28 decoded layers, 12 count planes, PNG canvases, EXR rows):
// brute, tiled and clustered peak within 4% of each other at 2048^2.
constexpr double kFrameBytesPerPixel = 88.0;
// MSAA: per sample, depth, centre depth and visibility (RenderCommand's explanation), and per
// layer above the first the layer's shading scratch.
constexpr double kMultisampleBytesPerSample = 12.0;
constexpr double kMultisampleBytesPerExtraLayer = 31.0;
// The exact surface (double position and normal, material inputs).
constexpr double kExactSurfaceBytesPerPixel = 96.0;
// --compare-reference: the reference frame and image, error and FLIP planes: 148 bytes per pixel
// measured at 1 sample per pixel, 227 supersampled (double accumulation and a jittered frame).
constexpr double kReferenceBytesPerPixel = 148.0;
constexpr double kSupersampledReferenceBytesPerPixel = 227.0;
constexpr double kPostAaBytesPerPixel = 16.0;
// Per drawn vertex: world position (float and double), normal, uv (SceneGeometry); uv1 and
// tangents when the scene has them. Per drawn triangle: 12 bytes of indices and the rasterizer's
// set-up data (scenes/input/Limits.h kBytesPerDrawnTriangle).
constexpr double kGeometryBytesPerVertex = 56.0;
constexpr double kGeometryBytesPerTriangle = 12.0 + double(scenes::limits::kBytesPerDrawnTriangle);
// Embree's BVH: ~90 bytes a triangle (lighting/shadows/RayVisibility.h, measured).
constexpr double kRayBytesPerTriangle = 90.0;
// Per light: the view-space copy and its share of culling lists.
constexpr double kBytesPerLight = 256.0;

std::string trimmedNumber(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", value);
    return text;
}

double sceneBytes(const scenes::Scene& scene) {
    double bytes = 0.0;
    for (const scenes::Mesh& mesh : scene.meshes)
        bytes += double(mesh.positions.size()) * sizeof(glm::vec3) +
                 double(mesh.normals.size()) * sizeof(glm::vec3) +
                 double(mesh.tangents.size()) * sizeof(glm::vec4) +
                 double(mesh.uvs.size()) * sizeof(glm::vec2) +
                 double(mesh.uvs1.size()) * sizeof(glm::vec2) +
                 double(mesh.indices.size()) * sizeof(uint32_t);
    for (const scenes::Texture& texture : scene.textures)
        bytes += double(texture.rgba8.size());
    bytes += double(scene.instances.size()) * sizeof(scenes::Instance);
    bytes += double(scene.lights.size()) * sizeof(scenes::Light);
    bytes += double(scene.materials.size()) * sizeof(scenes::Material);
    return bytes;
}

// The shadow maps' bytes at most: the casting lights (ShadowMaps::chooseLights' rule) the budget
// allows, those with the most bytes (faces times their own map size squared) first.
double shadowMapBound(const scenes::Scene& scene, const lighting::ShadowSettings& settings) {
    const bool anyMarked = std::any_of(scene.lights.begin(), scene.lights.end(), [](const auto& l) {
        return l.castsShadows && l.type != scenes::LightType::Ambient;
    });
    std::vector<double> bytes;
    for (const scenes::Light& light : scene.lights) {
        if (light.type == scenes::LightType::Ambient || (anyMarked && !light.castsShadows))
            continue;
        const int pointFaces =
            settings.pointProjection == lighting::ShadowPointProjection::DualParaboloid ? 2 : 6;
        const int faces = light.type == scenes::LightType::Point         ? pointFaces
                          : light.type == scenes::LightType::Directional ? settings.cascades
                                                                         : 1;
        const double size = lighting::settingsForLight(settings, light.shadow).mapSize;
        bytes.push_back(double(faces) * size * size *
                        double(lighting::shadowBytesPerTexel(settings.depthFormat)));
    }
    std::sort(bytes.begin(), bytes.end(), std::greater<>());
    if (settings.maxShadowLights >= 0 && bytes.size() > size_t(settings.maxShadowLights))
        bytes.resize(size_t(settings.maxShadowLights));
    double total = 0.0;
    for (double lightBytes : bytes)
        total += lightBytes;
    return total;
}

} // namespace

double MemoryEstimate::totalBytes() const {
    double total = 0.0;
    for (const MemoryTerm& term : terms)
        total += term.bytes;
    return total;
}

std::string MemoryEstimate::explain() const {
    std::ostringstream out;
    out << "peak memory estimate: " << formatBytes(totalBytes()) << " (limit "
        << formatBytes(double(limitBytes)) << ", --max-memory"
        << (totalBytes() > double(limitBytes) ? "; OVER THE LIMIT: the render would be refused"
                                              : "")
        << ")\n";
    for (const MemoryTerm& term : terms)
        if (term.bytes > 0.0)
            out << "  " << term.name << ": " << formatBytes(term.bytes) << " (" << term.basis
                << ")\n";
    return out.str();
}

nlohmann::json MemoryEstimate::toJson() const {
    nlohmann::json termBytes = nlohmann::json::object();
    for (const MemoryTerm& term : terms)
        termBytes[term.name] = term.bytes;
    return {{"estimate_bytes", totalBytes()},
            {"limit_bytes", limitBytes},
            {"terms_bytes", termBytes},
            {"note", "peak resident memory estimated before allocating (experiments/render/"
                     "MemoryEstimate.h); measured_peak_rss_bytes is the process's ru_maxrss "
                     "when stats.json was written"}};
}

uint64_t physicalMemoryBytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long pageSize = ::sysconf(_SC_PAGE_SIZE);
    uint64_t bytes = pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
    // A container's limit (cgroup v2): "max" or a byte count.
    std::ifstream cgroup("/sys/fs/cgroup/memory.max");
    std::string text;
    if (cgroup >> text && !text.empty() &&
        std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); })) {
        const uint64_t limit = std::strtoull(text.c_str(), nullptr, 10);
        if (limit > 0 && (bytes == 0 || limit < bytes))
            bytes = limit;
    }
    return bytes > 0 ? bytes : uint64_t(8) << 30; // unknown: assume 8 GiB
}

uint64_t memoryLimitBytes(const RenderOptions& options) {
    if (options.maxMemoryBytes > 0)
        return options.maxMemoryBytes;
    return uint64_t(double(physicalMemoryBytes()) * kDefaultMaxMemoryFraction);
}

uint64_t parseByteSize(const std::string& text, const std::string& option) {
    auto refuse = [&] {
        return UsageError(option + " '" + text +
                          "' refused: expected bytes > 0 with an optional suffix K, M, G or T "
                          "(powers of 1024), e.g. 512M or 1.5G, at most 2^60");
    };
    size_t end = 0;
    while (end < text.size() &&
           (std::isdigit(static_cast<unsigned char>(text[end])) || (text[end] == '.' && end > 0)))
        ++end;
    if (end == 0 || end > 24)
        throw refuse();
    double value = 0.0;
    try {
        size_t used = 0;
        value = std::stod(text.substr(0, end), &used);
        if (used != end)
            throw refuse(); // "1.5.5"
    } catch (const std::exception&) {
        throw refuse();
    }
    std::string suffix = text.substr(end);
    std::transform(suffix.begin(), suffix.end(), suffix.begin(),
                   [](unsigned char c) { return char(std::toupper(c)); });
    double scale = 1.0;
    if (!suffix.empty() && suffix != "B") {
        const std::string units = "KMGT";
        const size_t unit = units.find(suffix[0]);
        const std::string rest = suffix.substr(1);
        if (unit == std::string::npos || (rest != "" && rest != "B" && rest != "IB"))
            throw refuse();
        scale = std::pow(1024.0, double(unit + 1));
    }
    const double bytes = std::floor(value * scale);
    if (!(bytes >= 1.0) || bytes > std::ldexp(1.0, 60))
        throw refuse();
    return uint64_t(bytes);
}

std::string formatBytes(double bytes) {
    const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    int unit = 0;
    while (bytes >= 1024.0 && unit < 4) {
        bytes /= 1024.0;
        ++unit;
    }
    char text[48];
    std::snprintf(text, sizeof text, unit == 0 ? "%.0f %s" : "%.2f %s", bytes, units[unit]);
    return text;
}

double sceneLoadBytes(const std::string& scene) {
    if (scenes::isProceduralScene(scene))
        return 0.0;
    std::error_code ec;
    const std::filesystem::path path(scene);
    const double size = double(std::filesystem::file_size(path, ec));
    if (ec)
        return 0.0; // the loader reports a missing file
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (extension != ".glb")
        return size * kSceneLoadBytesPerJsonByte;
    // GLB: 12-byte header, then the JSON chunk's length (little-endian) and type.
    unsigned char header[20] = {};
    std::ifstream file(path, std::ios::binary);
    if (!file.read(reinterpret_cast<char*>(header), sizeof header))
        return size * kSceneLoadBytesPerJsonByte;
    const double json = double(uint32_t(header[12]) | uint32_t(header[13]) << 8 |
                               uint32_t(header[14]) << 16 | uint32_t(header[15]) << 24);
    const double jsonBytes = std::min(json, size);
    return jsonBytes * kSceneLoadBytesPerJsonByte +
           (size - jsonBytes) * kSceneLoadBytesPerBinaryByte;
}

void checkSceneLoadMemory(const RenderOptions& options) {
    const double load = sceneLoadBytes(options.scene);
    const double total = double(kProcessBaselineBytes) + load;
    const uint64_t limit = memoryLimitBytes(options);
    if (total > double(limit))
        throw UsageError("loading scene file '" + options.scene + "' needs an estimated " +
                         formatBytes(total) + " (" + formatBytes(load) +
                         " to parse it), over the memory limit " + formatBytes(double(limit)) +
                         " (--max-memory)");
}

MemoryEstimate estimateRenderMemory(const RenderOptions& options, const scenes::Scene& scene,
                                    const gbuffer::GBufferLayout& layout,
                                    const lighting::StageRequirements& requirements) {
    MemoryEstimate estimate;
    estimate.limitBytes = memoryLimitBytes(options);
    const double pixels = double(options.width) * double(options.height);
    const std::string pixelText = trimmedNumber(pixels) + " pixels";
    auto add = [&](const std::string& name, double bytes, const std::string& basis) {
        estimate.terms.push_back({name, bytes, basis});
    };
    add("process", double(kProcessBaselineBytes), "binary, libraries, thread pools");
    add("scene", sceneBytes(scene),
        std::to_string(scene.meshes.size()) + " meshes, " + std::to_string(scene.textures.size()) +
            " textures, " + std::to_string(scene.instances.size()) + " instances");

    double drawnVertices = 0.0, drawnTriangles = 0.0;
    bool anyUv1 = false, anyTangents = false;
    for (const scenes::Instance& instance : scene.instances) {
        if (instance.mesh >= scene.meshes.size())
            continue;
        const scenes::Mesh& mesh = scene.meshes[instance.mesh];
        drawnVertices += double(mesh.positions.size());
        drawnTriangles += double(mesh.triangleCount());
        anyUv1 = anyUv1 || !mesh.uvs1.empty();
        anyTangents = anyTangents || !mesh.tangents.empty();
    }
    const double vertexBytes =
        kGeometryBytesPerVertex + (anyUv1 ? 8.0 : 0.0) + (anyTangents ? 16.0 : 0.0);
    add("geometry", drawnVertices * vertexBytes + drawnTriangles * kGeometryBytesPerTriangle,
        trimmedNumber(drawnVertices) + " drawn vertices x " + trimmedNumber(vertexBytes) + " + " +
            trimmedNumber(drawnTriangles) + " drawn triangles x " +
            trimmedNumber(kGeometryBytesPerTriangle));

    const int samples = std::max(1, options.msaa);
    const double allocated = layout.allocatedBytesPerPixel();
    add("gbuffer", pixels * allocated * samples,
        pixelText + " x " + trimmedNumber(allocated) + " bytes" +
            (samples > 1 ? " x " + std::to_string(samples) + " layers at most" : ""));
    if (samples > 1)
        add("msaa",
            pixels * (kMultisampleBytesPerSample * samples +
                      kMultisampleBytesPerExtraLayer * (samples - 1)),
            pixelText + " x (" + trimmedNumber(kMultisampleBytesPerSample) + " x " +
                std::to_string(samples) + " samples + " +
                trimmedNumber(kMultisampleBytesPerExtraLayer) + " x " +
                std::to_string(samples - 1) + " extra layers)");
    add("frame", pixels * kFrameBytesPerPixel,
        pixelText + " x " + trimmedNumber(kFrameBytesPerPixel) +
            " (stage result, raster buffers, scratch, output images)");
    if (requirements.exactSurface)
        add("exact_surface", pixels * kExactSurfaceBytesPerPixel,
            pixelText + " x " + trimmedNumber(kExactSurfaceBytesPerPixel));
    if (options.compareReference) {
        const double perPixel = options.referenceSpp > 1 ? kSupersampledReferenceBytesPerPixel
                                                         : kReferenceBytesPerPixel;
        add("reference", pixels * perPixel,
            pixelText + " x " + trimmedNumber(perPixel) + " (" +
                std::to_string(options.referenceSpp) + " spp reference, error and FLIP planes)");
    }
    if (options.postAa != "none")
        add("post_aa", pixels * kPostAaBytesPerPixel,
            pixelText + " x " + trimmedNumber(kPostAaBytesPerPixel));
    const std::optional<lighting::ShadowSettings> shadows = shadowSettings(options);
    if (shadows) {
        const int runs = options.warmup + options.repetitions;
        const double maps = shadowMapBound(scene, *shadows) * (runs > 1 ? 2.0 : 1.0);
        const size_t texelBytes = lighting::shadowBytesPerTexel(shadows->depthFormat);
        add("shadow_maps", maps,
            "casting lights' faces x " + std::to_string(shadows->mapSize) +
                "^2 (or the light's own size) x " + std::to_string(texelBytes) + " bytes" +
                (runs > 1 ? " x 2 (rendered again each run)" : ""));
        if (shadows->depthFormat == lighting::ShadowDepthFormat::Unorm16) {
            // Unorm16 faces are drawn in float, into one buffer per thread and map size.
            int largest = shadows->mapSize;
            for (const scenes::Light& light : scene.lights)
                largest =
                    std::max(largest, lighting::settingsForLight(*shadows, light.shadow).mapSize);
            const int threads = effectiveThreads(options.threads);
            add("shadow_draw_buffers",
                double(threads) * double(largest) * double(largest) * sizeof(float),
                std::to_string(threads) + " threads x " + std::to_string(largest) +
                    "^2 x 4 bytes (unorm16 faces drawn in float)");
        }
    }
    if ((shadows && options.compareReference) || options.oracle == "visibility")
        add("rays", drawnTriangles * kRayBytesPerTriangle,
            trimmedNumber(drawnTriangles) + " triangles x " + trimmedNumber(kRayBytesPerTriangle) +
                " (Embree BVH)");
    add("lights", double(scene.lights.size()) * kBytesPerLight,
        std::to_string(scene.lights.size()) + " lights x " + trimmedNumber(kBytesPerLight));
    // The scene file's parse peaks before the render starts, its document freed after: the peak
    // of the run is the larger of the two, so only the parse's excess over the render counts.
    const double parsePeak = sceneLoadBytes(options.scene);
    const double renderPeak = estimate.totalBytes() - double(kProcessBaselineBytes);
    if (parsePeak > renderPeak)
        add("scene_file_parse", parsePeak - renderPeak,
            "parsing the file peaks at " + formatBytes(parsePeak) +
                " above the process; its excess over the render's own peak");
    return estimate;
}

void checkMemoryEstimate(const MemoryEstimate& estimate) {
    const double total = estimate.totalBytes();
    if (total <= double(estimate.limitBytes))
        return;
    std::vector<MemoryTerm> largest = estimate.terms;
    std::sort(largest.begin(), largest.end(),
              [](const MemoryTerm& a, const MemoryTerm& b) { return a.bytes > b.bytes; });
    std::string terms;
    for (size_t i = 0; i < std::min<size_t>(2, largest.size()); ++i)
        terms += (i ? ", " : "") + largest[i].name + " " + formatBytes(largest[i].bytes);
    throw UsageError("the render needs an estimated " + formatBytes(total) +
                     " of memory at its peak (largest: " + terms + "), over the limit " +
                     formatBytes(double(estimate.limitBytes)) + " (--max-memory; default " +
                     trimmedNumber(kDefaultMaxMemoryFraction * 100.0) +
                     "% of the machine's memory); refused before allocating");
}

uint64_t peakResidentBytes() {
    rusage usage{};
    if (::getrusage(RUSAGE_SELF, &usage) != 0)
        return 0;
    return uint64_t(usage.ru_maxrss) * 1024; // Linux: kilobytes
}

bool resetPeakResident() {
    std::ofstream clearRefs("/proc/self/clear_refs");
    clearRefs << "5";
    clearRefs.flush();
    return bool(clearRefs);
}

} // namespace experiments
