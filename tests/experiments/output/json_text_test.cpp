// File names in JSON (issue 32, class 8): the reversible escape of output/JsonText.h, on
// hand-made byte strings and generated ones (every round trip exact, every escape valid UTF-8
// that nlohmann dumps without throwing).
#include <gtest/gtest.h>

#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "experiments/output/JsonText.h"

namespace experiments {
namespace {

TEST(JsonText, HandMadeCases) {
    EXPECT_EQ(bytesForJson("scenes/atrium.json"), "scenes/atrium.json"); // UTF-8: unchanged
    EXPECT_EQ(bytesForJson("caf\xc3\xa9/\xe2\x82\xac.json"), "caf\xc3\xa9/\xe2\x82\xac.json");
    EXPECT_EQ(bytesForJson("sc\xff\xfe.json"), "sc\\xFF\\xFE.json");
    EXPECT_EQ(bytesForJson("a\\b"), "a\\\\b");
    EXPECT_EQ(bytesForJson("lit\\xFF"), "lit\\\\xFF"); // a literal escape stays distinguishable
    EXPECT_EQ(bytesForJson("\xc0\xaf"), "\\xC0\\xAF"); // overlong '/'
    EXPECT_EQ(bytesForJson("\xed\xa0\x80"), "\\xED\\xA0\\x80"); // surrogate
    EXPECT_EQ(bytesForJson("\xe2\x82"), "\\xE2\\x82");          // cut short
    for (const char* bytes : {"sc\xff\xfe.json", "a\\b", "lit\\xFF", "\xc0\xaf", "", "\\"})
        EXPECT_EQ(bytesFromJson(bytesForJson(bytes)), bytes);
    EXPECT_EQ(pathFromJson(pathForJson(std::filesystem::path("/tmp/o\xff/x"))),
              std::filesystem::path("/tmp/o\xff/x"));
}

TEST(JsonText, GeneratedByteStringsRoundTripThroughJson) {
    std::mt19937 random(8);
    const std::string pieces[] = {"\\",   "x", "F", "\xff", "\xc3\xa9",         "\xe2\x82\xac",
                                  "\xc3", "/", "a", "\x80", "\xf0\x9f\x98\x80", "\\x4",
                                  "\n",   "\""};
    for (int trial = 0; trial < 2000; ++trial) {
        std::string bytes;
        const int length = int(random() % 12);
        for (int i = 0; i < length; ++i)
            bytes += pieces[random() % std::size(pieces)];
        const std::string text = bytesForJson(bytes);
        std::string dumped;
        ASSERT_NO_THROW(dumped = nlohmann::json(text).dump()) << trial;
        EXPECT_EQ(bytesFromJson(nlohmann::json::parse(dumped).get<std::string>()), bytes) << trial;
    }
}

} // namespace
} // namespace experiments
