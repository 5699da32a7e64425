#include "experiments/sweep/SweepFile.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include "experiments/render/RenderPlan.h"
#include "scenes/Viewpoints.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"

namespace experiments {

namespace {

using Json = nlohmann::ordered_json;

// Settings the runner applies itself (RenderOptions fields that setRenderOption may not know).
const std::string kWarmup = "warmup";
const std::string kRepetitions = "repetitions";
// 64-bit FNV-1a: small, stable across platforms and releases (std::hash is neither).
uint64_t fnv1a(const std::string& text) {
    uint64_t hash = 1469598103934665603ull;
    for (unsigned char c : text) {
        hash ^= c;
        hash *= 1099511628211ull;
    }
    return hash;
}

std::string hex8(uint64_t hash) {
    static const char* kDigits = "0123456789abcdef";
    const uint32_t folded = uint32_t(hash ^ (hash >> 32));
    std::string text(8, '0');
    for (int i = 0; i < 8; ++i)
        text[size_t(7 - i)] = kDigits[(folded >> (4 * i)) & 0xFu];
    return text;
}

std::string safeName(const std::string& text) {
    std::string name;
    for (char c : text)
        name += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
    return name.empty() ? "scene" : name;
}

void applySetting(RenderOptions& options, const SweepSetting& setting) {
    const std::string text = settingText(setting.value, setting.key);
    if (setting.key == kWarmup || setting.key == kRepetitions) {
        int number = 0;
        try {
            size_t end = 0;
            number = std::stoi(text, &end);
            if (end != text.size())
                throw std::invalid_argument(text);
        } catch (const std::exception&) {
            throw UsageError("option '" + setting.key + "': '" + text + "' is not a valid number");
        }
        const int minimum = setting.key == kWarmup ? 0 : 1;
        if (number < minimum || number > kMaxRunCount)
            throw UsageError("option '" + setting.key + "' must be " + std::to_string(minimum) +
                             ".." + std::to_string(kMaxRunCount) + ", got " + text);
        (setting.key == kWarmup ? options.warmup : options.repetitions) = number;
        return;
    }
    setRenderOption(options, setting.key, text);
}

std::string referenceKeyOf(const RenderOptions& o) {
    std::string canonical = "scene=" + o.scene + "\n";
    for (const auto& [key, value] : o.sceneOptions)
        canonical += "scene-option." + key + "=" + value + "\n";
    canonical += "lights=" + lightsText(o) + "\nseed=" + std::to_string(o.seed) +
                 "\nwidth=" + std::to_string(o.width) + "\nheight=" + std::to_string(o.height) +
                 "\n";
    // The view changes the reference image; the default view ("") keeps the keys of sweeps
    // written before views existed, so their reference folders stay valid.
    std::string stem = safeName(std::filesystem::path(o.scene).stem().string());
    if (!o.view.empty()) {
        canonical += "view=" + o.view + "\n";
        stem += "-" + safeName(o.view);
    }
    // So do the reference's samples per pixel; 1 (the only reference before supersampling)
    // keeps the older keys, so their cached 1-sample references stay valid for 1-sample jobs.
    std::string samples;
    if (o.referenceSpp != 1) {
        canonical += "reference-spp=" + std::to_string(o.referenceSpp) + "\n";
        samples = "-spp" + std::to_string(o.referenceSpp);
    }
    // Shadows: the reference ray-traces the casting lights the maps get (the budget decides
    // which); the maps' own settings (size, filter, bias, cascades) do not change it. Off keeps
    // the older keys.
    std::string shadows;
    if (o.shadows != "off") {
        canonical += "shadows=" + o.shadows + "\nshadow-lights=" + o.shadowLights + "\n";
        shadows = "-shadows" + (o.shadowLights == "all" ? std::string() : o.shadowLights);
    }
    return stem + "-" + std::to_string(o.width) + "x" + std::to_string(o.height) + "-" +
           (requestedLights(o) ? lightsText(o) + "l" : "file-lights") + "-s" +
           std::to_string(o.seed) + samples + shadows + "-" + hex8(fnv1a(canonical));
}

} // namespace

std::vector<std::string> axisColumns(const std::vector<std::string>& settingKeys) {
    static const std::vector<std::string> kOrder = {"scene",
                                                    "stage",
                                                    "lights",
                                                    "seed",
                                                    "resolution",
                                                    "width",
                                                    "height",
                                                    "threads",
                                                    "isa",
                                                    "simt-warp",
                                                    "layout",
                                                    "normals",
                                                    "normal-space",
                                                    "depth",
                                                    "position",
                                                    "reference-spp",
                                                    "msaa",
                                                    "complex-detect",
                                                    "alpha-to-coverage",
                                                    "post-aa",
                                                    "oracle",
                                                    "shadows",
                                                    "shadow-map-size",
                                                    "shadow-filter",
                                                    "shadow-point",
                                                    "shadow-depth-format",
                                                    "shadow-bias",
                                                    "shadow-lights",
                                                    "shadow-cascades",
                                                    "shadow-caster-sets"};
    std::vector<std::string> columns;
    for (const std::string& key : kOrder)
        if (key == "width" || key == "height" ||
            std::find(settingKeys.begin(), settingKeys.end(), key) != settingKeys.end())
            columns.push_back(key);
    std::vector<std::string> rest;
    for (const std::string& key : settingKeys)
        if (std::find(kOrder.begin(), kOrder.end(), key) == kOrder.end() && key != kWarmup &&
            key != kRepetitions)
            rest.push_back(key);
    std::sort(rest.begin(), rest.end());
    columns.insert(columns.end(), rest.begin(), rest.end());
    columns.push_back(kRepetitions);
    columns.push_back(kWarmup);
    return columns;
}

Json axisValue(const SweepJob& job, const std::string& column) {
    for (const SweepSetting& s : job.settings)
        if (s.key == column)
            return s.value;
    if (column == "width")
        return job.options.width;
    if (column == "height")
        return job.options.height;
    if (column == kRepetitions)
        return job.options.repetitions;
    if (column == kWarmup)
        return job.options.warmup;
    return nullptr;
}

// view=all: every unresolved job that has it gets the view list of its scene (loaded once per
// distinct scene and scene options: views do not depend on lights, seed, size or method), and
// the ordinal blocks are laid out. `total` is the unresolved job count on entry, the resolved
// one on return. Scenes that cannot be loaded are reported together, once each.
void SweepExpansion::resolveEveryView(SweepExpansion& expansion, const std::string& origin,
                                      size_t& total) {
    bool any = false;
    for (const SweepSetting& s : expansion.mFixed)
        any = any || isEveryView(s);
    for (const auto& caseSettings : expansion.mCases)
        for (const SweepSetting& s : caseSettings)
            any = any || isEveryView(s);
    for (const auto& [key, values] : expansion.mAxes)
        if (key == "view")
            for (const Json& value : values)
                any = any || isEveryView({key, value});
    if (!any)
        return;
    std::map<std::string, uint32_t> listOfScene;
    std::map<std::string, std::string> failedScenes; // scene key -> reason
    expansion.mViewListOf.assign(total, kNoViewList);
    expansion.mFirstOrdinal.assign(total + 1, 0);
    uint64_t resolved = 0;
    for (size_t u = 0; u < total; ++u) {
        const std::vector<SweepSetting> settings = expansion.unresolvedSettingsOf(u);
        expansion.mFirstOrdinal[u] = uint32_t(std::min<uint64_t>(resolved, UINT32_MAX));
        if (std::none_of(settings.begin(), settings.end(), isEveryView)) {
            ++resolved;
            continue;
        }
        RenderOptions options;
        std::string sceneKey;
        try {
            for (const SweepSetting& s : settings)
                if (s.key != "view")
                    applySetting(options, s);
            validate(options); // input errors before the scene is loaded
        } catch (const std::exception&) {
            ++resolved; // the job stays one (invalid) job: expandSweep's check reports it
            continue;
        }
        sceneKey = options.scene;
        for (const auto& [key, value] : options.sceneOptions)
            sceneKey += "\n" + key + "=" + value;
        auto it = listOfScene.find(sceneKey);
        if (it == listOfScene.end() && !failedScenes.count(sceneKey)) {
            try {
                std::vector<std::string> views = scenes::viewNames(loadRequestedScene(options));
                if (views.empty())
                    throw std::runtime_error("the scene has no views");
                it = listOfScene.emplace(sceneKey, uint32_t(expansion.mViewLists.size())).first;
                expansion.mViewLists.push_back(std::move(views));
            } catch (const std::exception& e) {
                failedScenes.emplace(sceneKey, e.what());
            }
        }
        if (it == listOfScene.end()) {
            ++resolved;
            continue;
        }
        expansion.mViewListOf[u] = it->second;
        resolved += expansion.mViewLists[it->second].size();
        if (resolved > scenes::limits::kMaxSweepJobs)
            failSweep(origin, "view=all makes more than " +
                                  std::to_string(scenes::limits::kMaxSweepJobs) +
                                  " jobs; refused (list fewer views or scenes)");
    }
    if (!failedScenes.empty()) {
        std::string message = origin + ": view=" + kEveryView + " needs the views of " +
                              std::to_string(failedScenes.size()) + " scene" +
                              (failedScenes.size() == 1 ? "" : "s") + " that cannot be loaded:";
        for (const auto& [scene, reason] : failedScenes) {
            std::string name = scene;
            std::replace(name.begin(), name.end(), '\n', ' ');
            message += "\n  " + name + ": " + reason;
        }
        throw SweepError(message);
    }
    expansion.mFirstOrdinal[total] = uint32_t(resolved);
    total = size_t(resolved);
}

SweepExpansion expandSweep(const SweepSpec& spec, std::optional<int> threads) {
    SweepSpec effective = spec;
    if (threads) {
        for (const auto& [key, values] : spec.axes)
            if (key == "threads")
                failSweep(spec.origin, "--threads given but 'threads' is an axis of the sweep");
        if (!spec.cases.empty())
            for (const SweepSetting& s : spec.cases.front())
                if (s.key == "threads")
                    failSweep(spec.origin, "--threads given but 'threads' is set by the cases");
        std::erase_if(effective.fixed, [](const SweepSetting& s) { return s.key == "threads"; });
        effective.fixed.push_back({"threads", *threads});
    }
    SweepExpansion expansion;
    expansion.mFixed = effective.fixed;
    expansion.mCases =
        effective.cases.empty() ? std::vector<std::vector<SweepSetting>>{{}} : effective.cases;
    expansion.mAxes = effective.axes;
    expansion.mWarmup = effective.warmup;
    expansion.mRepetitions = effective.repetitions;
    expansion.mReference = effective.reference;
    expansion.mHeatmapMax = spec.heatmapMax;
    expansion.mErrorScale = spec.errorScale;
    expansion.mErrorMax = spec.errorMax;
    // Counted in double: twenty axes of 10 values would overflow any integer product. The total
    // is known before any job is made, so a typo'd axis is refused without allocating.
    double combinations = 1.0;
    for (const auto& [key, values] : effective.axes)
        combinations *= double(values.size());
    const double jobCount = double(expansion.mCases.size()) * combinations;
    if (jobCount > double(scenes::limits::kMaxSweepJobs))
        failSweep(spec.origin,
                  (jobCount < 1e18 ? std::to_string(uint64_t(jobCount)) : "more than 10^18") +
                      " jobs refused (at most " + std::to_string(scenes::limits::kMaxSweepJobs) +
                      ")");
    static_assert(scenes::limits::kMaxSweepJobs <= UINT32_MAX, "run order entries are 32-bit");
    expansion.mCombinations = size_t(combinations);
    size_t total = size_t(jobCount);
    checkEveryViewAlone(effective);
    SweepExpansion::resolveEveryView(expansion, spec.origin, total);
    expansion.mJobCount = total;
    expansion.mIdDigits = std::max<size_t>(4, std::to_string(total ? total - 1 : 0).size());

    // Each job is made once, validated and reduced to its reference group; groups are numbered in
    // order of first appearance, through a hash of the reference key (a collision of two keys in
    // 64 bits would only merge two groups' run order, never change a result).
    std::vector<std::string> errors;
    size_t invalid = 0;
    std::vector<uint32_t> groupOf(total);
    std::unordered_map<uint64_t, uint32_t> groupOfKey;
    for (size_t ordinal = 0; ordinal < total; ++ordinal) {
        try {
            const SweepJob job = expansion.jobAtOrdinal(ordinal);
            validate(job.options);
            groupOf[ordinal] =
                groupOfKey.emplace(fnv1a(job.referenceKey), uint32_t(groupOfKey.size()))
                    .first->second;
        } catch (const std::exception& e) {
            if (++invalid <= kMaxListedInvalidJobs) {
                const std::vector<SweepSetting> settings = expansion.settingsOf(ordinal);
                errors.push_back("job " + expansion.idOf(ordinal, settings) + " (" +
                                 describeSettings(settings) + "): " + e.what());
            }
        }
    }
    if (invalid > 0) {
        std::string message =
            spec.origin + ": " + std::to_string(invalid) + " of " + std::to_string(total) +
            " jobs are invalid" +
            (invalid > errors.size() ? " (the first " + std::to_string(errors.size()) + " listed)"
                                     : "") +
            ":";
        for (const std::string& error : errors)
            message += "\n  " + error;
        throw SweepError(message);
    }
    // Run order: a counting sort of the ordinals by group (stable: ordinal order inside).
    std::vector<size_t> groupStart(groupOfKey.size() + 1, 0);
    for (uint32_t group : groupOf)
        ++groupStart[group + 1];
    for (size_t g = 1; g < groupStart.size(); ++g)
        groupStart[g] += groupStart[g - 1];
    expansion.mOrdinalAt.resize(total);
    for (size_t ordinal = 0; ordinal < total; ++ordinal)
        expansion.mOrdinalAt[groupStart[groupOf[ordinal]]++] = uint32_t(ordinal);

    std::vector<std::string> keys;
    for (const SweepSetting& s : total ? expansion.settingsOf(0) : std::vector<SweepSetting>{})
        keys.push_back(s.key);
    expansion.mAxisColumns = axisColumns(keys);
    return expansion;
}

std::vector<SweepSetting> SweepExpansion::settingsOf(size_t ordinal) const {
    if (mFirstOrdinal.empty())
        return unresolvedSettingsOf(ordinal);
    // The unresolved job u whose block of jobs holds the ordinal, and the view inside the block.
    const size_t u =
        size_t(std::upper_bound(mFirstOrdinal.begin(), mFirstOrdinal.end(), uint32_t(ordinal)) -
               mFirstOrdinal.begin()) -
        1;
    std::vector<SweepSetting> settings = unresolvedSettingsOf(u);
    if (mViewListOf[u] != kNoViewList)
        for (SweepSetting& s : settings)
            if (isEveryView(s))
                s.value = mViewLists[mViewListOf[u]][ordinal - mFirstOrdinal[u]];
    return settings;
}

std::vector<SweepSetting> SweepExpansion::unresolvedSettingsOf(size_t ordinal) const {
    const size_t caseIndex = ordinal / mCombinations;
    std::vector<SweepSetting> settings = mFixed;
    settings.insert(settings.end(), mCases[caseIndex].begin(), mCases[caseIndex].end());
    // Mixed radix, last axis fastest.
    size_t rest = ordinal % mCombinations;
    std::vector<SweepSetting> axisSettings(mAxes.size());
    for (size_t a = mAxes.size(); a-- > 0;) {
        const auto& [key, values] = mAxes[a];
        axisSettings[a] = {key, values[rest % values.size()]};
        rest /= values.size();
    }
    settings.insert(settings.end(), axisSettings.begin(), axisSettings.end());
    return settings;
}

std::string SweepExpansion::idOf(size_t ordinal, const std::vector<SweepSetting>& settings) const {
    std::vector<std::string> canonical;
    for (const SweepSetting& s : settings)
        canonical.push_back(s.key + "=" + settingText(s.value, s.key));
    canonical.push_back("warmup=" + std::to_string(mWarmup));
    canonical.push_back("repetitions=" + std::to_string(mRepetitions));
    canonical.push_back(std::string("reference=") + (mReference ? "1" : "0"));
    std::sort(canonical.begin(), canonical.end());
    std::string text;
    for (const std::string& line : canonical)
        text += line + "\n";
    std::string number = std::to_string(ordinal);
    number.insert(0, mIdDigits - std::min(mIdDigits, number.size()), '0');
    return number + "-" + hex8(fnv1a(text));
}

std::string SweepExpansion::jobId(size_t ordinal) const {
    return idOf(ordinal, settingsOf(ordinal));
}

SweepJob SweepExpansion::jobAtOrdinal(size_t ordinal) const {
    if (ordinal >= size())
        throw std::out_of_range("sweep job ordinal " + std::to_string(ordinal) + " of " +
                                std::to_string(size()));
    SweepJob job;
    job.ordinal = ordinal;
    job.settings = settingsOf(ordinal);
    job.id = idOf(ordinal, job.settings);
    job.options.warmup = mWarmup;
    job.options.repetitions = mRepetitions;
    job.compareReference = mReference;
    job.heatmapMax = mHeatmapMax;
    job.errorScale = mErrorScale;
    job.errorMax = mErrorMax;
    for (const SweepSetting& s : job.settings)
        applySetting(job.options, s);
    job.referenceKey = referenceKeyOf(job.options);
    return job;
}

Json sweepJobJson(const SweepJob& job) {
    Json settings = Json::array();
    for (const SweepSetting& s : job.settings)
        settings.push_back(Json{{"key", s.key}, {"value", s.value}});
    return Json{{"ordinal", job.ordinal},
                {"id", job.id},
                {"settings", settings},
                {"warmup", job.options.warmup},
                {"repetitions", job.options.repetitions},
                {"reference", job.compareReference},
                {"heatmap_max", job.heatmapMax},
                {"error_scale", mapScaleName(job.errorScale)},
                {"error_max", job.errorMax}};
}

SweepJob sweepJobFromJson(const Json& json) {
    SweepJob job;
    try {
        job.ordinal = json.at("ordinal").get<size_t>();
        job.id = json.at("id").get<std::string>();
        job.options.warmup = json.at("warmup").get<int>();
        job.options.repetitions = json.at("repetitions").get<int>();
        job.compareReference = json.at("reference").get<bool>();
        job.heatmapMax = json.at("heatmap_max").get<uint32_t>();
        job.errorScale = parseMapScale(json.at("error_scale").get<std::string>());
        job.errorMax = json.at("error_max").get<double>();
        for (const Json& setting : json.at("settings"))
            job.settings.push_back({setting.at("key").get<std::string>(), setting.at("value")});
        for (const SweepSetting& s : job.settings)
            applySetting(job.options, s);
    } catch (const nlohmann::json::exception& e) {
        throw SweepError(std::string("malformed sweep job: ") + e.what());
    } catch (const UsageError& e) {
        throw SweepError(std::string("sweep job: ") + e.what());
    } catch (const std::invalid_argument& e) { // parseMapScale
        throw SweepError(std::string("sweep job: ") + e.what());
    }
    job.referenceKey = referenceKeyOf(job.options);
    return job;
}

std::vector<SweepJob> SweepExpansion::jobs() const {
    std::vector<SweepJob> all;
    all.reserve(size());
    for (size_t position = 0; position < size(); ++position)
        all.push_back(job(position));
    return all;
}

std::pair<size_t, size_t> shardRange(size_t jobCount, int index, int count) {
    if (count < 1 || index < 1 || index > count)
        throw SweepError("shard " + std::to_string(index) + "/" + std::to_string(count) +
                         " refused: need 1 <= I <= N");
    return {jobCount * size_t(index - 1) / size_t(count), jobCount * size_t(index) / size_t(count)};
}

std::vector<SweepJob> shardJobs(const std::vector<SweepJob>& jobs, int index, int count) {
    const auto [first, last] = shardRange(jobs.size(), index, count);
    return std::vector<SweepJob>(jobs.begin() + ptrdiff_t(first), jobs.begin() + ptrdiff_t(last));
}

std::pair<int, int> parseShard(const std::string& text) {
    const size_t slash = text.find('/');
    try {
        if (slash == std::string::npos)
            throw std::invalid_argument(text);
        size_t endI = 0, endN = 0;
        const std::string first = text.substr(0, slash), second = text.substr(slash + 1);
        const int index = std::stoi(first, &endI), count = std::stoi(second, &endN);
        if (endI != first.size() || endN != second.size() || count < 1 || index < 1 ||
            index > count)
            throw std::invalid_argument(text);
        return {index, count};
    } catch (const std::exception&) {
        throw SweepError("--shard '" + text + "' is not I/N with 1 <= I <= N (e.g. 2/4)");
    }
}

} // namespace experiments
