// SweepLock: keeps two `testbed sweep` processes from running the same jobs into one output
// folder at once (they would redo each other's jobs and overwrite each other's results, and the
// timings of both would suffer).
//
// The lock is a POSIX record lock (fcntl F_SETLK) on DIR/sweep.lock over the byte range
// [first, last) of the sweep's run positions that this process runs: its shard. So a second
// sweep over the same jobs (the same command twice, or overlapping shards) is refused, naming the
// process that holds them, while shards with disjoint jobs (1/4 and 2/4) still share one folder,
// as experiments/README.md allows. The kernel releases the lock when the holder exits, however
// it exits (kill -9 included), so a stale lock cannot exist. Record locks work across NFS (lockd
// / NFSv4) too; on a file system without locking the sweep warns and runs unprotected.
// With wait = true the second process waits until the range is free, then runs (and skips the
// jobs the first one finished).
//
// The lock file holds no data; it is created once and left in place. Record locks belong to the
// process: the sweep's child processes (JobProcess.h) neither hold nor release it, and the
// process must not open and close DIR/sweep.lock elsewhere (closing any descriptor of the file
// would release the lock).
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <stdexcept>

namespace experiments {

// The folder's jobs are held by another process (and wait was false).
struct SweepBusyError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

class SweepLock {
public:
    // Locks run positions [first, last) of the sweep in dir (which must exist). An empty range
    // locks nothing. Throws SweepBusyError naming the holder's process id when another process
    // holds any of them and wait is false; with wait, prints one line to log and blocks until
    // they are free. Throws std::runtime_error when the lock file cannot be created.
    SweepLock(const std::filesystem::path& dir, size_t first, size_t last, bool wait,
              std::ostream& log);
    ~SweepLock();
    SweepLock(const SweepLock&) = delete;
    SweepLock& operator=(const SweepLock&) = delete;

    static std::filesystem::path lockPath(const std::filesystem::path& dir);

private:
    int mFd = -1;
};

} // namespace experiments
