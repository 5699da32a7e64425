#include "experiments/sweep/SweepLock.h"

#include <cerrno>
#include <cstring>
#include <ostream>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "experiments/CommandErrors.h"

namespace experiments {

namespace fs = std::filesystem;

namespace {

struct flock rangeOf(short type, size_t first, size_t last) {
    struct flock range {};
    range.l_type = type;
    range.l_whence = SEEK_SET;
    range.l_start = off_t(first);
    range.l_len = off_t(last - first); // > 0: a length of 0 would mean "to the end of the file"
    return range;
}

} // namespace

fs::path SweepLock::lockPath(const fs::path& dir) {
    return dir / "sweep.lock";
}

SweepLock::SweepLock(const fs::path& dir, size_t first, size_t last, bool wait, std::ostream& log) {
    if (last <= first)
        return;
    const fs::path path = lockPath(dir);
    mFd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (mFd < 0)
        throw std::runtime_error("cannot create the sweep lock " + path.string() + ": " +
                                 std::strerror(errno));
    struct flock range = rangeOf(F_WRLCK, first, last);
    if (fcntl(mFd, F_SETLK, &range) == 0)
        return;
    const int error = errno;
    if (error != EACCES && error != EAGAIN) {
        // ENOLCK and the like: a file system without record locks.
        reportWarning("cannot lock " + path.string() + " (" + std::strerror(error) +
                          "): nothing keeps a second sweep from running the same jobs into this "
                          "folder",
                      log);
        close(mFd);
        mFd = -1;
        return;
    }
    struct flock holder = rangeOf(F_WRLCK, first, last);
    std::string who = "another process";
    if (fcntl(mFd, F_GETLK, &holder) == 0 && holder.l_type != F_UNLCK && holder.l_pid > 0)
        who = "process " + std::to_string(holder.l_pid);
    if (!wait) {
        close(mFd);
        mFd = -1;
        throw SweepBusyError(dir.string() + " is in use: " + who +
                             " is running jobs of this sweep into it (lock " + path.string() +
                             "); wait for it to end, or give --wait to start when it has");
    }
    log << "testbed: " << who << " is running jobs of this sweep into " << dir.string()
        << "; waiting until it ends (--wait)\n";
    log.flush();
    range = rangeOf(F_WRLCK, first, last);
    while (fcntl(mFd, F_SETLKW, &range) != 0) {
        if (errno == EINTR)
            continue;
        const int waitError = errno;
        close(mFd);
        mFd = -1;
        throw std::runtime_error("cannot lock " + path.string() + ": " + std::strerror(waitError));
    }
}

SweepLock::~SweepLock() {
    if (mFd >= 0)
        close(mFd); // releases the range
}

} // namespace experiments
