// Atomic file output through a temporary sibling and rename(2); see AtomicFile.h for the naming
// scheme and what is (and is not) guaranteed. C stdio is used for the byte writes because it
// reports the system error (errno) that our messages must name; iostreams do not.
#include "experiments/output/AtomicFile.h"

#include <atomic>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>

#include <signal.h>
#include <unistd.h>

namespace experiments {

namespace fs = std::filesystem;

namespace {

std::string systemMessage(int errorNumber) {
    return std::error_code(errorNumber, std::generic_category()).message();
}

// 8 hex digits of the FNV-1a hash of this machine's host name (see AtomicFile.h).
const std::string& hostTag() {
    static const std::string tag = [] {
        char name[256] = {};
        if (::gethostname(name, sizeof name - 1) != 0)
            name[0] = '\0';
        uint32_t hash = 2166136261u;
        for (const char* c = name; *c; ++c)
            hash = (hash ^ uint8_t(*c)) * 16777619u;
        char text[9];
        std::snprintf(text, sizeof text, "%08x", hash);
        return std::string(text);
    }();
    return tag;
}

// A hidden name beside path that no other writer uses: the pid separates processes, the counter
// separates threads and successive calls within one process, the host tag separates machines.
fs::path temporarySibling(const fs::path& path) {
    static std::atomic<uint64_t> counter{0};
    std::string name = "." + path.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter.fetch_add(1)) + "-" + hostTag() +
                       path.extension().string();
    return path.parent_path() / name;
}

// The writer's pid if name is a temporary of this scheme made on this host, else 0.
pid_t temporaryOwner(const std::string& name) {
    const size_t marker = name.rfind(".tmp-");
    if (name.empty() || name[0] != '.' || marker == std::string::npos || marker == 0)
        return 0;
    const char* p = name.data() + marker + 5;
    const char* end = name.data() + name.size();
    uint64_t pid = 0, counter = 0;
    auto number = [&](uint64_t& into) {
        const auto [stop, error] = std::from_chars(p, end, into);
        const bool ok = error == std::errc() && stop != p && stop < end && *stop == '-';
        p = stop + 1;
        return ok;
    };
    if (!number(pid) || !number(counter) || end - p < 8 || std::string(p, 8) != hostTag())
        return 0;
    p += 8;
    if (p != end && *p != '.') // only an extension may follow
        return 0;
    return pid > 0 && pid <= uint64_t(std::numeric_limits<pid_t>::max()) ? pid_t(pid) : 0;
}

bool processExists(pid_t pid) {
    // EPERM: it exists but belongs to another user.
    return ::kill(pid, 0) == 0 || errno != ESRCH;
}

// removeStaleTemporaries once per folder and process: the first write into a folder pays for one
// directory listing, later writes nothing.
void cleanFolderOnce(const fs::path& dir) {
    static std::mutex mutex;
    static std::set<std::string> cleaned;
    std::error_code ec;
    const std::string key = fs::absolute(dir.empty() ? fs::path(".") : dir, ec).string();
    {
        std::lock_guard lock(mutex);
        if (!cleaned.insert(key).second)
            return;
    }
    removeStaleTemporaries(dir);
}

void removeQuietly(const fs::path& path) {
    std::error_code ignored; // best effort: the error being reported matters more
    fs::remove(path, ignored);
}

} // namespace

size_t removeStaleTemporaries(const fs::path& dir) {
    size_t removed = 0;
    std::error_code ec;
    fs::directory_iterator entries(dir.empty() ? fs::path(".") : dir,
                                   fs::directory_options::skip_permission_denied, ec);
    if (ec)
        return 0;
    const pid_t self = ::getpid();
    for (const fs::directory_entry& entry : entries) {
        const pid_t owner = temporaryOwner(entry.path().filename().string());
        if (owner == 0 || owner == self || processExists(owner))
            continue;
        if (entry.is_regular_file(ec) && fs::remove(entry.path(), ec))
            ++removed;
        // A staging folder (StagedFolder.h) of a process killed before its commit.
        else if (!entry.is_symlink(ec) && entry.is_directory(ec) &&
                 fs::remove_all(entry.path(), ec) > 0)
            ++removed;
    }
    return removed;
}

fs::path temporaryPathFor(const fs::path& finalPath) {
    return temporarySibling(finalPath);
}

void writeFileAtomically(const fs::path& finalPath,
                         const std::function<void(const fs::path& tempPath)>& writer) {
    if (!finalPath.has_filename())
        throw std::runtime_error("cannot write " + finalPath.string() + ": it has no file name");
    cleanFolderOnce(finalPath.parent_path());
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
    cleanFolderOnce(folder);

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
