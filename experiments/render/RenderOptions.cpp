#include "experiments/render/RenderOptions.h"

#include "experiments/render/MemoryEstimate.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>

#include "gbuffer/msaa/FragmentLayers.h"
#include "lighting/StageRegistry.h"
#include "lighting/SupersampledReference.h"
#include "raster/Rasterizer.h"
#include "scenes/input/ClosestName.h"
#include "scenes/input/WholeFile.h"
#include "scenes/procedural/LightGenerator.h"
#include "scenes/procedural/ProceduralScenes.h"

namespace experiments {

namespace {

std::string joined(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names)
        text += (text.empty() ? "" : ", ") + name;
    return text;
}

template <typename Number> Number parseNumber(const std::string& key, const std::string& value) {
    Number number{};
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (error != std::errc() || end != value.data() + value.size())
        throw UsageError("option '" + key + "': '" + value + "' is not a valid number");
    return number;
}

void checkSizes(const RenderOptions& options) {
    if (options.width <= 0 || options.height <= 0 || options.width > kMaxImageSide ||
        options.height > kMaxImageSide ||
        uint64_t(options.width) * uint64_t(options.height) > kMaxPixels)
        throw UsageError("image size " + std::to_string(options.width) + "x" +
                         std::to_string(options.height) + " refused: each side must be 1.." +
                         std::to_string(kMaxImageSide) + " and at most " +
                         std::to_string(kMaxPixels) + " pixels in all");
    if (options.lights && (*options.lights < 0 || *options.lights > kMaxLights))
        throw UsageError("--lights " + std::to_string(*options.lights) + " refused: must be 0.." +
                         std::to_string(kMaxLights));
    if (options.threads < 0 || options.threads > kMaxThreads)
        throw UsageError("--threads " + std::to_string(options.threads) +
                         " refused: must be 0 (all) .. " + std::to_string(kMaxThreads));
}

void checkScene(const std::string& scene) {
    if (scenes::isProceduralScene(scene))
        return;
    const std::filesystem::path path(scene);
    const std::string extension = path.extension().string();
    if (extension != ".gltf" && extension != ".glb" && extension != ".json")
        throw UsageError("unknown scene '" + scene + "'" +
                         scenes::didYouMean(scene, scenes::proceduralSceneNames()) +
                         ": not a built-in scene (" + joined(scenes::proceduralSceneNames()) +
                         ") nor a .gltf/.glb/.json file");
    // A FIFO or device would block or never end in the loader: refused here with its kind.
    if (const std::string problem = scenes::regularFileProblem(path); !problem.empty())
        throw UsageError("scene file '" + scene + "' " +
                         (problem == "file not found" ? "not found" : problem));
}

void checkRepetitions(const RenderOptions& options) {
    if (options.warmup < 0 || options.warmup > kMaxRepetitions || options.repetitions < 1 ||
        options.repetitions > kMaxRepetitions)
        throw UsageError("--warmup " + std::to_string(options.warmup) + " / --repetitions " +
                         std::to_string(options.repetitions) + " refused: warmup 0.." +
                         std::to_string(kMaxRepetitions) + ", repetitions 1.." +
                         std::to_string(kMaxRepetitions));
}

// The G-buffer names of the options parsed (throws UsageError for bad encodings, formats or
// presets).
gbuffer::LayoutRequest layoutRequest(const RenderOptions& options) {
    return usageErrorFrom([&] {
        gbuffer::LayoutRequest request;
        if (!options.layout.empty()) {
            const std::vector<std::string> presets = gbuffer::layoutPresetNames();
            if (std::find(presets.begin(), presets.end(), options.layout) == presets.end())
                throw UsageError("unknown G-buffer layout '" + options.layout +
                                 "'; valid: " + joined(presets));
            request.preset = options.layout;
        }
        if (!options.normals.empty())
            request.normals = gbuffer::NormalCodecSpec::parse(options.normals);
        if (!options.depth.empty())
            request.depth = gbuffer::DepthFormatSpec::parse(options.depth);
        if (!options.position.empty())
            request.position = gbuffer::parsePositionMethod(options.position);
        if (!options.normalSpace.empty())
            request.normalSpace = gbuffer::parseNormalSpace(options.normalSpace);
        return request;
    });
}

} // namespace

