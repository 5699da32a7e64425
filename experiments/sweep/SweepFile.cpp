#include "experiments/SweepFile.h"

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

#include <toml++/toml.h>

#include "experiments/RenderPlan.h"
#include "scenes/Limits.h"
#include "scenes/NestingDepth.h"
#include "scenes/Viewpoints.h"

namespace experiments {

namespace {

using Json = nlohmann::ordered_json;

const std::vector<std::string> kTopLevelKeys = {
    "name",      "description", "notes",       "fixed",       "axes",
    "cases",     "warmup",      "repetitions", "reference",   "quick",
    "published", "heatmap-max", "error-max",   "error-scale", "job-timeout"};
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
        rejectUnknownKeys(
            table,
            {"title", "source", "metric", "columns", "rows", "ratio_to", "finding", "modelled"},
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
        if (table.contains("modelled") && !table["modelled"].is_string())
            fail(origin, "'" + where + ".modelled' must be a column name (e.g. simt_lane_slots)");
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
    return stem + "-" + std::to_string(o.width) + "x" + std::to_string(o.height) + "-" +
           (requestedLights(o) ? lightsText(o) + "l" : "file-lights") + "-s" +
           std::to_string(o.seed) + "-" + hex8(fnv1a(canonical));
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

bool isEveryView(const SweepSetting& setting) {
    return setting.key == "view" && setting.value.is_string() &&
           setting.value.get<std::string>() == kEveryView;
}

// view = "all" stands for every view of a scene, so it cannot sit beside named views in one
// axis (the named ones would run twice).
void checkEveryViewAlone(const SweepSpec& spec) {
    for (const auto& [key, values] : spec.axes) {
        if (key != "view" || values.size() < 2)
            continue;
        for (const Json& value : values)
            if (value.is_string() && value.get<std::string>() == kEveryView)
                fail(spec.origin, std::string("'axes.view' lists \"") + kEveryView +
                                      "\" beside other views; \"" + kEveryView +
                                      "\" already stands for every view of the scene, so it "
                                      "must be the axis' only value");
    }
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
    // Without settings the sweep would be one default render, which a typo'd or truncated file
    // must not silently become (`testbed render` is the way to make a default render).
    if (spec.fixed.empty() && spec.axes.empty() && spec.cases.empty())
        fail(origin, "the sweep sets nothing to run: it needs 'fixed' settings, 'axes' or "
                     "'cases' (e.g. \"axes\": {\"stage\": [\"brute\", \"tiled\"]}), and has " +
                         (object.empty() ? std::string("no keys")
                                         : "only " + joined([&] {
                                               std::vector<std::string> keys;
                                               for (const auto& [key, value] : object.items())
                                                   keys.push_back("'" + key + "'");
                                               return keys;
                                           }())));
    if (object.contains("heatmap-max")) {
        const Json& value = object["heatmap-max"];
        if (!value.is_number_integer() || value.get<int64_t>() < 0 ||
            value.get<int64_t>() > int64_t(kMaxLights))
            fail(origin, "'heatmap-max' must be a light count 0.." + std::to_string(kMaxLights) +
                             " (0 = each image's maximum), got " + value.dump());
        spec.heatmapMax = value.get<uint32_t>();
    }
    if (object.contains("error-max")) {
        const Json& value = object["error-max"];
        if (!value.is_number() || !(value.get<double>() >= 0.0) ||
            !std::isfinite(value.get<double>()))
            fail(origin,
                 "'error-max' must be a number >= 0 (0 = each image's largest error), got " +
                     value.dump());
        spec.errorMax = value.get<double>();
    }
    if (object.contains("error-scale")) {
        const Json& value = object["error-scale"];
        if (!value.is_string() ||
            (value.get<std::string>() != "linear" && value.get<std::string>() != "log"))
            fail(origin, "'error-scale' must be \"linear\" or \"log\", got " + value.dump());
        spec.errorScale = parseMapScale(value.get<std::string>());
    }
    if (object.contains("job-timeout")) {
        const Json& value = object["job-timeout"];
        const std::string error =
            value.is_number()
                ? jobTimeoutError(value.get<double>(), "'job-timeout'")
                : "'job-timeout' must be a number of seconds (0 = no limit), got " + value.dump();
        if (!error.empty())
            fail(origin, error);
        spec.jobTimeoutSeconds = value.get<double>();
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

std::string jobTimeoutError(double seconds, const std::string& where) {
    if (std::isfinite(seconds) && seconds >= 0.0 && seconds <= kMaxJobTimeoutSeconds)
        return "";
    char limit[32], got[32];
    std::snprintf(limit, sizeof limit, "%g", kMaxJobTimeoutSeconds);
    std::snprintf(got, sizeof got, "%g", seconds);
    return where + " must be a number of seconds 0.." + limit + " (0 = no limit), got " + got;
}

SweepSpec readSweepFile(const std::filesystem::path& file) {
    const std::string origin = file.string();
    std::error_code error;
    const uintmax_t size = std::filesystem::file_size(file, error);
    if (!error && size > scenes::limits::kMaxFileBytes)
        throw SweepError(origin + ": " + std::to_string(size) + " bytes, more than the limit of " +
                         std::to_string(scenes::limits::kMaxFileBytes));
    std::ifstream in(file, std::ios::binary);
    if (!in)
        throw SweepError(origin + ": cannot open the sweep file");
    std::stringstream text;
    text << in.rdbuf();
    return readSweepText(text.str(), origin, file.extension() == ".toml");
}

SweepSpec readSweepText(const std::string& text, const std::string& origin, bool isToml) {
    // Both parsers' results are copied and converted recursively (and toml++ builds and destroys
    // dotted-key tables recursively), so the nesting is bounded before either parser runs.
    scenes::NestingViolation violation;
    if (isToml ? scenes::tomlNestsDeeperThan(text, scenes::limits::kMaxNestingDepth, &violation)
               : scenes::jsonNestsDeeperThan(text, scenes::limits::kMaxNestingDepth, &violation))
        throw SweepError(origin + ":" + std::to_string(violation.line) + ": nests deeper than " +
                         std::to_string(scenes::limits::kMaxNestingDepth) + " levels");
    Json object;
    if (isToml) {
        try {
            const toml::table table = toml::parse(text, origin);
            object = tomlToJson(table);
        } catch (const toml::parse_error& e) {
            const auto& begin = e.source().begin;
            throw SweepError(origin + ":" + std::to_string(begin.line) + ":" +
                             std::to_string(begin.column) +
                             ": TOML syntax error: " + std::string(e.description()));
        }
    } else {
        try {
            object = Json::parse(text);
        } catch (const nlohmann::json::exception& e) {
            // parse_error, or out_of_range for a number such as 1e999 (found by sweep_fuzzer)
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
            fail(origin, "view=all makes more than " +
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
                fail(spec.origin, "--threads given but 'threads' is an axis of the sweep");
        if (!spec.cases.empty())
            for (const SweepSetting& s : spec.cases.front())
                if (s.key == "threads")
                    fail(spec.origin, "--threads given but 'threads' is set by the cases");
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
        fail(spec.origin,
             (jobCount < 1e18 ? std::to_string(uint64_t(jobCount)) : "more than 10^18") +
                 " jobs refused (at most " + std::to_string(scenes::limits::kMaxSweepJobs) + ")");
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
