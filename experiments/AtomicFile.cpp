// Atomic file output through a temporary sibling and rename(2); see AtomicFile.h for the naming
// scheme and what is (and is not) guaranteed. C stdio is used for the byte writes because it
// reports the system error (errno) that our messages must name; iostreams do not.
#include "experiments/AtomicFile.h"

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <system_error>

#include <unistd.h>

namespace experiments {

namespace fs = std::filesystem;

namespace {

std::string systemMessage(int errorNumber) {
    return std::error_code(errorNumber, std::generic_category()).message();
}

// A hidden name beside path that no other writer uses: the pid separates processes, the counter
// separates threads and successive calls within one process.
fs::path temporarySibling(const fs::path& path) {
    static std::atomic<uint64_t> counter{0};
    std::string name = "." + path.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter.fetch_add(1)) + path.extension().string();
    return path.parent_path() / name;
}

void removeQuietly(const fs::path& path) {
    std::error_code ignored; // best effort: the error being reported matters more
    fs::remove(path, ignored);
}

} // namespace

void writeFileAtomically(const fs::path& finalPath,
                         const std::function<void(const fs::path& tempPath)>& writer) {
    if (!finalPath.has_filename())
        throw std::runtime_error("cannot write " + finalPath.string() + ": it has no file name");
    const fs::path tempPath = temporarySibling(finalPath);
    try {
        writer(tempPath);
    } catch (...) {
        removeQuietly(tempPath);
        throw;
    }
    std::error_code ec;
    if (!fs::exists(tempPath, ec)) {
        // A writer that "succeeds" without producing a file is a bug in the writer; renaming
        // nothing would silently keep a stale result under the final name.
        throw std::runtime_error("cannot write " + finalPath.string() +
                                 ": the writer reported success but created no file");
    }
    fs::rename(tempPath, finalPath, ec);
    if (ec) {
        removeQuietly(tempPath);
        throw std::runtime_error("cannot write " + finalPath.string() + ": rename from " +
                                 tempPath.string() + " failed: " + ec.message());
    }
}

void writeTextAtomically(const fs::path& finalPath, std::string_view text) {
    writeFileAtomically(finalPath, [&](const fs::path& tempPath) {
        std::FILE* file = std::fopen(tempPath.c_str(), "wb");
        if (!file)
            throw std::runtime_error("cannot write " + finalPath.string() + ": " +
                                     systemMessage(errno));
        const size_t written = std::fwrite(text.data(), 1, text.size(), file);
        int errorNumber = written == text.size() ? 0 : errno;
        // fclose flushes the stdio buffer, so a full disk may only show up here.
        if (std::fclose(file) != 0 && errorNumber == 0)
            errorNumber = errno;
        if (errorNumber != 0)
            throw std::runtime_error("cannot write " + finalPath.string() + ": " +
                                     systemMessage(errorNumber));
    });
}

void ensureWritableDirectory(const fs::path& dir) {
    const fs::path folder = dir.empty() ? fs::path(".") : dir;
    auto failure = [&](const std::string& reason) {
        return std::runtime_error("cannot write to output folder " + folder.string() + ": " +
                                  reason);
    };
    std::error_code ec;
    if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
        throw failure("it exists and is not a folder");
    fs::create_directories(folder, ec);
    if (ec)
        throw failure("cannot create it: " + ec.message());
    if (!fs::is_directory(folder, ec))
        throw failure("it is not a folder");

    // Permission bits, ACLs, read-only mounts and quotas all decide writability; creating a real
    // file is the only check that asks all of them at once.
    const fs::path probePath = temporarySibling(folder / "write-probe");
    std::FILE* probe = std::fopen(probePath.c_str(), "wbx");
    if (!probe)
        throw failure("cannot create a file in it: " + systemMessage(errno));
    std::fclose(probe);
    fs::remove(probePath, ec);
    if (ec)
        throw failure("cannot remove probe file " + probePath.string() + ": " + ec.message());
}

} // namespace experiments
