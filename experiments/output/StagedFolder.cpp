// A result folder written all or nothing; see StagedFolder.h.
#include "experiments/output/StagedFolder.h"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <system_error>

#include "experiments/output/AtomicFile.h"

namespace experiments {

namespace fs = std::filesystem;

namespace {

// "out/" and "out" name the same folder; an empty path is the current folder.
fs::path folderPath(const fs::path& path) {
    if (path.empty())
        return ".";
    fs::path normal = path.lexically_normal();
    if (!normal.has_filename() && normal.has_parent_path() && normal != normal.root_path())
        normal = normal.parent_path();
    return normal.empty() ? fs::path(".") : normal;
}

} // namespace

StagedFolder::StagedFolder(const fs::path& destination) : mDestination(folderPath(destination)) {
    // The folders that do not exist yet, innermost first: a failed run removes them again.
    std::error_code ec;
    for (fs::path folder = mDestination; !folder.empty() && !fs::exists(folder, ec);
         folder = folder.parent_path()) {
        mCreated.push_back(folder);
        if (folder == folder.parent_path())
            break;
    }
    try {
        ensureWritableDirectory(mDestination);
        mStaging = temporaryPathFor(mDestination / "staged");
        if (!fs::create_directory(mStaging, ec) || ec)
            throw std::runtime_error("cannot write to output folder " + mDestination.string() +
                                     ": cannot create the staging folder " + mStaging.string() +
                                     ": " + (ec ? ec.message() : "it exists"));
    } catch (...) {
        for (const fs::path& folder : mCreated)
            fs::remove(folder, ec); // only if empty
        throw;
    }
}

StagedFolder::~StagedFolder() {
    if (mCommitted)
        return;
    std::error_code ec;
    fs::remove_all(mStaging, ec);
    for (const fs::path& folder : mCreated)
        fs::remove(folder, ec); // fails, as wanted, when something else was put there meanwhile
}

std::vector<fs::path> StagedFolder::commit(const std::vector<std::string>& ownedNames) {
    std::vector<fs::path> staged;
    for (auto it = fs::recursive_directory_iterator(mStaging);
         it != fs::recursive_directory_iterator(); ++it)
        if (it->is_regular_file() && !it->is_symlink())
            staged.push_back(it->path().lexically_relative(mStaging));
    std::sort(staged.begin(), staged.end());
    // What would stop a rename (a folder where a file goes, a file where a folder goes) is found
    // before the first rename, so a refused commit too leaves the destination as it was.
    for (const fs::path& relative : staged) {
        std::error_code ec;
        const fs::path target = mDestination / relative;
        if (fs::is_directory(target, ec))
            throw std::runtime_error("cannot write " + target.string() +
                                     ": a folder of that name is in the way");
        for (fs::path folder = relative.parent_path(); !folder.empty();
             folder = folder.parent_path())
            if (fs::exists(mDestination / folder, ec) &&
                !fs::is_directory(mDestination / folder, ec))
                throw std::runtime_error("cannot write " + target.string() + ": " +
                                         (mDestination / folder).string() + " is not a folder");
    }
    for (const fs::path& relative : staged) {
        const fs::path target = mDestination / relative;
        std::error_code ec;
        fs::create_directories(target.parent_path(), ec);
        if (!ec)
            fs::rename(mStaging / relative, target, ec);
        if (ec)
            throw std::runtime_error("cannot write " + target.string() + ": moving it from " +
                                     (mStaging / relative).string() + " failed: " + ec.message());
    }
    const std::set<fs::path> written(staged.begin(), staged.end());
    for (const std::string& name : ownedNames) {
        std::error_code ec;
        const fs::path old = mDestination / name;
        if (!written.count(fs::path(name)) && fs::is_regular_file(old, ec))
            fs::remove(old, ec);
    }
    std::error_code ec;
    fs::remove_all(mStaging, ec);
    mCommitted = true;
    return staged;
}

} // namespace experiments