CheckedOptions checkOptions(const RenderOptions& options) {
    checkSizes(options);
    CheckedOptions checked;
    checked.stage = lighting::makeStage(options.stage); // throws StageError listing valid names
    checkScene(options.scene);
    checkRepetitions(options);
    checked.layoutRequest = layoutRequest(options);
    checked.isa = usageErrorFrom([&] { return lighting::kernel::KernelIsa::byName(options.isa); });
    if (options.simtWarp != 32 && options.simtWarp != 64)
        throw UsageError("--simt-warp " + std::to_string(options.simtWarp) +
                         " refused: must be 32 (8x4 pixels) or 64 (8x8)");
    if (!raster::isRasterSampleCount(options.msaa))
        throw UsageError("--msaa " + std::to_string(options.msaa) +
                         " refused: samples per pixel must be 1, 2, 4 or 8");
    gbuffer::ComplexDetection detection;
    if (!gbuffer::parseComplexDetection(options.complexDetect, detection))
        throw UsageError("--complex-detect '" + options.complexDetect +
                         "' refused: must be primitive or discontinuity");
    if (options.alphaToCoverage != "on" && options.alphaToCoverage != "off")
        throw UsageError("--alpha-to-coverage '" + options.alphaToCoverage +
                         "' refused: must be on or off");
    if (options.alphaToCoverage == "on" && options.msaa == 1)
        throw UsageError("--alpha-to-coverage on refused with --msaa 1: one sample per pixel has "
                         "no coverage to dither; alpha-masked materials are alpha-tested at 1x "
                         "(use --msaa 2, 4 or 8)");
    if (options.msaa > 1) {
        const std::string stageName = lighting::StageSpec::parse(options.stage).name;
        for (const lighting::StageInfo& info : lighting::stageInfos())
            if (info.name == stageName && !info.msaaRefusal.empty())
                throw UsageError("--msaa " + std::to_string(options.msaa) + " refused for stage " +
                                 stageName + ": " + info.msaaRefusal);
    }
    if (const std::string problem = lighting::referenceSppProblem(options.referenceSpp);
        !problem.empty())
        throw UsageError("--reference-spp " + std::to_string(options.referenceSpp) +
                         " refused: " + problem);
    if (options.brdf != "auto")
        usageErrorFrom([&] { return scenes::parseMaterialModel(options.brdf); });
    try {
        checked.postAa = lighting::postaa::parsePostAa(options.postAa);
    } catch (const std::invalid_argument& error) {
        throw UsageError(std::string("option 'post-aa': ") + error.what());
    }
    checked.shadows = shadowSettings(options);
    if (options.oracle != "unshadowed" && options.oracle != "visibility")
        throw UsageError("--oracle '" + options.oracle +
                         "' refused: must be unshadowed or visibility");
    if (options.oracle == "visibility" && options.msaa > 1)
        throw UsageError("--oracle visibility refused with --msaa " + std::to_string(options.msaa) +
                         ": the occlusion-aware oracle counts the one-sample G-buffer only");
    return checked;
}

