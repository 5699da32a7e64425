#include "experiments/SweepFile.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <toml++/toml.h>

namespace experiments {

namespace {

using Json = nlohmann::ordered_json;

const std::vector<std::string> kTopLevelKeys = {
    "name",   "description", "notes",     "fixed", "axes",     "cases",
    "warmup", "repetitions", "reference", "quick", "published"};
const std::vector<std::string> kQuickKeys = {"fixed",  "axes",        "cases",
                                             "warmup", "repetitions", "reference"};
// Settings the runner applies itself (RenderOptions fields that setRenderOption may not know).
const std::string kWarmup = "warmup";
const std::string kRepetitions = "repetitions";
// Upper bound of warmup and repetitions: a typo must not keep a sweep running for days.
constexpr int kMaxRunCount = 1000;

std::string joined(const std::vector<std::string>& items) {
    std::string text;
    for (const std::string& item : items)
        text += (text.empty() ? "" : ", ") + item;
    return text;
}

[[noreturn]] void fail(const std::string& origin, const std::string& message) {
    throw SweepError(origin + ": " + message);
}

void rejectUnknownKeys(const Json& object, const std::vector<std::string>& known,
                       const std::string& origin, const std::string& where) {
    for (const auto& [key, value] : object.items())
        if (std::find(known.begin(), known.end(), key) == known.end())
            fail(origin, "unknown key '" + where + key + "'; valid keys: " + joined(known));
}

int readCount(const Json& value, const std::string& origin, const std::string& key, int minimum) {
    if (!value.is_number_integer() || value.get<int64_t>() < minimum ||
        value.get<int64_t>() > kMaxRunCount)
        fail(origin, "'" + key + "' must be an integer " + std::to_string(minimum) + ".." +
                         std::to_string(kMaxRunCount) + ", got " + value.dump());
    return value.get<int>();
}

void checkSettingValue(const Json& value, const std::string& origin, const std::string& where) {
    if (!value.is_string() && !value.is_number())
        fail(origin, "'" + where + "' must be a string or a number, got " + value.dump());
}

std::vector<SweepSetting> readSettings(const Json& object, const std::string& origin,
                                       const std::string& where) {
    if (!object.is_object())
        fail(origin, "'" + where + "' must be an object of key: value");
    std::vector<SweepSetting> settings;
    for (const auto& [key, value] : object.items()) {
        checkSettingValue(value, origin, where + "." + key);
        settings.push_back({key, value});
    }
    return settings;
}

std::vector<std::pair<std::string, std::vector<Json>>>
readAxes(const Json& object, const std::string& origin, const std::string& where) {
    if (!object.is_object())
        fail(origin, "'" + where + "' must be an object of key: [values]");
    std::vector<std::pair<std::string, std::vector<Json>>> axes;
    for (const auto& [key, values] : object.items()) {
        if (!values.is_array() || values.empty())
            fail(origin, "'" + where + "." + key + "' must be a non-empty array of values");
        std::vector<Json> list;
        for (const Json& value : values) {
            checkSettingValue(value, origin, where + "." + key + "[]");
            list.push_back(value);
        }
        axes.emplace_back(key, std::move(list));
    }
    return axes;
}

std::vector<std::vector<SweepSetting>> readCases(const Json& array, const std::string& origin,
                                                 const std::string& where) {
    if (!array.is_array() || array.empty())
        fail(origin, "'" + where + "' must be a non-empty array of objects");
    std::vector<std::vector<SweepSetting>> cases;
    std::vector<std::string> firstKeys;
    for (size_t i = 0; i < array.size(); ++i) {
        const std::string here = where + "[" + std::to_string(i) + "]";
        cases.push_back(readSettings(array[i], origin, here));
        std::vector<std::string> keys;
        for (const SweepSetting& s : cases.back())
            keys.push_back(s.key);
        std::sort(keys.begin(), keys.end());
        if (i == 0)
            firstKeys = keys;
        else if (keys != firstKeys) // zipped groups: one column per key, filled in every row
            fail(origin, "'" + here + "' sets {" + joined(keys) + "} but '" + where +
                             "[0]' sets {" + joined(firstKeys) +
                             "}: every case sets the same keys");
    }
    return cases;
}

std::set<std::string> settingKeys(const SweepSpec& spec) {
    std::set<std::string> keys;
    for (const SweepSetting& s : spec.fixed)
        keys.insert(s.key);
    for (const auto& [key, values] : spec.axes)
        keys.insert(key);
    if (!spec.cases.empty())
        for (const SweepSetting& s : spec.cases.front())
            keys.insert(s.key);
    return keys;
}

// A key may be set in one place only: fixed, axes or cases.
void checkDisjoint(const SweepSpec& spec, const std::string& where) {
    std::map<std::string, std::string> place;
    auto claim = [&](const std::string& key, const std::string& in) {
        const auto [it, inserted] = place.emplace(key, in);
        if (!inserted)
            fail(spec.origin, "key '" + key + "' is set in both '" + where + it->second +
                                  "' and '" + where + in + "'");
    };
    for (const SweepSetting& s : spec.fixed)
        claim(s.key, "fixed");
    for (const auto& [key, values] : spec.axes)
        claim(key, "axes");
    if (!spec.cases.empty())
        for (const SweepSetting& s : spec.cases.front())
            claim(s.key, "cases");
}

void checkPublished(const Json& published, const std::string& origin,
                    const std::vector<std::string>& columns) {
    if (!published.is_array())
        fail(origin, "'published' must be an array of tables");
    auto checkSelect = [&](const Json& item, const std::string& where) {
        if (!item.is_object() || !item.contains("select") || !item["select"].is_object())
            fail(origin, "'" + where + "' must be an object with a 'select' object");
        for (const auto& [key, value] : item["select"].items()) {
            if (std::find(columns.begin(), columns.end(), key) == columns.end())
                fail(origin, "'" + where + ".select." + key +
                                 "' is not a result column; axis columns: " + joined(columns));
            checkSettingValue(value, origin, where + ".select." + key);
        }
    };
    for (size_t t = 0; t < published.size(); ++t) {
        const Json& table = published[t];
        const std::string where = "published[" + std::to_string(t) + "]";
        if (!table.is_object())
            fail(origin, "'" + where + "' must be an object");
        rejectUnknownKeys(table,
                          {"title", "source", "metric", "columns", "rows", "ratio_to", "finding"},
                          origin, where + ".");
        for (const char* key : {"title", "metric", "columns", "rows"})
            if (!table.contains(key))
                fail(origin, "'" + where + "' lacks '" + key + "'");
        const Json& metric = table["metric"];
        const bool metricOk =
            metric.is_string() || (metric.is_array() && !metric.empty() &&
                                   std::all_of(metric.begin(), metric.end(),
                                               [](const Json& m) { return m.is_string(); }));
        if (!metricOk)
            fail(origin, "'" + where + ".metric' must be a column name or a list of them");
        const Json& tableColumns = table["columns"];
        if (!tableColumns.is_array() || tableColumns.empty())
            fail(origin, "'" + where + ".columns' must be a non-empty array");
        for (size_t c = 0; c < tableColumns.size(); ++c)
            checkSelect(tableColumns[c], where + ".columns[" + std::to_string(c) + "]");
        if (!table["rows"].is_array())
            fail(origin, "'" + where + ".rows' must be an array");
        for (size_t r = 0; r < table["rows"].size(); ++r) {
            const Json& row = table["rows"][r];
            const std::string here = where + ".rows[" + std::to_string(r) + "]";
            checkSelect(row, here);
            if (!row.contains("values") || !row["values"].is_array() ||
                row["values"].size() != tableColumns.size())
                fail(origin, "'" + here + ".values' must have one value (or null) per column (" +
                                 std::to_string(tableColumns.size()) + ")");
            for (const Json& v : row["values"])
                if (!v.is_number() && !v.is_null())
                    fail(origin,
                         "'" + here + ".values' holds " + v.dump() + ": numbers or null only");
        }
        if (table.contains("ratio_to") && (!table["ratio_to"].is_number_unsigned() ||
                                           table["ratio_to"].get<size_t>() >= tableColumns.size()))
            fail(origin, "'" + where + ".ratio_to' must be a column index 0.." +
                             std::to_string(tableColumns.size() - 1));
    }
}

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
    canonical += "lights=" + std::to_string(o.lights) + "\nseed=" + std::to_string(o.seed) +
                 "\nwidth=" + std::to_string(o.width) + "\nheight=" + std::to_string(o.height) +
                 "\n";
    // The view changes the reference image; the default view ("") keeps the keys of sweeps
    // written before views existed, so their reference folders stay valid.
    std::string stem = safeName(std::filesystem::path(o.scene).stem().string());
    if (!o.view.empty()) {
        canonical += "view=" + o.view + "\n";
        stem += "-" + safeName(o.view);
    }
    return stem + "-" + std::to_string(o.width) + "x" + std::to_string(o.height) + "-" +
           std::to_string(o.lights) + "l-s" + std::to_string(o.seed) + "-" + hex8(fnv1a(canonical));
}

// TOML to JSON keeping the file's key order (toml::table sorts keys; the axes' order matters:
// it is the order of the cross product). Dates and times become strings.
Json tomlToJson(const toml::node& node) {
    if (const toml::table* table = node.as_table()) {
        std::vector<std::pair<const toml::key*, const toml::node*>> entries;
        for (const auto& [key, value] : *table)
            entries.emplace_back(&key, &value);
        std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
            const toml::source_position pa = a.first->source().begin, pb = b.first->source().begin;
            return pa.line != pb.line ? pa.line < pb.line : pa.column < pb.column;
        });
        Json object = Json::object();
        for (const auto& [key, value] : entries)
            object[std::string(key->str())] = tomlToJson(*value);
        return object;
    }
    if (const toml::array* array = node.as_array()) {
        Json list = Json::array();
        for (const toml::node& item : *array)
            list.push_back(tomlToJson(item));
        return list;
    }
    if (const auto* text = node.as_string())
        return text->get();
    if (const auto* integer = node.as_integer())
        return integer->get();
    if (const auto* floating = node.as_floating_point())
        return floating->get();
    if (const auto* boolean = node.as_boolean())
        return boolean->get();
    std::stringstream other; // date, time, date-time
    if (const auto* date = node.as_date())
        other << *date;
    else if (const auto* time = node.as_time())
        other << *time;
    else if (const auto* dateTime = node.as_date_time())
        other << *dateTime;
    return other.str();
}

} // namespace

