// Atomic file output: "nothing is left half-written". Every result file (EXR, PNG, JSON, CSV) is
// written under a hidden temporary name in the destination folder and renamed over the final name
// only after the writer has finished without error. rename(2) within one file system is atomic,
// so a reader sees either the previous file or the complete new one, never a prefix; on an
// exception the temporary file is removed and the final name is left untouched.
//
// Temporary names are ".<stem>.tmp-<pid>-<counter>-<host><extension>" beside the final file, e.g.
// ".render.tmp-4242-7-1a2b3c4d.exr" for "render.exr", where <host> is 8 hex digits of the FNV-1a
// hash of the host name. The extension is kept last so that writers which pick the format from
// the file name (OpenImageIO's ImageBuf::write, oiiotool, matplotlib) still work; the leading dot
// hides the file from shell globs; pid and counter keep concurrent writers (threads or processes)
// from colliding, and the host tells whose pid it is on a folder shared between machines. The
// plot scripts (experiments/plots/plotfiles.py) name their temporaries the same way. The
// temporary file lives in the same folder because a rename across file systems is not atomic
// (and fails with EXDEV).
//
// Stale temporaries: a process killed mid-write (kill -9, power loss) leaves its temporary file.
// The first time a process writes into a folder (writeFileAtomically, ensureWritableDirectory),
// it removes the temporaries of this naming scheme there whose writer is gone: same host, and no
// process with that pid exists (kill(pid, 0) fails with ESRCH). A temporary of a live process, of
// another host, or of a recycled pid (another process now has it) is left alone, so a concurrent
// writer never loses its file; a leftover of a recycled pid is removed by a later run.
// Staging folders of the same naming scheme (StagedFolder.h: a run's outputs before its commit)
// are removed the same way, with their contents.
//
// Scope: this protects against the process failing mid-write (exception, crash, Ctrl-C). It does
// not fsync, so after a power loss the file system decides; results are reproducible, so a rerun
// is the remedy there and the per-file fsync cost is not paid in sweeps.
//
// Writers must report every failed byte write by throwing: a library that ignores a short write
// (a full disk) would otherwise leave a truncated file under the final name. OpenImageIO output
// goes through writeImageAtomically (ImageOutput.h), which checks them.
//
// Thread safety: all functions may be called concurrently for different final paths.
#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

namespace experiments {

// Calls writer(tempPath), then renames tempPath to finalPath (replacing an existing file). The
// writer creates tempPath with any library and reports failure by throwing. If the writer throws,
// its exception propagates unchanged after the temporary file is removed. Throws
// std::runtime_error naming finalPath when the writer returned without creating tempPath or when
// the rename fails (with the system error). The folder of finalPath must exist.
void writeFileAtomically(const std::filesystem::path& finalPath,
                         const std::function<void(const std::filesystem::path& tempPath)>& writer);

// Writes text byte for byte (no newline translation) through writeFileAtomically. Throws
// std::runtime_error naming finalPath and the system error on failure.
void writeTextAtomically(const std::filesystem::path& finalPath, std::string_view text);

// Creates dir with its parents if missing, then proves that files can be created in it by
// creating and removing a probe file. Called before any rendering so that an unusable output
// folder fails in milliseconds, not after the render. An empty path means the current folder.
// Throws std::runtime_error("cannot write to output folder <dir>: <reason>") otherwise.
void ensureWritableDirectory(const std::filesystem::path& dir);

// Removes the stale temporaries (see above) in dir now, whether or not this process already did;
// returns how many it removed. Errors (an unreadable folder, a file that vanished) are ignored:
// cleaning is best effort and must never fail a command.
size_t removeStaleTemporaries(const std::filesystem::path& dir);

// The temporary name writeFileAtomically would use next for finalPath (for writers, such as the
// plot scripts, that create files the C++ side renames, and for tests).
std::filesystem::path temporaryPathFor(const std::filesystem::path& finalPath);

} // namespace experiments
