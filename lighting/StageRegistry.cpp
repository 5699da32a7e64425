#include "lighting/StageRegistry.h"

#include <algorithm>
#include <cstdio>
#include <exception>

#include "scenes/input/ClosestName.h"

namespace lighting {

namespace {

struct StageEntry {
    StageInfo info;
    StageFactory make;
};

// Function-local: registrars in other translation units may run before any static of this file.
std::vector<StageEntry>& registry() {
    static std::vector<StageEntry> entries;
    return entries;
}

// The registry in listOrder, sorted once on first read (registration is over by then: it happens
// during static initialisation, reads from main() on).
const std::vector<StageEntry>& sortedRegistry() {
    static const bool sorted = [] {
        std::stable_sort(
            registry().begin(), registry().end(), [](const StageEntry& a, const StageEntry& b) {
                return a.info.listOrder != b.info.listOrder ? a.info.listOrder < b.info.listOrder
                                                            : a.info.name < b.info.name;
            });
        return true;
    }();
    (void)sorted;
    return registry();
}

const StageEntry& findStage(const std::string& name) {
    std::string valid;
    std::vector<std::string> names;
    for (const StageEntry& entry : sortedRegistry()) {
        if (entry.info.name == name)
            return entry;
        valid += (valid.empty() ? "" : ", ") + entry.info.name;
        names.push_back(entry.info.name);
    }
    throw StageError("unknown stage '" + name + "'" + scenes::didYouMean(name, names) +
                     " (valid: " + valid + ")");
}

} // namespace

StageRegistrar::StageRegistrar(StageInfo info, StageFactory make) {
    for (const StageEntry& entry : registry())
        if (entry.info.name == info.name) {
            std::fprintf(stderr, "stage '%s' registered twice\n", info.name.c_str());
            std::terminate();
        }
    registry().push_back({std::move(info), std::move(make)});
}

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

std::vector<StageInfo> stageInfos() {
    std::vector<StageInfo> infos;
    for (const StageEntry& entry : sortedRegistry())
        infos.push_back(entry.info);
    return infos;
}

std::unique_ptr<ShadingStage> makeStage(const std::string& text) {
    const StageSpec spec = StageSpec::parse(text);
    const StageEntry& entry = findStage(spec.name);
    return entry.make(parseStageOptions(spec.name, entry.info.options, spec.options));
}

std::map<std::string, std::string> resolvedStageOptions(const std::string& text) {
    const StageSpec spec = StageSpec::parse(text);
    const StageEntry& entry = findStage(spec.name);
    return parseStageOptions(spec.name, entry.info.options, spec.options).resolved();
}

} // namespace lighting
