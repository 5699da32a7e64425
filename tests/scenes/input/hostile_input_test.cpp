// Hostile input files for the scene side (issue 32, classes 5, 6 and 7): keys given twice in JSON
// scenes, glTF and GLB JSON chunks (and the pre-scan itself, on paths, escapes and malformed
// text); paths that are not regular files (a FIFO, /dev/zero behind a .json or .gltf name, a
// folder) or are over the size cap; and the escaping of control characters and invalid UTF-8 in
// messages. A read that would hang is run in a child process with an alarm, so a regression
// fails the test instead of hanging the suite. Every input is generated here.
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "scenes/SceneLoader.h"
#include "scenes/input/DuplicateKeys.h"
#include "scenes/input/MessageText.h"
#include "scenes/input/WholeFile.h"

namespace {

namespace fs = std::filesystem;
using scenes::SceneError;

fs::path testDirectory() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path directory =
        fs::path(::testing::TempDir()) /
        (std::string("hostile_input_test.") + test->test_suite_name() + "." + test->name());
    fs::remove_all(directory);
    fs::create_directories(directory);
    return directory;
}

void writeFile(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

// Runs check in a child process that SIGALRM ends after kSeconds: a read that blocks on a FIFO
// or never ends on /dev/zero fails the test (it is a hang detector, not a timing measurement).
// Returns the child's exit code: check's result, or 128 + the signal that ended it.
constexpr unsigned kSeconds = 5;
int runBounded(const std::function<int()>& check) {
    const pid_t child = fork();
    if (child == 0) {
        alarm(kSeconds);
        _exit(check());
    }
    int status = 0;
    waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The message of the SceneError that loading path throws, or "(no error)".
std::string sceneError(const fs::path& path) {
    try {
        scenes::loadScene(path.string(), scenes::SceneRequest{});
    } catch (const SceneError& error) {
        return error.what();
    }
    return "(no error)";
}

TEST(DuplicateKeys, FindsTheFirstRepeatWithItsPath) {
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"a": 1, "b": 2})"), "");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"a": 1, "a": 2})"), "a");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"axes": {"stage": [1], "stage": [2]}})"), "axes.stage");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"o": [{"x": 1}, {"y": 1, "y": 2}]})"), "o[1].y");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"o": [1, [2, {"z": 0, "z": 0}]]})"), "o[1][1].z");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"([{"k": 1}, {"k": 2, "k": 3}])"), "[1].k");
    // Keys are compared unescaped, as the parser would store them.
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"stage": 1, "st\u0061ge": 2})"), "stage");
    // The same key in sibling or nested objects is fine.
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"a": {"a": {"a": 1}}, "b": {"a": 2}})"), "");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"([{"a": 1}, {"a": 2}])"), "");
    // Malformed text is the parser's to report; a repeat before the damage is still found.
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"a": 1, "b": )"), "");
    EXPECT_EQ(scenes::jsonDuplicateKey(R"({"a": 1, "a": )"), "a");
    EXPECT_EQ(scenes::jsonDuplicateKey("not json"), "");
    EXPECT_EQ(scenes::jsonDuplicateKey(""), "");
    EXPECT_EQ(scenes::jsonDuplicateKeyProblem(R"({"axes": {"stage": 1, "stage": 2}})"),
              "key 'axes.stage' is given twice in the same object");
}

TEST(DuplicateKeys, JsonSceneIsRefusedWithThePathAndTheFile) {
    const fs::path dir = testDirectory();
    const fs::path file = dir / "twice.json";
    writeFile(file, R"({"objects": [{"procedural": "spheres"}],
        "lights": [{"type": "point", "position": [0, 1, 0], "range": 3, "range": 30}]})");
    EXPECT_EQ(sceneError(file),
              file.string() + ": key 'lights[0].range' is given twice in the same object");
    writeFile(file, R"({"objects": [{"procedural": "spheres"}], "objects": []})");
    EXPECT_EQ(sceneError(file),
              file.string() + ": key 'objects' is given twice in the same object");
}

TEST(DuplicateKeys, GltfAndGlbJsonChunkAreRefused) {
    const fs::path dir = testDirectory();
    const std::string json =
        R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0, "scene": 0})";
    writeFile(dir / "twice.gltf", json);
    EXPECT_EQ(sceneError(dir / "twice.gltf"),
              (dir / "twice.gltf").string() + ": key 'scene' is given twice in the same object");

    std::string chunk = R"({"asset": {"version": "2.0", "version": "1.0"}})";
    while (chunk.size() % 4 != 0)
        chunk += ' ';
    const auto word = [](uint32_t value) {
        return std::string(reinterpret_cast<char*>(&value), 4);
    };
    const std::string glb = "glTF" + word(2) + word(uint32_t(20 + chunk.size())) +
                            word(uint32_t(chunk.size())) + "JSON" + chunk;
    writeFile(dir / "twice.glb", glb);
    EXPECT_EQ(sceneError(dir / "twice.glb"), (dir / "twice.glb").string() +
                                                 ": key 'asset.version' is given twice in the "
                                                 "same object");
}

