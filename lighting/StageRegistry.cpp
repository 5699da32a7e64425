#include "lighting/StageRegistry.h"

#include <functional>

#include "lighting/stages/Stages.h"

namespace lighting {

namespace {

struct StageEntry {
    StageInfo info;
    std::function<std::unique_ptr<ShadingStage>(const StageSpec&)> make;
};

const std::vector<StageEntry>& registry() {
    static const std::vector<StageEntry> entries = {
        {{"reference", "every light at every pixel, double precision, exact surface"}, makeReferenceStage},
        {{"brute", "every light at every pixel, float, from the G-buffer"}, makeBruteStage},
    };
    return entries;
}

}  // namespace

StageSpec StageSpec::parse(const std::string& text) {
    StageSpec spec;
    const size_t colon = text.find(':');
    spec.name = text.substr(0, colon);
    if (spec.name.empty()) throw StageError("stage '" + text + "': empty name");
    if (colon == std::string::npos) return spec;
    const std::string options = text.substr(colon + 1);
    size_t begin = 0;
    while (begin <= options.size()) {
        const size_t end = std::min(options.find(',', begin), options.size());
        const std::string item = options.substr(begin, end - begin);
        const size_t equals = item.find('=');
        if (item.empty() || equals == std::string::npos || equals == 0)
            throw StageError("stage '" + text + "': option '" + item + "' is not key=value");
        if (!spec.options.emplace(item.substr(0, equals), item.substr(equals + 1)).second)
            throw StageError("stage '" + text + "': option '" + item.substr(0, equals) + "' given twice");
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
            throw StageError("stage '" + spec.name + "': unknown option '" + key + "' (valid: " +
                             (valid.empty() ? "none" : valid) + ")");
    }
}

std::vector<StageInfo> stageInfos() {
    std::vector<StageInfo> infos;
    for (const StageEntry& entry : registry()) infos.push_back(entry.info);
    return infos;
}

std::unique_ptr<ShadingStage> makeStage(const std::string& text) {
    const StageSpec spec = StageSpec::parse(text);
    std::string valid;
    for (const StageEntry& entry : registry()) {
        if (entry.info.name == spec.name) return entry.make(spec);
        valid += (valid.empty() ? "" : ", ") + entry.info.name;
    }
    throw StageError("unknown stage '" + spec.name + "' (valid: " + valid + ")");
}

}  // namespace lighting