std::string settingText(const Json& value, const std::string& where) {
    if (value.is_string())
        return value.get<std::string>();
    if (value.is_number_unsigned())
        return std::to_string(value.get<uint64_t>());
    if (value.is_number_integer())
        return std::to_string(value.get<int64_t>());
    if (value.is_number_float()) {
        const double number = value.get<double>();
        if (std::isfinite(number) && number == std::floor(number) && std::fabs(number) < 9.0e15)
            return std::to_string(int64_t(number));
        return value.dump();
    }
    throw SweepError("'" + where + "' must be a string or a number, got " + value.dump());
}

std::string describeSettings(const std::vector<SweepSetting>& settings) {
    std::string text;
    for (const SweepSetting& s : settings)
        text += (text.empty() ? "" : " ") + s.key + "=" + settingText(s.value, s.key);
    return text;
}

SweepSpec parseSweep(const Json& object, const std::string& origin) {
    if (!object.is_object())
        fail(origin, "a sweep file holds one object");
    rejectUnknownKeys(object, kTopLevelKeys, origin, "");
    SweepSpec spec;
    spec.origin = origin;
    spec.source = object;
    auto text = [&](const char* key) -> std::string {
        if (!object.contains(key))
            return {};
        if (!object[key].is_string())
            fail(origin, std::string("'") + key + "' must be a string");
        return object[key].get<std::string>();
    };
    spec.name = text("name");
    spec.description = text("description");
    if (object.contains("notes") && !object["notes"].is_string() && !object["notes"].is_array())
        fail(origin, "'notes' must be a string or an array of strings");
    if (object.contains("fixed"))
        spec.fixed = readSettings(object["fixed"], origin, "fixed");
    if (object.contains("axes"))
        spec.axes = readAxes(object["axes"], origin, "axes");
    if (object.contains("cases"))
        spec.cases = readCases(object["cases"], origin, "cases");
    if (object.contains("warmup"))
        spec.warmup = readCount(object["warmup"], origin, "warmup", 0);
    if (object.contains("repetitions"))
        spec.repetitions = readCount(object["repetitions"], origin, "repetitions", 1);
    if (object.contains("reference")) {
        if (!object["reference"].is_boolean())
            fail(origin, "'reference' must be true or false");
        spec.reference = object["reference"].get<bool>();
    }
    checkDisjoint(spec, "");
    std::set<std::string> keys = settingKeys(spec);
    if (object.contains("quick")) {
        const Json& quick = object["quick"];
        if (!quick.is_object())
            fail(origin, "'quick' must be an object");
        rejectUnknownKeys(quick, kQuickKeys, origin, "quick.");
        // Check the block's shape now, so that a broken quick block fails without --quick too.
        const SweepSpec quickSpec = applyQuick(spec);
        const std::set<std::string> quickKeys = settingKeys(quickSpec);
        keys.insert(quickKeys.begin(), quickKeys.end());
    }
    if (object.contains("published"))
        checkPublished(object["published"], origin,
                       axisColumns(std::vector<std::string>(keys.begin(), keys.end())));
    return spec;
}

