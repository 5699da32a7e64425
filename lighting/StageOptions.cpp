#include "lighting/StageOptions.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "lighting/StageRegistry.h"
#include "scenes/input/ClosestName.h"

namespace lighting {

namespace {

// The shortest text that reads back as the same float.
std::string floatText(float value) {
    char buffer[64];
    const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
    return error == std::errc() ? std::string(buffer, end) : std::to_string(value);
}

std::string joined(const std::vector<std::string>& items, const char* separator) {
    std::string text;
    for (const std::string& item : items)
        text += (text.empty() ? "" : separator) + item;
    return text;
}

// Reads the whole of `text` with `convert` (std::stoi or std::stof, which alone accept "12x" and
// " 12" and throw on overflow): false unless every character was used.
template <class T, class Convert>
bool parseWhole(const std::string& text, T& value, Convert convert) {
    if (text.empty() || std::isspace(static_cast<unsigned char>(text.front())))
        return false;
    size_t used = 0;
    try {
        value = convert(text, &used);
    } catch (const std::exception&) {
        return false;
    }
    return used == text.size();
}

bool parseInteger(const std::string& text, int& value) {
    return parseWhole(text, value,
                      [](const std::string& t, size_t* used) { return std::stoi(t, used); });
}

bool parseFloat(const std::string& text, float& value) {
    return parseWhole(text, value,
                      [](const std::string& t, size_t* used) { return std::stof(t, used); }) &&
           std::isfinite(value);
}

// The canonical text of `value` for `option`, or a StageError naming the stage, key and value.
std::string canonicalValue(const std::string& stageName, const StageOption& option,
                           const std::string& value) {
    const std::string prefix = "stage '" + stageName + "': option " + option.key + "=" + value;
    switch (option.type) {
    case StageOptionType::Int: {
        int parsed = 0;
        if (!parseInteger(value, parsed) || parsed < option.minValue || parsed > option.maxValue)
            throw StageError(prefix + " is not an integer in " + option.range());
        return std::to_string(parsed);
    }
    case StageOptionType::Bool:
        if (value == "1" || value == "on" || value == "true")
            return "1";
        if (value == "0" || value == "off" || value == "false")
            return "0";
        throw StageError(prefix + " is not a boolean (1/0, on/off, true/false)");
    case StageOptionType::Float: {
        float parsed = 0.0f;
        if (!parseFloat(value, parsed) ||
            !(option.minExclusive ? parsed > option.minValue : parsed >= option.minValue) ||
            parsed > option.maxValue)
            throw StageError(prefix + " is not a number in " + option.range());
        return floatText(parsed);
    }
    case StageOptionType::Choice:
        if (std::find(option.choices.begin(), option.choices.end(), value) == option.choices.end())
            throw StageError(prefix + " is not one of " + option.range());
        return value;
    case StageOptionType::Text: {
        const std::optional<std::string> text = option.canonical(value);
        if (!text)
            throw StageError(prefix + " is not " + option.form);
        return *text;
    }
    }
    throw std::logic_error("StageOption: unknown type");
}

} // namespace

StageOption StageOption::integer(std::string key, int defaultValue, int minValue, int maxValue,
                                 std::string doc) {
    StageOption option;
    option.key = std::move(key);
    option.type = StageOptionType::Int;
    option.defaultText = std::to_string(defaultValue);
    option.minValue = minValue;
    option.maxValue = maxValue;
    option.doc = std::move(doc);
    return option;
}

StageOption StageOption::boolean(std::string key, bool defaultValue, std::string doc) {
    StageOption option;
    option.key = std::move(key);
    option.type = StageOptionType::Bool;
    option.defaultText = defaultValue ? "1" : "0";
    option.minValue = 0;
    option.maxValue = 1;
    option.doc = std::move(doc);
    return option;
}

StageOption StageOption::number(std::string key, float defaultValue, float minValue, float maxValue,
                                bool minExclusive, std::string doc) {
    StageOption option;
    option.key = std::move(key);
    option.type = StageOptionType::Float;
    option.defaultText = floatText(defaultValue);
    option.minValue = minValue;
    option.maxValue = maxValue;
    option.minExclusive = minExclusive;
    option.doc = std::move(doc);
    return option;
}

StageOption StageOption::choice(std::string key, std::vector<std::string> choices,
                                std::string doc) {
    StageOption option;
    option.key = std::move(key);
    option.type = StageOptionType::Choice;
    option.defaultText = choices.at(0);
    option.choices = std::move(choices);
    option.doc = std::move(doc);
    return option;
}

StageOption
StageOption::text(std::string key, std::string defaultValue, std::string form,
                  std::function<std::optional<std::string>(const std::string&)> canonical,
                  std::string doc) {
    StageOption option;
    option.key = std::move(key);
    option.type = StageOptionType::Text;
    option.defaultText = std::move(defaultValue);
    option.form = std::move(form);
    option.canonical = std::move(canonical);
    option.doc = std::move(doc);
    return option;
}

std::string StageOption::range() const {
    switch (type) {
    case StageOptionType::Int:
        return std::to_string(int(minValue)) + ".." + std::to_string(int(maxValue));
    case StageOptionType::Bool:
        return "1|0";
    case StageOptionType::Float:
        return (minExclusive ? "(" : "[") + floatText(float(minValue)) + ", " +
               floatText(float(maxValue)) + "]";
    case StageOptionType::Choice:
        return joined(choices, "|");
    case StageOptionType::Text:
        return form;
    }
    return "";
}

const char* StageOption::typeName() const {
    switch (type) {
    case StageOptionType::Int:
        return "int";
    case StageOptionType::Bool:
        return "bool";
    case StageOptionType::Float:
        return "float";
    case StageOptionType::Choice:
        return "choice";
    case StageOptionType::Text:
        return "text";
    }
    return "";
}

StageOptions::StageOptions(std::string stageName, std::vector<StageOption> table,
                           std::map<std::string, std::string> canonical,
                           std::vector<std::string> given)
    : mStageName(std::move(stageName)), mTable(std::move(table)), mCanonical(std::move(canonical)),
      mGiven(std::move(given)) {}

const StageOption& StageOptions::row(const std::string& key, StageOptionType type) const {
    for (const StageOption& option : mTable)
        if (option.key == key) {
            if (option.type != type)
                throw std::logic_error("stage '" + mStageName + "': option " + key +
                                       " read as another type than its table's");
            return option;
        }
    throw std::logic_error("stage '" + mStageName + "': option " + key + " is not in its table");
}

int StageOptions::integer(const std::string& key) const {
    row(key, StageOptionType::Int);
    return std::stoi(mCanonical.at(key));
}

bool StageOptions::boolean(const std::string& key) const {
    row(key, StageOptionType::Bool);
    return mCanonical.at(key) == "1";
}

float StageOptions::number(const std::string& key) const {
    row(key, StageOptionType::Float);
    // The canonical text is the shortest that reads back as the same float.
    float value = 0.0f;
    const std::string& text = mCanonical.at(key);
    std::from_chars(text.data(), text.data() + text.size(), value);
    return value;
}

const std::string& StageOptions::text(const std::string& key) const {
    const auto found = std::find_if(mTable.begin(), mTable.end(),
                                    [&](const StageOption& option) { return option.key == key; });
    row(key, found != mTable.end() && found->type == StageOptionType::Text
                 ? StageOptionType::Text
                 : StageOptionType::Choice);
    return mCanonical.at(key);
}

bool StageOptions::given(const std::string& key) const {
    return std::find(mGiven.begin(), mGiven.end(), key) != mGiven.end();
}

StageOptions parseStageOptions(const std::string& stageName, const std::vector<StageOption>& table,
                               const std::map<std::string, std::string>& options) {
    std::vector<std::string> keys;
    for (const StageOption& option : table)
        keys.push_back(option.key);
    std::vector<std::string> given;
    for (const auto& [key, value] : options) {
        if (std::find(keys.begin(), keys.end(), key) == keys.end())
            throw StageError("stage '" + stageName + "': unknown option '" + key + "'" +
                             scenes::didYouMean(key, keys) +
                             " (valid: " + (keys.empty() ? "none" : joined(keys, ", ")) + ")");
        given.push_back(key);
    }
    std::map<std::string, std::string> canonical;
    for (const StageOption& option : table) {
        const auto found = options.find(option.key);
        canonical[option.key] = found == options.end()
                                    ? option.defaultText
                                    : canonicalValue(stageName, option, found->second);
    }
    return StageOptions(stageName, table, std::move(canonical), std::move(given));
}

} // namespace lighting
