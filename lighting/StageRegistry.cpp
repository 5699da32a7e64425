#include "lighting/StageRegistry.h"

#include <functional>

#include "lighting/stages/Stages.h"
#include "scenes/ClosestName.h"

namespace lighting {

namespace {

struct StageEntry {
    StageInfo info;
    std::function<std::unique_ptr<ShadingStage>(const StageSpec&)> make;
};

const std::vector<StageEntry>& registry() {
    static const std::vector<StageEntry> entries = {
        {{"reference", "every light at every pixel, double precision, exact surface",
          StageKind::Reference},
         makeReferenceStage},
        {{"brute", "every light at every pixel, float, from the G-buffer", StageKind::Exact},
         makeBruteStage},
        {{"ideal",
          "perfect culling, the ceiling of exact culling: each pixel shades exactly its "
          "contributing lights (lists made outside the timer)",
          StageKind::Exact},
         makeIdealStage},
        {{"deferred",
          "traditional deferred: one light volume per light, shaded and added per fragment "
          "(volume=sphere|rect, spot=cone|sphere, stencil=0, vfc=1)",
          StageKind::Exact},
         makeDeferredStage},
        {{"light-indexed",
          "light-indexed deferred: volumes write per-pixel light lists (max=16), "
          "overflow shades every light",
          StageKind::Exact},
         makeLightIndexedStage},
        {{"clustered",
          "implicit clusters: grid of screen tiles x depth slices (default 24x12x32, exp), "
          "lights assigned per cluster AABB",
          StageKind::Exact},
         makeClusteredStage},
        {{"tiled", "tiled deferred: per-tile depth-bounded frusta (tile=16, vfc=1, mask=0)",
          StageKind::Exact},
         makeTiledStage},
        {{"tiled-backface", "tiled deferred plus per-tile normal-cone back-face culling of lights",
          StageKind::Exact},
         makeTiledBackfaceStage},
        {{"forward", "single-pass forward, per-object light lists (prepass=0|1)", StageKind::Exact},
         makeForwardStage},
        {{"forward-multipass", "one additive pass per light over its illumination set",
          StageKind::Exact},
         makeForwardMultipassStage},
        {{"light-prepass",
          "Light Pre-Pass: thin G-buffer, diffuse RGB + monochrome specular light buffer, "
          "material pass (spec=grey|chroma, tile=16)",
          StageKind::Approximate},
         makeLightPrepassStage},
        {{"inferred",
          "inferred lighting: L-buffer at 1/scale resolution, DSF upsampling in the material "
          "pass (scale=2, depth=0.1, normal=0.9, tile=16)",
          StageKind::Approximate},
         makeInferredStage},
        {{"tiled-forward",
          "Forward+: depth pre-pass, per-tile light lists, forward shading (tile=16, vfc=1)",
          StageKind::Exact},
         makeTiledForwardStage},
    };
    return entries;
}

} // namespace

StageSpec StageSpec::parse(const std::string& text) {
    StageSpec spec;
    const size_t colon = text.find(':');
    spec.name = text.substr(0, colon);
    if (spec.name.empty())
        throw StageError("stage '" + text + "': empty name");
    if (colon == std::string::npos)
        return spec;
    const std::string options = text.substr(colon + 1);
    size_t begin = 0;
    while (begin <= options.size()) {
        const size_t end = std::min(options.find(',', begin), options.size());
        const std::string item = options.substr(begin, end - begin);
        const size_t equals = item.find('=');
        if (item.empty() || equals == std::string::npos || equals == 0)
            throw StageError("stage '" + text + "': option '" + item + "' is not key=value");
        if (!spec.options.emplace(item.substr(0, equals), item.substr(equals + 1)).second)
            throw StageError("stage '" + text + "': option '" + item.substr(0, equals) +
                             "' given twice");
        begin = end + 1;
    }
    return spec;
}

void rejectUnknownOptions(const StageSpec& spec, std::initializer_list<const char*> known) {
    for (const auto& [key, value] : spec.options) {
        bool found = false;
        std::string valid;
        for (const char* k : known) {
            found = found || key == k;
            valid += valid.empty() ? k : std::string(", ") + k;
        }
        if (!found)
            throw StageError("stage '" + spec.name + "': unknown option '" + key +
                             "' (valid: " + (valid.empty() ? "none" : valid) + ")");
    }
}

int intOption(const StageSpec& spec, const char* key, int defaultValue, int minValue,
              int maxValue) {
    const auto found = spec.options.find(key);
    if (found == spec.options.end())
        return defaultValue;
    size_t used = 0;
    int value = 0;
    try {
        value = std::stoi(found->second, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used != found->second.size() || found->second.empty() || value < minValue ||
        value > maxValue)
        throw StageError("stage '" + spec.name + "': option " + key + "=" + found->second +
                         " is not an integer in " + std::to_string(minValue) + ".." +
                         std::to_string(maxValue));
    return value;
}

bool boolOption(const StageSpec& spec, const char* key, bool defaultValue) {
    const auto found = spec.options.find(key);
    if (found == spec.options.end())
        return defaultValue;
    if (found->second == "1" || found->second == "on" || found->second == "true")
        return true;
    if (found->second == "0" || found->second == "off" || found->second == "false")
        return false;
    throw StageError("stage '" + spec.name + "': option " + key + "=" + found->second +
                     " is not a boolean (1/0, on/off, true/false)");
}

std::string choiceOption(const StageSpec& spec, const char* key,
                         const std::vector<std::string>& choices) {
    const auto found = spec.options.find(key);
    if (found == spec.options.end())
        return choices.front();
    std::string valid;
    for (const std::string& choice : choices) {
        if (choice == found->second)
            return choice;
        valid += (valid.empty() ? "" : ", ") + choice;
    }
    throw StageError("stage '" + spec.name + "': option " + key + "=" + found->second +
                     " is not one of " + valid);
}

std::vector<StageInfo> stageInfos() {
    std::vector<StageInfo> infos;
    for (const StageEntry& entry : registry())
        infos.push_back(entry.info);
    return infos;
}

std::unique_ptr<ShadingStage> makeStage(const std::string& text) {
    const StageSpec spec = StageSpec::parse(text);
    std::string valid;
    std::vector<std::string> names;
    for (const StageEntry& entry : registry()) {
        if (entry.info.name == spec.name)
            return entry.make(spec);
        valid += (valid.empty() ? "" : ", ") + entry.info.name;
        names.push_back(entry.info.name);
    }
    throw StageError("unknown stage '" + spec.name + "'" + scenes::didYouMean(spec.name, names) +
                     " (valid: " + valid + ")");
}

} // namespace lighting