SweepSpec readSweepFile(const std::filesystem::path& file) {
    const std::string origin = file.string();
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw SweepError(origin + ": cannot open the sweep file");
    std::stringstream text;
    text << in.rdbuf();
    Json object;
    if (file.extension() == ".toml") {
        try {
            const toml::table table = toml::parse(text.str(), origin);
            object = tomlToJson(table);
        } catch (const toml::parse_error& e) {
            const auto& begin = e.source().begin;
            throw SweepError(origin + ":" + std::to_string(begin.line) + ":" +
                             std::to_string(begin.column) +
                             ": TOML syntax error: " + std::string(e.description()));
        }
    } else {
        try {
            object = Json::parse(text.str());
        } catch (const nlohmann::json::parse_error& e) {
            throw SweepError(origin + ": JSON syntax error: " + e.what());
        }
    }
    return parseSweep(object, origin);
}

SweepSpec applyQuick(const SweepSpec& spec) {
    if (!spec.source.contains("quick"))
        fail(spec.origin, "--quick given but the sweep file has no 'quick' block");
    const Json& quick = spec.source["quick"];
    SweepSpec result = spec;
    auto dropKey = [&](const std::string& key) {
        std::erase_if(result.fixed, [&](const SweepSetting& s) { return s.key == key; });
        std::erase_if(result.axes, [&](const auto& axis) { return axis.first == key; });
    };
    if (quick.contains("cases"))
        result.cases = readCases(quick["cases"], spec.origin, "quick.cases");
    if (quick.contains("fixed"))
        for (const SweepSetting& s : readSettings(quick["fixed"], spec.origin, "quick.fixed")) {
            dropKey(s.key);
            result.fixed.push_back(s);
        }
    if (quick.contains("axes"))
        for (auto& axis : readAxes(quick["axes"], spec.origin, "quick.axes")) {
            // Replace in place when the key was an axis already, to keep the axis order.
            std::erase_if(result.fixed, [&](const SweepSetting& s) { return s.key == axis.first; });
            auto it = std::find_if(result.axes.begin(), result.axes.end(),
                                   [&](const auto& a) { return a.first == axis.first; });
            if (it != result.axes.end())
                it->second = axis.second;
            else
                result.axes.push_back(std::move(axis));
        }
    if (quick.contains("warmup"))
        result.warmup = readCount(quick["warmup"], spec.origin, "quick.warmup", 0);
    if (quick.contains("repetitions"))
        result.repetitions = readCount(quick["repetitions"], spec.origin, "quick.repetitions", 1);
    if (quick.contains("reference")) {
        if (!quick["reference"].is_boolean())
            fail(spec.origin, "'quick.reference' must be true or false");
        result.reference = quick["reference"].get<bool>();
    }
    checkDisjoint(result, "quick: ");
    return result;
}

