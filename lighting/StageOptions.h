// StageOptions: a stage's options as a typed table, and the values one spec gives them.
//
// Each stage declares its options once, as a list of StageOption rows (key, type, default, the
// accepted range or choices, a one-line doc), in its own file under lighting/stages/. From that
// one table:
//   - parseStageOptions() checks a spec's `key=value` pairs (unknown keys, malformed and
//     out-of-range values are StageErrors naming the stage and the key) and hands the factory the
//     typed values, defaults filled in (StageOptions);
//   - `testbed list` prints every option with its type, default, range and doc (describe());
//   - stats.json records the resolved options (StageOptions::resolved(): every key, defaults
//     included, as canonical text).
// So an option cannot be accepted without being listed and recorded, nor listed with a default
// other than the one the stage runs with.
//
// Canonical text (what resolved() and the listing show): integers in decimal, booleans 1|0,
// numbers in the shortest form that reads back as the same float, choices and text as given.
// Booleans accept 1/0, on/off, true/false.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace lighting {

enum class StageOptionType { Int, Bool, Float, Choice, Text };

// One row of a stage's option table. Build rows with the named constructors below; the default
// is valid by construction (a test checks it against the row's own rule).
struct StageOption {
    std::string key;
    StageOptionType type = StageOptionType::Int;
    std::string defaultText;          // canonical text of the default
    double minValue = 0.0;            // Int, Float: the accepted range, inclusive...
    double maxValue = 0.0;            //
    bool minExclusive = false;        // ... except the minimum when set (Float)
    std::vector<std::string> choices; // Choice: the accepted values, the first is the default
    // Text: the accepted form, in words for the listing and the error ("XxYxZ with ..."), and
    // its check: the canonical text of an accepted `value`, nullopt for a refused one.
    std::string form;
    std::function<std::optional<std::string>(const std::string& value)> canonical;
    std::string doc; // one line: what the option does

    static StageOption integer(std::string key, int defaultValue, int minValue, int maxValue,
                               std::string doc);
    static StageOption boolean(std::string key, bool defaultValue, std::string doc);
    // A float in [minValue, maxValue], or (minValue, maxValue] when minExclusive.
    static StageOption number(std::string key, float defaultValue, float minValue, float maxValue,
                              bool minExclusive, std::string doc);
    static StageOption choice(std::string key, std::vector<std::string> choices, std::string doc);
    static StageOption text(std::string key, std::string defaultValue, std::string form,
                            std::function<std::optional<std::string>(const std::string&)> canonical,
                            std::string doc);

    // The accepted values in words, for the listing and the errors: "4..128", "1|0",
    // "(0, 1e+30]", "sphere|rect", or the form of a Text option.
    std::string range() const;
    // "int", "bool", "float", "choice" or "text".
    const char* typeName() const;
};

// The typed values one spec gives a stage's options, defaults filled in. The accessors name a key
// of the stage's table with the matching type; anything else is a programming error
// (std::logic_error).
class StageOptions {
public:
    StageOptions() = default;
    StageOptions(std::string stageName, std::vector<StageOption> table,
                 std::map<std::string, std::string> canonical, std::vector<std::string> given);

    const std::string& stageName() const { return mStageName; }
    int integer(const std::string& key) const;
    bool boolean(const std::string& key) const;
    float number(const std::string& key) const;
    const std::string& text(const std::string& key) const; // Choice or Text
    // Whether the spec set the key (for rules between options, e.g. `spot` needs volume=sphere).
    bool given(const std::string& key) const;
    // Every option of the table: key -> canonical text (what stats.json records).
    const std::map<std::string, std::string>& resolved() const { return mCanonical; }

private:
    const StageOption& row(const std::string& key, StageOptionType type) const;

    std::string mStageName;
    std::vector<StageOption> mTable;
    std::map<std::string, std::string> mCanonical;
    std::vector<std::string> mGiven;
};

// Checks `options` (a spec's key=value pairs) against `table` for stage `stageName`: a StageError
// (StageRegistry.h) naming the stage and the key for an unknown key (with a did-you-mean and the
// valid keys), and naming the key, the value and what is accepted for a malformed or
// out-of-range value.
StageOptions parseStageOptions(const std::string& stageName, const std::vector<StageOption>& table,
                               const std::map<std::string, std::string>& options);

} // namespace lighting
