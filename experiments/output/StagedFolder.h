// StagedFolder: a result folder written all or nothing (issue 32, class 4: "a failed run leaves
// its output folder as it was"). Every output of a run is written into a hidden staging folder
// inside the destination; only when the run has finished without error does commit() move the
// staged files into place, one rename(2) each (atomic per file, the same file system). A run that
// throws before commit() leaves the destination byte for byte as it was: the destructor removes
// the staging folder and every folder the constructor created (the destination and its missing
// parents), so a failed run into a new folder leaves no folder behind either.
//
// Naming: the staging folder is "<dest>/.staged.tmp-<pid>-<counter>-<host>", the naming scheme of
// AtomicFile.h's temporaries, so a process killed before commit() leaves a folder that the next
// run writing into <dest> removes (removeStaleTemporaries removes stale staging folders as well
// as files).
//
// Replacing a previous run: commit(ownedNames) also removes the files of `ownedNames` that the
// destination holds but this run did not write (e.g. error.png of an earlier run with a reference,
// when this one had none), so the folder never mixes the outputs of two runs. Files the run does
// not own (anything else in the destination) are left alone.
//
// Scope: the commit is a sequence of renames inside one folder, each atomic; a crash in the
// middle of commit() (microseconds) leaves some new and some old files, never a partial file.
//
// Thread safety: one object per run; different objects may stage into the same destination.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace experiments {

class StagedFolder {
public:
    // Creates `destination` (and missing parents) if needed, proves it writable (as
    // ensureWritableDirectory does) and creates the staging folder in it. Throws
    // std::runtime_error("cannot write to output folder ...") like ensureWritableDirectory, after
    // removing what it created.
    explicit StagedFolder(const std::filesystem::path& destination);
    // Without commit(): removes the staging folder and the folders the constructor created.
    // Never throws (best effort).
    ~StagedFolder();
    StagedFolder(const StagedFolder&) = delete;
    StagedFolder& operator=(const StagedFolder&) = delete;

    // Where the run writes its outputs (sub-folders allowed).
    const std::filesystem::path& path() const { return mStaging; }
    const std::filesystem::path& destination() const { return mDestination; }

    // Moves every staged file into the destination at the same relative path (creating
    // sub-folders, replacing files of the same name), removes the files of ownedNames (paths
    // relative to the destination) that were not staged, then removes the staging folder.
    // Returns the relative paths committed, sorted. Throws std::runtime_error naming the file
    // when a rename fails.
    std::vector<std::filesystem::path> commit(const std::vector<std::string>& ownedNames = {});

private:
    std::filesystem::path mDestination;
    std::filesystem::path mStaging;
    std::vector<std::filesystem::path> mCreated; // folders made by the constructor, outermost last
    bool mCommitted = false;
};

} // namespace experiments
