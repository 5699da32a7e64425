// WholeFile: the one way the testbed reads an input file whole into memory (JSON scenes, sweep
// files, glTF/GLB and their external buffers, results.json and job markers). Before anything is
// opened or allocated it checks that the path is a regular file (a FIFO would block open() and a
// read from /dev/zero never ends; a folder has no bytes) and that its size is within a cap
// (limits::kMaxFileBytes by default), so a hostile path fails at once with one reason instead of
// hanging or reading until std::bad_alloc (issue 32, class 6).
//
// The checks are made on the path (stat) and again on the opened descriptor (fstat), so a path
// swapped for a FIFO in between is still refused; the file is opened non-blocking for that
// reason. A file that grows while it is read is read up to the size checked, never past it.
// Problems are returned as text without the path ("is a FIFO (named pipe), not a regular
// file"): each reader puts them into its own error with the file's name. Thread-safe.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scenes/input/Limits.h"

namespace scenes {

// "" when path is a regular file of at most maxBytes bytes; else why it is not. Opens nothing:
// callers that hand the path to a library which reads it itself (OpenImageIO) check it first.
std::string regularFileProblem(const std::filesystem::path& path,
                               uint64_t maxBytes = limits::kMaxFileBytes);

// Reads the whole file into *bytes. Returns "" on success, else the problem ("file not found",
// "is a directory, not a regular file", "has 5000000000 bytes, more than the limit of ...",
// "cannot be read: <reason>"); *bytes is then empty.
std::string readWholeFile(const std::filesystem::path& path, std::string* bytes,
                          uint64_t maxBytes = limits::kMaxFileBytes);
std::string readWholeFile(const std::filesystem::path& path, std::vector<unsigned char>* bytes,
                          uint64_t maxBytes = limits::kMaxFileBytes);

} // namespace scenes
