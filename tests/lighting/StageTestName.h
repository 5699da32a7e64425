// The name of a test instantiated per stage: the stage's name with '-' as '_' (GoogleTest takes
// only letters, digits and underscores), for INSTANTIATE_TEST_SUITE_P over stage names.
#pragma once

#include <string>

#include <gtest/gtest.h>

namespace stagecheck {

inline std::string stageTestName(const ::testing::TestParamInfo<std::string>& info) {
    std::string name = info.param;
    for (char& c : name)
        if (c == '-')
            c = '_';
    return name;
}

} // namespace stagecheck
