// Helpers shared by the experiments tests that write files: a fresh output folder per test under
// the build tree (kept after the run as evidence; emptied when the test starts) and whole-file
// reads.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace experiments::test_files {

// <build>/test-output/experiments/<suite>.<test>/, empty.
inline std::filesystem::path freshTestFolder() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::filesystem::path dir = std::filesystem::path(TESTBED_BINARY_DIR) / "test-output" /
                                      "experiments" /
                                      (std::string(info->test_suite_name()) + "." + info->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

inline std::string readText(const std::filesystem::path& path) {
    std::ifstream file(path, std::ios::binary);
    std::ostringstream text;
    text << file.rdbuf();
    return text.str();
}

} // namespace experiments::test_files