std::optional<lighting::ShadowSettings> shadowSettings(const RenderOptions& options) {
    if (options.shadows == "off")
        return std::nullopt;
    if (options.shadows != "maps")
        throw UsageError("--shadows '" + options.shadows + "' refused: must be off or maps");
    lighting::ShadowSettings settings;
    if (options.shadowMapSize < 16 || options.shadowMapSize > 8192)
        throw UsageError("--shadow-map-size " + std::to_string(options.shadowMapSize) +
                         " refused: must be 16..8192 texels (a cube map of 8192^2 faces is "
                         "1.5 GB)");
    settings.mapSize = options.shadowMapSize;
    if (!options.shadowBias.empty()) {
        const size_t comma = options.shadowBias.find(',');
        const std::string constant = options.shadowBias.substr(0, comma);
        const std::string slope =
            comma == std::string::npos ? std::string() : options.shadowBias.substr(comma + 1);
        try {
            size_t used = 0, usedSlope = 0;
            settings.biasConstant = std::stof(constant, &used);
            settings.biasSlope = std::stof(slope, &usedSlope);
            if (used != constant.size() || usedSlope != slope.size())
                throw std::invalid_argument("trailing text");
        } catch (const std::exception&) {
            throw UsageError("--shadow-bias '" + options.shadowBias +
                             "' refused: must be CONSTANT,SLOPE (metres, texels), e.g. 0.005,1.5");
        }
        if (!std::isfinite(settings.biasConstant) || !std::isfinite(settings.biasSlope) ||
            settings.biasConstant < 0.0f || settings.biasSlope < 0.0f ||
            settings.biasConstant > 100.0f || settings.biasSlope > 100.0f)
            throw UsageError("--shadow-bias '" + options.shadowBias +
                             "' refused: both parts must be finite, 0..100");
    }
    const std::optional<lighting::ShadowFilter> filter =
        lighting::parseShadowFilter(options.shadowFilter);
    if (!filter)
        throw UsageError("--shadow-filter '" + options.shadowFilter + "' refused: must be " +
                         lighting::kShadowFilterNames);
    settings.filter = *filter;
    const std::optional<lighting::ShadowPointProjection> point =
        lighting::parseShadowPointProjection(options.shadowPoint);
    if (!point)
        throw UsageError("--shadow-point '" + options.shadowPoint + "' refused: must be " +
                         lighting::kShadowPointProjectionNames);
    settings.pointProjection = *point;
    const std::optional<lighting::ShadowDepthFormat> depthFormat =
        lighting::parseShadowDepthFormat(options.shadowDepthFormat);
    if (!depthFormat)
        throw UsageError("--shadow-depth-format '" + options.shadowDepthFormat +
                         "' refused: must be " + lighting::kShadowDepthFormatNames);
    settings.depthFormat = *depthFormat;
    if (options.shadowLights != "all") {
        const int count = parseNumber<int>("shadow-lights", options.shadowLights);
        if (count < 0)
            throw UsageError("--shadow-lights " + options.shadowLights +
                             " refused: must be all or a count >= 0");
        settings.maxShadowLights = count;
    }
    if (options.shadowCascades < 1 || options.shadowCascades > 8)
        throw UsageError("--shadow-cascades " + std::to_string(options.shadowCascades) +
                         " refused: must be 1..8");
    settings.cascades = options.shadowCascades;
    if (options.shadowCasterSets != "on" && options.shadowCasterSets != "off")
        throw UsageError("--shadow-caster-sets '" + options.shadowCasterSets +
                         "' refused: must be on or off");
    settings.casterSets = options.shadowCasterSets == "on";
    return settings;
}

void validate(const RenderOptions& options) {
    checkOptions(options);
}

bool isJsonSceneFile(const std::string& scene) {
    std::string extension = std::filesystem::path(scene).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return !scenes::isProceduralScene(scene) && extension == ".json";
}

std::optional<int> requestedLights(const RenderOptions& options) {
    if (options.lights)
        return options.lights;
    if (isJsonSceneFile(options.scene))
        return std::nullopt;
    return kDefaultLights;
}

std::string lightsText(const RenderOptions& options) {
    const std::optional<int> lights = requestedLights(options);
    return lights ? std::to_string(*lights) : "file";
}

