// StagedFolder (issue 32, class 4): a run's outputs are staged inside the destination and moved
// into place only on commit; a run that throws first leaves the destination byte for byte as it
// was (snapshots of the folder before and after are compared), and a new destination is not
// left behind at all. Hand-made cases plus generated ones: random trees of old files and random
// failure points.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <stdexcept>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include "experiments/output/AtomicFile.h"
#include "experiments/output/StagedFolder.h"
#include "tests/experiments/TestFolders.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using test_files::freshTestFolder;
using test_files::readText;

// Every entry below dir (relative path -> file contents, or "<dir>" for a folder).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> entries;
    if (!fs::exists(dir))
        return entries;
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir))
        entries[entry.path().lexically_relative(dir).string()] =
            entry.is_directory() ? "<dir>" : readText(entry.path());
    return entries;
}

void writeFile(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

TEST(StagedFolder, AFailedRunLeavesTheFolderAsItWas) {
    const fs::path dir = freshTestFolder() / "out";
    fs::create_directories(dir / "views");
    writeFile(dir / "render.exr", "old render");
    writeFile(dir / "stats.json", "old stats");
    writeFile(dir / "notes.txt", "the user's");
    const auto before = snapshot(dir);
    EXPECT_THROW(
        {
            StagedFolder staged(dir);
            writeTextAtomically(staged.path() / "render.exr", "new render");
            writeTextAtomically(staged.path() / "preview.png", "new preview");
            throw std::runtime_error("the run fails after two files");
        },
        std::runtime_error);
    EXPECT_EQ(snapshot(dir), before);
}

TEST(StagedFolder, AFailedRunIntoANewFolderLeavesNoFolder) {
    const fs::path root = freshTestFolder();
    const fs::path dir = root / "a" / "b" / "out";
    try {
        StagedFolder staged(dir);
        EXPECT_TRUE(fs::is_directory(staged.path()));
        writeTextAtomically(staged.path() / "stats.json", "{}");
        throw std::runtime_error("fails");
    } catch (const std::runtime_error&) {
    }
    EXPECT_FALSE(fs::exists(root / "a"));
}

TEST(StagedFolder, CommitReplacesTheRunsFilesAndRemovesItsStaleOnes) {
    const fs::path dir = freshTestFolder() / "out";
    fs::create_directories(dir);
    writeFile(dir / "render.exr", "old render");
    writeFile(dir / "error.png", "old error map of a run with a reference");
    writeFile(dir / "notes.txt", "the user's");
    {
        StagedFolder staged(dir);
        writeTextAtomically(staged.path() / "render.exr", "new render");
        fs::create_directories(staged.path() / "views" / "v1");
        writeTextAtomically(staged.path() / "views" / "v1" / "stats.json", "{}");
        const std::vector<fs::path> committed = staged.commit({"render.exr", "error.png"});
        EXPECT_EQ(committed, (std::vector<fs::path>{"render.exr", "views/v1/stats.json"}));
    }
    EXPECT_EQ(snapshot(dir), (std::map<std::string, std::string>{{"notes.txt", "the user's"},
                                                                 {"render.exr", "new render"},
                                                                 {"views", "<dir>"},
                                                                 {"views/v1", "<dir>"},
                                                                 {"views/v1/stats.json", "{}"}}));
}

// A folder where a file goes: the commit is refused before its first rename.
TEST(StagedFolder, ARefusedCommitRenamesNothing) {
    const fs::path dir = freshTestFolder() / "out";
    fs::create_directories(dir / "stats.json");
    writeFile(dir / "render.exr", "old render");
    const auto before = snapshot(dir);
    EXPECT_THROW(
        {
            StagedFolder staged(dir);
            writeTextAtomically(staged.path() / "render.exr", "new render");
            writeTextAtomically(staged.path() / "stats.json", "{}");
            staged.commit();
        },
        std::runtime_error);
    EXPECT_EQ(snapshot(dir), before);
}

// A staging folder of a process killed before its commit is removed by the next writer there.
TEST(StagedFolder, AStaleStagingFolderIsRemoved) {
    const fs::path dir = freshTestFolder();
    const pid_t child = fork();
    if (child == 0) {
        // Leaves its staging folder behind: _exit skips the destructor.
        StagedFolder* staged = new StagedFolder(dir);
        writeTextAtomically(staged->path() / "render.exr", "half");
        _exit(0);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    size_t entries = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir))
        ++entries;
    ASSERT_EQ(entries, 1u);
    EXPECT_EQ(removeStaleTemporaries(dir), 1u);
    EXPECT_TRUE(fs::is_empty(dir));
}

// Generated: random old folders, random new outputs, a failure at a random point; the folder is
// unchanged after every failure and holds exactly the new outputs (plus files the run does not
// own) after every success.
TEST(StagedFolder, GeneratedRunsAreAllOrNothing) {
    const fs::path root = freshTestFolder();
    std::mt19937 random(32);
    const std::vector<std::string> names = {"render.exr", "preview.png", "heatmap.png",
                                            "error.png",  "flip.png",    "stats.json"};
    for (int trial = 0; trial < 40; ++trial) {
        const fs::path dir = root / ("trial" + std::to_string(trial));
        fs::create_directories(dir);
        for (const std::string& name : names)
            if (random() % 2)
                writeFile(dir / name, "old " + name + std::to_string(random()));
        writeFile(dir / "unowned.txt", "keep");
        const auto before = snapshot(dir);
        const size_t failAt = random() % (names.size() + 1); // names.size(): no failure
        std::map<std::string, std::string> expected = {{"unowned.txt", "keep"}};
        try {
            StagedFolder staged(dir);
            for (size_t i = 0; i < names.size(); ++i) {
                if (i == failAt)
                    throw std::runtime_error("injected");
                if (random() % 3 == 0)
                    continue; // this run does not write that output
                const std::string text = "new " + names[i];
                writeTextAtomically(staged.path() / names[i], text);
                expected[names[i]] = text;
            }
            staged.commit(names);
            EXPECT_EQ(snapshot(dir), expected) << "trial " << trial;
        } catch (const std::runtime_error&) {
            EXPECT_EQ(snapshot(dir), before) << "trial " << trial;
        }
    }
}

} // namespace
} // namespace experiments
