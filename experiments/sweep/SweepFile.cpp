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

#include <toml++/toml.h>

#include "experiments/render/RenderPlan.h"
#include "scenes/Viewpoints.h"
#include "scenes/input/DuplicateKeys.h"
#include "scenes/input/Limits.h"
#include "scenes/input/NestingDepth.h"
#include "scenes/input/WholeFile.h"

namespace experiments {

namespace {

using Json = nlohmann::ordered_json;

const std::vector<std::string> kTopLevelKeys = {
    "name",      "description", "notes",       "fixed",       "axes",
    "cases",     "warmup",      "repetitions", "reference",   "quick",
    "published", "heatmap-max", "error-max",   "error-scale", "job-timeout"};
const std::vector<std::string> kQuickKeys = {"fixed",  "axes",        "cases",
                                             "warmup", "repetitions", "reference"};
std::string joined(const std::vector<std::string>& items) {
    std::string text;
    for (const std::string& item : items)
        text += (text.empty() ? "" : ", ") + item;
    return text;
}

void rejectUnknownKeys(const Json& object, const std::vector<std::string>& known,
                       const std::string& origin, const std::string& where) {
    for (const auto& [key, value] : object.items())
        if (std::find(known.begin(), known.end(), key) == known.end())
            failSweep(origin, "unknown key '" + where + key + "'; valid keys: " + joined(known));
}

int readCount(const Json& value, const std::string& origin, const std::string& key, int minimum) {
    if (!value.is_number_integer() || value.get<int64_t>() < minimum ||
        value.get<int64_t>() > kMaxRunCount)
        failSweep(origin, "'" + key + "' must be an integer " + std::to_string(minimum) + ".." +
                              std::to_string(kMaxRunCount) + ", got " + value.dump());
    return value.get<int>();
}

void checkSettingValue(const Json& value, const std::string& origin, const std::string& where) {
    if (!value.is_string() && !value.is_number())
        failSweep(origin, "'" + where + "' must be a string or a number, got " + value.dump());
}

std::vector<SweepSetting> readSettings(const Json& object, const std::string& origin,
                                       const std::string& where) {
    if (!object.is_object())
        failSweep(origin, "'" + where + "' must be an object of key: value");
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
        failSweep(origin, "'" + where + "' must be an object of key: [values]");
    std::vector<std::pair<std::string, std::vector<Json>>> axes;
    for (const auto& [key, values] : object.items()) {
        if (!values.is_array() || values.empty())
            failSweep(origin, "'" + where + "." + key + "' must be a non-empty array of values");
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
        failSweep(origin, "'" + where + "' must be a non-empty array of objects");
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
            failSweep(origin, "'" + here + "' sets {" + joined(keys) + "} but '" + where +
                                  "[0]' sets {" + joined(firstKeys) +
                                  "}: every case sets the same keys");
    }
    return cases;
}

// A key may be set in one place only: fixed, axes or cases.
void checkDisjoint(const SweepSpec& spec, const std::string& where) {
    std::map<std::string, std::string> place;
    auto claim = [&](const std::string& key, const std::string& in) {
        const auto [it, inserted] = place.emplace(key, in);
        if (!inserted)
            failSweep(spec.origin, "key '" + key + "' is set in both '" + where + it->second +
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
        failSweep(origin, "'published' must be an array of tables");
    auto checkSelect = [&](const Json& item, const std::string& where) {
        if (!item.is_object() || !item.contains("select") || !item["select"].is_object())
            failSweep(origin, "'" + where + "' must be an object with a 'select' object");
        for (const auto& [key, value] : item["select"].items()) {
            if (std::find(columns.begin(), columns.end(), key) == columns.end())
                failSweep(origin, "'" + where + ".select." + key +
                                      "' is not a result column; axis columns: " + joined(columns));
            checkSettingValue(value, origin, where + ".select." + key);
        }
    };
    for (size_t t = 0; t < published.size(); ++t) {
        const Json& table = published[t];
        const std::string where = "published[" + std::to_string(t) + "]";
        if (!table.is_object())
            failSweep(origin, "'" + where + "' must be an object");
        rejectUnknownKeys(
            table,
            {"title", "source", "metric", "columns", "rows", "ratio_to", "finding", "modelled"},
            origin, where + ".");
        for (const char* key : {"title", "metric", "columns", "rows"})
            if (!table.contains(key))
                failSweep(origin, "'" + where + "' lacks '" + key + "'");
        const Json& metric = table["metric"];
        const bool metricOk =
            metric.is_string() || (metric.is_array() && !metric.empty() &&
                                   std::all_of(metric.begin(), metric.end(),
                                               [](const Json& m) { return m.is_string(); }));
        if (!metricOk)
            failSweep(origin, "'" + where + ".metric' must be a column name or a list of them");
        if (table.contains("modelled") && !table["modelled"].is_string())
            failSweep(origin,
                      "'" + where + ".modelled' must be a column name (e.g. simt_lane_slots)");
        const Json& tableColumns = table["columns"];
        if (!tableColumns.is_array() || tableColumns.empty())
            failSweep(origin, "'" + where + ".columns' must be a non-empty array");
        for (size_t c = 0; c < tableColumns.size(); ++c)
            checkSelect(tableColumns[c], where + ".columns[" + std::to_string(c) + "]");
        if (!table["rows"].is_array())
            failSweep(origin, "'" + where + ".rows' must be an array");
        for (size_t r = 0; r < table["rows"].size(); ++r) {
            const Json& row = table["rows"][r];
            const std::string here = where + ".rows[" + std::to_string(r) + "]";
            checkSelect(row, here);
            if (!row.contains("values") || !row["values"].is_array() ||
                row["values"].size() != tableColumns.size())
                failSweep(origin, "'" + here +
                                      ".values' must have one value (or null) per column (" +
                                      std::to_string(tableColumns.size()) + ")");
            for (const Json& v : row["values"])
                if (!v.is_number() && !v.is_null())
                    failSweep(origin,
                              "'" + here + ".values' holds " + v.dump() + ": numbers or null only");
        }
        if (table.contains("ratio_to") && (!table["ratio_to"].is_number_unsigned() ||
                                           table["ratio_to"].get<size_t>() >= tableColumns.size()))
            failSweep(origin, "'" + where + ".ratio_to' must be a column index 0.." +
                                  std::to_string(tableColumns.size() - 1));
    }
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

[[noreturn]] void failSweep(const std::string& origin, const std::string& message) {
    throw SweepError(origin + ": " + message);
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

bool isEveryView(const SweepSetting& setting) {
    return setting.key == "view" && setting.value.is_string() &&
           setting.value.get<std::string>() == kEveryView;
}

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
        failSweep(origin, "a sweep file holds one object");
    rejectUnknownKeys(object, kTopLevelKeys, origin, "");
    SweepSpec spec;
    spec.origin = origin;
    spec.source = object;
    auto text = [&](const char* key) -> std::string {
        if (!object.contains(key))
            return {};
        if (!object[key].is_string())
            failSweep(origin, std::string("'") + key + "' must be a string");
        return object[key].get<std::string>();
    };
    spec.name = text("name");
    spec.description = text("description");
    if (object.contains("notes") && !object["notes"].is_string() && !object["notes"].is_array())
        failSweep(origin, "'notes' must be a string or an array of strings");
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
            failSweep(origin, "'reference' must be true or false");
        spec.reference = object["reference"].get<bool>();
    }
    // Without settings the sweep would be one default render, which a typo'd or truncated file
    // must not silently become (`testbed render` is the way to make a default render).
    if (spec.fixed.empty() && spec.axes.empty() && spec.cases.empty())
        failSweep(origin, "the sweep sets nothing to run: it needs 'fixed' settings, 'axes' or "
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
            failSweep(origin, "'heatmap-max' must be a light count 0.." +
                                  std::to_string(kMaxLights) + " (0 = each image's maximum), got " +
                                  value.dump());
        spec.heatmapMax = value.get<uint32_t>();
    }
    if (object.contains("error-max")) {
        const Json& value = object["error-max"];
        if (!value.is_number() || !scaleMaximumProblem(value.get<double>()).empty())
            failSweep(origin, "'error-max' " + scaleMaximumProblem(-1.0) + ", got " + value.dump());
        spec.errorMax = value.get<double>();
    }
    if (object.contains("error-scale")) {
        const Json& value = object["error-scale"];
        if (!value.is_string() ||
            (value.get<std::string>() != "linear" && value.get<std::string>() != "log"))
            failSweep(origin, "'error-scale' must be \"linear\" or \"log\", got " + value.dump());
        spec.errorScale = parseMapScale(value.get<std::string>());
    }
    if (object.contains("job-timeout")) {
        const Json& value = object["job-timeout"];
        const std::string error =
            value.is_number()
                ? jobTimeoutError(value.get<double>(), "'job-timeout'")
                : "'job-timeout' must be a number of seconds (0 = no limit), got " + value.dump();
        if (!error.empty())
            failSweep(origin, error);
        spec.jobTimeoutSeconds = value.get<double>();
    }
    checkDisjoint(spec, "");
    std::set<std::string> keys = settingKeys(spec);
    if (object.contains("quick")) {
        const Json& quick = object["quick"];
        if (!quick.is_object())
            failSweep(origin, "'quick' must be an object");
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
    std::string text;
    if (const std::string problem = scenes::readWholeFile(file, &text); !problem.empty())
        throw SweepError(origin + ": " + problem);
    return readSweepText(text, origin, file.extension() == ".toml");
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
        // toml++ refuses a key given twice itself ("cannot redefine existing ..."); nlohmann
        // keeps the last, so JSON is checked first.
        if (const std::string problem = scenes::jsonDuplicateKeyProblem(text); !problem.empty())
            throw SweepError(origin + ": " + problem);
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
        failSweep(spec.origin, "--quick given but the sweep file has no 'quick' block");
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
            failSweep(spec.origin, "'quick.reference' must be true or false");
        result.reference = quick["reference"].get<bool>();
    }
    checkDisjoint(result, "quick: ");
    return result;
}

// view = "all" stands for every view of a scene, so it cannot sit beside named views in one
// axis (the named ones would run twice).
void checkEveryViewAlone(const SweepSpec& spec) {
    for (const auto& [key, values] : spec.axes) {
        if (key != "view" || values.size() < 2)
            continue;
        for (const Json& value : values)
            if (value.is_string() && value.get<std::string>() == kEveryView)
                failSweep(spec.origin, std::string("'axes.view' lists \"") + kEveryView +
                                           "\" beside other views; \"" + kEveryView +
                                           "\" already stands for every view of the scene, so it "
                                           "must be the axis' only value");
    }
}

} // namespace experiments