TEST(WholeFile, ReadsARegularFileAndRefusesEverythingElseWithoutOpeningIt) {
    const fs::path dir = testDirectory();
    writeFile(dir / "small.json", "{}");
    std::string bytes;
    EXPECT_EQ(scenes::readWholeFile(dir / "small.json", &bytes), "");
    EXPECT_EQ(bytes, "{}");
    EXPECT_EQ(scenes::readWholeFile(dir / "small.json", &bytes, 1),
              "has 2 bytes, more than the limit of 1");
    EXPECT_TRUE(bytes.empty());
    EXPECT_EQ(scenes::readWholeFile(dir / "missing.json", &bytes), "file not found");
    EXPECT_EQ(scenes::readWholeFile(dir, &bytes), "is a directory, not a regular file");

    ASSERT_EQ(mkfifo((dir / "fifo.json").c_str(), 0600), 0) << std::strerror(errno);
    fs::create_symlink("/dev/zero", dir / "zero.json");
    std::vector<unsigned char> buffer;
    EXPECT_EQ(scenes::regularFileProblem(dir / "fifo.json"),
              "is a FIFO (named pipe), not a regular file");
    EXPECT_EQ(scenes::regularFileProblem(dir / "zero.json"),
              "is a character device, not a regular file");
    // No writer ever opens the FIFO: opening it for reading would block for ever.
    EXPECT_EQ(runBounded([&] {
                  std::string text;
                  return scenes::readWholeFile(dir / "fifo.json", &text) ==
                                 "is a FIFO (named pipe), not a regular file"
                             ? 0
                             : 1;
              }),
              0);
    EXPECT_EQ(runBounded([&] {
                  std::vector<unsigned char> data;
                  return scenes::readWholeFile(dir / "zero.json", &data) ==
                                 "is a character device, not a regular file"
                             ? 0
                             : 1;
              }),
              0);
}

TEST(WholeFile, SceneLoadersRefuseSpecialFilesWithTheirName) {
    const fs::path dir = testDirectory();
    ASSERT_EQ(mkfifo((dir / "fifo.json").c_str(), 0600), 0);
    ASSERT_EQ(mkfifo((dir / "fifo.gltf").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", dir / "zero.glb");
    fs::create_directory(dir / "folder.json");
    const std::vector<std::pair<fs::path, std::string>> cases = {
        {dir / "fifo.json", "is a FIFO (named pipe), not a regular file"},
        {dir / "fifo.gltf", "is a FIFO (named pipe), not a regular file"},
        {dir / "zero.glb", "is a character device, not a regular file"},
        {dir / "folder.json", "is a directory, not a regular file"},
    };
    // Not a structured binding: clang 14 (the sanitizer build) cannot capture one in a lambda.
    for (const auto& testCase : cases) {
        const fs::path& path = testCase.first;
        const std::string& problem = testCase.second;
        EXPECT_EQ(runBounded([&] {
                      const std::string error = sceneError(path);
                      if (error == path.string() + ": " + problem)
                          return 0;
                      std::fprintf(stderr, "%s\n", error.c_str());
                      return 1;
                  }),
                  0)
            << path;
    }
}

TEST(WholeFile, GltfBufferThatIsAFifoIsRefused) {
    const fs::path dir = testDirectory();
    ASSERT_EQ(mkfifo((dir / "data.bin").c_str(), 0600), 0);
    writeFile(dir / "model.gltf", R"({"asset": {"version": "2.0"},
        "buffers": [{"uri": "data.bin", "byteLength": 12}]})");
    EXPECT_EQ(runBounded([&] {
                  const std::string error = sceneError(dir / "model.gltf");
                  return error.find((dir / "model.gltf").string()) == 0 ? 0 : 1;
              }),
              0);
}

TEST(MessageText, EscapesControlsAndInvalidUtf8AndKeepsTheRest) {
    using scenes::escapeControlCharacters;
    EXPECT_EQ(escapeControlCharacters("plain text, 100% ok"), "plain text, 100% ok");
    EXPECT_EQ(escapeControlCharacters("a\nb\r\tc"), "a\\nb\\r\\tc");
    EXPECT_EQ(escapeControlCharacters("\n testbed: error: forged\x1b[31m"),
              "\\n testbed: error: forged\\x1b[31m");
    EXPECT_EQ(escapeControlCharacters(std::string("nul\0del\x7f", 8)), "nul\\x00del\\x7f");
    // Valid UTF-8 passes: Latin, CJK, the FLIP letter, an emoji.
    EXPECT_EQ(escapeControlCharacters("caf\xc3\xa9 \xe6\x97\xa5 \xea\x9f\xbb \xf0\x9f\x99\x82"),
              "caf\xc3\xa9 \xe6\x97\xa5 \xea\x9f\xbb \xf0\x9f\x99\x82");
    // Invalid: a lone continuation byte, 0xff, an overlong '/', a UTF-16 surrogate, past
    // U+10FFFF, a sequence cut short by the end.
    EXPECT_EQ(escapeControlCharacters("\x80"), "\\x80");
    EXPECT_EQ(escapeControlCharacters("a\xff"
                                      "b"),
              "a\\xffb");
    EXPECT_EQ(escapeControlCharacters("\xc0\xaf"), "\\xc0\\xaf");
    EXPECT_EQ(escapeControlCharacters("\xed\xa0\x80"), "\\xed\\xa0\\x80");
    EXPECT_EQ(escapeControlCharacters("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");
    EXPECT_EQ(escapeControlCharacters("\xe6\x97"), "\\xe6\\x97");
    // C1 CSI (U+009B) and a right-to-left override (U+202E) are valid but act on the display.
    EXPECT_EQ(escapeControlCharacters("\xc2\x9b"
                                      "31m"),
              "\\u009b31m");
    EXPECT_EQ(escapeControlCharacters("x\xe2\x80\xaey"), "x\\u202ey");
    // HTML keeps line breaks, which are only white space there.
    EXPECT_EQ(escapeControlCharacters("a\nb\x1b", scenes::LineBreaks::Keep), "a\nb\\x1b");
}

} // namespace
