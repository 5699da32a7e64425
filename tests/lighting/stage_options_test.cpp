// The stage registry and the stages' option tables (StageRegistry.h, StageOptions.h), driven by
// the tables themselves: every registered stage, every option of its table. A stage registered
// later, or an option added to a table, is covered without editing this file; only the expected
// list of today's stages below names them, to catch a stage whose registrar the link dropped.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "lighting/StageRegistry.h"

namespace {

using lighting::StageOption;
using lighting::StageOptionType;

// The StageError message of `spec`, or "" when it is accepted.
std::string errorOf(const std::string& spec) {
    try {
        lighting::makeStage(spec);
    } catch (const lighting::StageError& error) {
        return error.what();
    }
    return "";
}

// Values the option's rule refuses: out of range and malformed.
std::vector<std::string> refusedValues(const StageOption& option) {
    switch (option.type) {
    case StageOptionType::Int:
        return {std::to_string(int(option.minValue) - 1),
                std::to_string(int(option.maxValue) + 1),
                "",
                "x",
                "1.5",
                "12abc",
                " 16",
                "99999999999999999999"};
    case StageOptionType::Bool:
        return {"", "2", "-1", "yes", "01", "truee"};
    case StageOptionType::Float: {
        std::vector<std::string> values = {"", "x", "nan", "inf", "0.5y", "1e999"};
        values.push_back(option.minExclusive ? std::to_string(option.minValue)
                                             : std::to_string(option.minValue - 1.0));
        values.push_back(std::to_string(option.maxValue * 2.0 + 1.0));
        return values;
    }
    case StageOptionType::Choice:
        return {"", "no_such_choice", option.choices.front() + "x"};
    case StageOptionType::Text:
        return {"", "no_such_value", "0x0x0"};
    }
    return {};
}

TEST(StageRegistry, ListsTodaysStagesInTheirFixedOrder) {
    // Also the guard that every stage file was linked: a registrar dropped by the static link
    // would shorten this list.
    const std::vector<std::string> expected = {
        "reference",          "brute",         "ideal",
        "deferred",           "light-indexed", "clustered",
        "clustered-explicit", "tiled",         "zbinned",
        "tiled-backface",     "forward",       "forward-multipass",
        "light-prepass",      "inferred",      "tiled-forward"};
    std::vector<std::string> names;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        names.push_back(info.name);
    EXPECT_EQ(names, expected);
    std::set<int> orders;
    for (const lighting::StageInfo& info : lighting::stageInfos())
        EXPECT_TRUE(orders.insert(info.listOrder).second) << info.name << ": listOrder taken";
}

TEST(StageRegistry, UnknownStageNamesTheValidOnesAndTheClosest) {
    const std::string message = errorOf("tiled-backfase");
    EXPECT_NE(message.find("unknown stage 'tiled-backfase'"), std::string::npos) << message;
    EXPECT_NE(message.find("did you mean 'tiled-backface'"), std::string::npos) << message;
    EXPECT_NE(message.find("valid: reference, brute"), std::string::npos) << message;
}

TEST(StageOptionTables, EveryOptionIsDocumentedAndItsDefaultParses) {
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        EXPECT_FALSE(info.description.empty()) << info.name;
        // The options are listed from the table, not written into the description.
        EXPECT_EQ(info.description.find('='), std::string::npos) << info.name;
        const std::map<std::string, std::string> defaults =
            lighting::resolvedStageOptions(info.name);
        EXPECT_EQ(defaults.size(), info.options.size()) << info.name;
        std::set<std::string> keys;
        for (const StageOption& option : info.options) {
            const std::string label = info.name + ":" + option.key;
            EXPECT_TRUE(keys.insert(option.key).second) << label << " listed twice";
            EXPECT_FALSE(option.doc.empty()) << label;
            EXPECT_FALSE(option.range().empty()) << label;
            EXPECT_EQ(defaults.at(option.key), option.defaultText) << label;
            // The default given explicitly is accepted and resolves to itself.
            const std::string spec = label + "=" + option.defaultText;
            EXPECT_EQ(errorOf(spec), "") << spec;
            EXPECT_EQ(lighting::resolvedStageOptions(spec).at(option.key), option.defaultText)
                << spec;
        }
    }
}

TEST(StageOptionTables, OutOfRangeAndMalformedValuesAreRefusedNamingStageKeyAndValue) {
    for (const lighting::StageInfo& info : lighting::stageInfos())
        for (const StageOption& option : info.options)
            for (const std::string& value : refusedValues(option)) {
                const std::string spec = info.name + ":" + option.key + "=" + value;
                const std::string message = errorOf(spec);
                EXPECT_NE(message.find("stage '" + info.name + "': option " + option.key + "=" +
                                       value + " is not "),
                          std::string::npos)
                    << spec << " -> " << message;
                EXPECT_NE(
                    message.find(option.type == StageOptionType::Bool ? "1/0" : option.range()),
                    std::string::npos)
                    << spec << " -> " << message;
            }
}

TEST(StageOptionTables, UnknownKeysAreRefusedWithTheValidOnesAndTheClosest) {
    for (const lighting::StageInfo& info : lighting::stageInfos()) {
        const std::string message = errorOf(info.name + ":no_such_option=1");
        EXPECT_NE(message.find("stage '" + info.name + "': unknown option 'no_such_option'"),
                  std::string::npos)
            << message;
        for (const StageOption& option : info.options)
            EXPECT_NE(message.find(option.key), std::string::npos) << message;
        if (info.options.empty())
            EXPECT_NE(message.find("valid: none"), std::string::npos) << message;
    }
    for (const auto& [spec, closest] : std::map<std::string, std::string>{
             {"tiled:til=8", "tile"}, {"deferred:stencl=1", "stencil"}}) {
        const std::string message = errorOf(spec);
        EXPECT_NE(message.find("did you mean '" + closest + "'"), std::string::npos) << message;
    }
}

TEST(StageOptionTables, ResolvedOptionsAreCanonical) {
    const auto tiled = lighting::resolvedStageOptions("tiled:vfc=off,tile=032,hier=on");
    EXPECT_EQ(tiled,
              (std::map<std::string, std::string>{
                  {"tile", "32"}, {"vfc", "0"}, {"mask", "0"}, {"assign", "loop"}, {"hier", "1"}}));
    EXPECT_EQ(lighting::resolvedStageOptions("inferred:depth=0.10,normal=-1").at("depth"), "0.1");
    EXPECT_EQ(lighting::resolvedStageOptions("inferred:normal=-1.0").at("normal"), "-1");
    EXPECT_EQ(lighting::resolvedStageOptions("clustered:grid=8x4x16").at("grid"), "8x4x16");
    EXPECT_EQ(lighting::resolvedStageOptions("clustered").at("grid"), "24x12x32");
}

TEST(StageOptionTables, RulesBetweenOptionsStayWithTheStage) {
    // `spot` applies to sphere volumes only: the table accepts both keys, the factory refuses.
    const std::string message = errorOf("deferred:volume=rect,spot=cone");
    EXPECT_NE(message.find("option spot applies to volume=sphere only"), std::string::npos)
        << message;
    EXPECT_EQ(errorOf("deferred:volume=rect"), "");
}

} // namespace