std::vector<std::string> renderOptionKeys() {
    return {"scene",
            "stage",
            "lights",
            "seed",
            "light-density",
            "width",
            "height",
            "resolution",
            "threads",
            "isa",
            "simt-warp",
            "reference-spp",
            "msaa",
            "complex-detect",
            "alpha-to-coverage",
            "layout",
            "normals",
            "normal-space",
            "depth",
            "position",
            "view",
            "brdf",
            "post-aa",
            "oracle",
            "shadows",
            "shadow-map-size",
            "shadow-bias",
            "shadow-filter",
            "shadow-point",
            "shadow-depth-format",
            "shadow-lights",
            "shadow-cascades",
            "shadow-caster-sets",
            "max-memory",
            "scene-option.<key>"};
}

void setRenderOption(RenderOptions& options, const std::string& key, const std::string& value) {
    static const std::string kSceneOption = "scene-option.";
    if (key == "scene")
        options.scene = value;
    else if (key == "stage")
        options.stage = value;
    else if (key == "view")
        options.view = value;
    else if (key == "lights")
        options.lights = parseNumber<int>(key, value);
    else if (key == "seed")
        options.seed = parseNumber<uint64_t>(key, value);
    else if (key == "light-density") {
        try {
            options.lightDensity = scenes::parseLightDensity(value);
        } catch (const scenes::SceneError& error) {
            throw UsageError(std::string("option 'light-density': ") + error.what());
        }
    } else if (key == "width")
        options.width = parseNumber<int>(key, value);
    else if (key == "height")
        options.height = parseNumber<int>(key, value);
    else if (key == "threads")
        options.threads = parseNumber<int>(key, value);
    else if (key == "isa")
        options.isa = value;
    else if (key == "simt-warp")
        options.simtWarp = parseNumber<int>(key, value);
    else if (key == "msaa")
        options.msaa = parseNumber<int>(key, value);
    else if (key == "complex-detect")
        options.complexDetect = value;
    else if (key == "alpha-to-coverage")
        options.alphaToCoverage = value;
    else if (key == "reference-spp")
        options.referenceSpp = parseNumber<int>(key, value);
    else if (key == "layout")
        options.layout = value;
    else if (key == "normals")
        options.normals = value;
    else if (key == "normal-space")
        options.normalSpace = value;
    else if (key == "depth")
        options.depth = value;
    else if (key == "position")
        options.position = value;
    else if (key == "brdf")
        options.brdf = value;
    else if (key == "post-aa")
        options.postAa = value;
    else if (key == "oracle")
        options.oracle = value;
    else if (key == "shadows")
        options.shadows = value;
    else if (key == "shadow-map-size")
        options.shadowMapSize = parseNumber<int>(key, value);
    else if (key == "shadow-bias")
        options.shadowBias = value;
    else if (key == "shadow-filter")
        options.shadowFilter = value;
    else if (key == "shadow-point")
        options.shadowPoint = value;
    else if (key == "shadow-depth-format")
        options.shadowDepthFormat = value;
    else if (key == "shadow-lights")
        options.shadowLights = value;
    else if (key == "shadow-cascades")
        options.shadowCascades = parseNumber<int>(key, value);
    else if (key == "shadow-caster-sets")
        options.shadowCasterSets = value;
    else if (key == "max-memory")
        options.maxMemoryBytes = parseByteSize(value, "option 'max-memory'");
    else if (key == "resolution") {
        const size_t x = value.find('x');
        if (x == std::string::npos)
            throw UsageError("option 'resolution': '" + value + "' is not WIDTHxHEIGHT");
        options.width = parseNumber<int>(key, value.substr(0, x));
        options.height = parseNumber<int>(key, value.substr(x + 1));
    } else if (key.rfind(kSceneOption, 0) == 0 && key.size() > kSceneOption.size()) {
        options.sceneOptions[key.substr(kSceneOption.size())] = value;
    } else {
        throw UsageError("unknown render option '" + key +
                         "'; valid: " + joined(renderOptionKeys()));
    }
}

} // namespace experiments
