// Every job of a shard planned against its scene before any runs; see SweepPreflight.h.
#include "experiments/sweep/SweepPreflight.h"

#include <optional>
#include <unordered_map>
#include <vector>

#include "experiments/render/RenderPlan.h"
#include "scenes/procedural/LightGenerator.h"

namespace experiments {

namespace {

// What the loaded scene depends on, apart from the seed (which moves generated lights, never
// their count or kind, so the plan and its estimate are the same for every seed).
std::string sceneKey(const RenderOptions& options) {
    std::string key = options.scene + "\n" + lightsText(options) + "\n" +
                      std::string(scenes::lightDensityName(options.lightDensity)) + "\n" +
                      options.brdf + "\n" + options.view;
    for (const auto& [name, value] : options.sceneOptions)
        key += "\n" + name + "=" + value;
    return key;
}

// What the job's plan depends on: every setting but the seed, and the runs and reference. Jobs
// with the same key get the same verdict, so a seed axis of 1000 values plans once.
std::string planKey(const SweepJob& job) {
    std::string key = std::to_string(job.options.warmup) + " " +
                      std::to_string(job.options.repetitions) + " " +
                      (job.compareReference ? "1" : "0");
    for (const SweepSetting& setting : job.settings)
        if (setting.key != "seed")
            key += "\n" + setting.key + "=" + settingText(setting.value, setting.key);
    return key;
}

} // namespace

void preflightSweepJobs(const SweepExpansion& expansion, size_t first, size_t last,
                        const std::string& origin) {
    std::string loadedKey;
    std::optional<scenes::Scene> loaded;
    std::string loadError;
    std::vector<std::string> errors;
    std::unordered_map<std::string, std::string> verdicts; // plan key -> "" or the error
    size_t invalid = 0;
    for (size_t position = first; position < last; ++position) {
        const SweepJob job = expansion.job(position);
        RenderOptions options = job.options;
        options.compareReference = job.compareReference;
        const auto [verdict, isNew] = verdicts.try_emplace(planKey(job));
        if (!isNew) {
            if (!verdict->second.empty() && ++invalid <= kMaxListedInvalidJobs)
                errors.push_back("job " + job.id + " (" + describeSettings(job.settings) +
                                 "): " + verdict->second);
            continue;
        }
        try {
            const std::string key = sceneKey(options);
            if (key != loadedKey) {
                loadedKey = key;
                loaded.reset();
                loadError.clear();
                try {
                    checkSceneLoadMemory(options);
                    loaded = loadRequestedScene(options);
                } catch (const std::exception& e) {
                    loadError = e.what();
                }
            }
            if (!loaded)
                throw std::runtime_error(loadError);
            const RenderPlan plan = planRenderWithScene(options, *loaded);
            checkMemoryEstimate(plan.memory);
        } catch (const std::exception& e) {
            verdict->second = e.what();
            if (verdict->second.empty())
                verdict->second = "unknown error";
            if (++invalid <= kMaxListedInvalidJobs)
                errors.push_back("job " + job.id + " (" + describeSettings(job.settings) +
                                 "): " + e.what());
        }
    }
    if (invalid == 0)
        return;
    std::string message =
        origin + ": " + std::to_string(invalid) + " of " + std::to_string(last - first) +
        " jobs cannot run" +
        (invalid > errors.size() ? " (the first " + std::to_string(errors.size()) + " listed)"
                                 : "") +
        "; nothing was run:";
    for (const std::string& error : errors)
        message += "\n  " + error;
    throw SweepError(message);
}

} // namespace experiments