std::vector<std::string> axisColumns(const std::vector<std::string>& settingKeys) {
    static const std::vector<std::string> kOrder = {
        "scene", "stage",     "lights", "seed",    "resolution",   "width", "height",  "threads",
        "isa",   "simt-warp", "layout", "normals", "normal-space", "depth", "position"};
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

SweepExpansion expandSweep(const SweepSpec& spec, std::optional<int> threads) {
    SweepSpec effective = spec;
    if (threads) {
        for (const auto& [key, values] : spec.axes)
            if (key == "threads")
                fail(spec.origin, "--threads given but 'threads' is an axis of the sweep");
        if (!spec.cases.empty())
            for (const SweepSetting& s : spec.cases.front())
                if (s.key == "threads")
                    fail(spec.origin, "--threads given but 'threads' is set by the cases");
        std::erase_if(effective.fixed, [](const SweepSetting& s) { return s.key == "threads"; });
        effective.fixed.push_back({"threads", *threads});
    }
    const std::vector<std::vector<SweepSetting>> cases =
        effective.cases.empty() ? std::vector<std::vector<SweepSetting>>{{}} : effective.cases;
    size_t combinations = 1;
    for (const auto& [key, values] : effective.axes)
        combinations *= values.size();
    const size_t total = cases.size() * combinations;
    constexpr size_t kMaxJobs = 1'000'000; // a typo'd axis must not allocate forever
    if (total > kMaxJobs)
        fail(spec.origin,
             std::to_string(total) + " jobs refused (at most " + std::to_string(kMaxJobs) + ")");
    const size_t digits = std::max<size_t>(4, std::to_string(total ? total - 1 : 0).size());

    SweepExpansion expansion;
    std::vector<std::string> errors;
    std::vector<SweepJob> jobs;
    jobs.reserve(total);
    for (size_t c = 0; c < cases.size(); ++c)
        for (size_t combo = 0; combo < combinations; ++combo) {
            SweepJob job;
            job.ordinal = jobs.size();
            job.settings = effective.fixed;
            job.settings.insert(job.settings.end(), cases[c].begin(), cases[c].end());
            // Mixed radix, last axis fastest.
            size_t rest = combo;
            std::vector<SweepSetting> axisSettings(effective.axes.size());
            for (size_t a = effective.axes.size(); a-- > 0;) {
                const auto& [key, values] = effective.axes[a];
                axisSettings[a] = {key, values[rest % values.size()]};
                rest /= values.size();
            }
            job.settings.insert(job.settings.end(), axisSettings.begin(), axisSettings.end());
            job.options.warmup = effective.warmup;
            job.options.repetitions = effective.repetitions;
            job.compareReference = effective.reference;
            std::vector<std::string> canonical;
            for (const SweepSetting& s : job.settings)
                canonical.push_back(s.key + "=" + settingText(s.value, s.key));
            canonical.push_back("warmup=" + std::to_string(effective.warmup));
            canonical.push_back("repetitions=" + std::to_string(effective.repetitions));
            canonical.push_back(std::string("reference=") + (effective.reference ? "1" : "0"));
            std::sort(canonical.begin(), canonical.end());
            std::string text;
            for (const std::string& line : canonical)
                text += line + "\n";
            std::string ordinal = std::to_string(job.ordinal);
            ordinal.insert(0, digits - ordinal.size(), '0');
            job.id = ordinal + "-" + hex8(fnv1a(text));
            try {
                for (const SweepSetting& s : job.settings)
                    applySetting(job.options, s);
                validate(job.options);
                job.referenceKey = referenceKeyOf(job.options);
            } catch (const std::exception& e) {
                errors.push_back("job " + job.id + " (" + describeSettings(job.settings) +
                                 "): " + e.what());
            }
            jobs.push_back(std::move(job));
        }
    if (!errors.empty()) {
        std::string message = spec.origin + ": " + std::to_string(errors.size()) + " of " +
                              std::to_string(total) + " jobs are invalid:";
        for (const std::string& error : errors)
            message += "\n  " + error;
        throw SweepError(message);
    }
    // Run order: grouped by reference key, groups in order of first appearance, stable inside.
    std::map<std::string, size_t> firstSeen;
    for (const SweepJob& job : jobs)
        firstSeen.emplace(job.referenceKey, firstSeen.size());
    std::stable_sort(jobs.begin(), jobs.end(), [&](const SweepJob& a, const SweepJob& b) {
        return firstSeen.at(a.referenceKey) < firstSeen.at(b.referenceKey);
    });
    std::vector<std::string> keys;
    for (const SweepSetting& s : jobs.empty() ? std::vector<SweepSetting>{} : jobs.front().settings)
        keys.push_back(s.key);
    expansion.axisColumns = axisColumns(keys);
    expansion.jobs = std::move(jobs);
    return expansion;
}

std::vector<SweepJob> shardJobs(const std::vector<SweepJob>& jobs, int index, int count) {
    if (count < 1 || index < 1 || index > count)
        throw SweepError("shard " + std::to_string(index) + "/" + std::to_string(count) +
                         " refused: need 1 <= I <= N");
    const size_t n = jobs.size(), first = n * size_t(index - 1) / size_t(count),
                 last = n * size_t(index) / size_t(count);
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
