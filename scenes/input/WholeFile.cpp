// WholeFile.h's checked whole-file read, on POSIX calls: std::ifstream cannot open without
// blocking on a FIFO, and cannot tell what kind of file it opened.
#include "scenes/input/WholeFile.h"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace scenes {

namespace {

std::string typeProblem(mode_t mode) {
    if (S_ISREG(mode))
        return "";
    if (S_ISDIR(mode))
        return "is a directory, not a regular file";
    if (S_ISFIFO(mode))
        return "is a FIFO (named pipe), not a regular file";
    if (S_ISCHR(mode))
        return "is a character device, not a regular file";
    if (S_ISBLK(mode))
        return "is a block device, not a regular file";
    if (S_ISSOCK(mode))
        return "is a socket, not a regular file";
    return "is not a regular file";
}

std::string statProblem(const struct stat& info, uint64_t maxBytes) {
    std::string problem = typeProblem(info.st_mode);
    if (problem.empty() && uint64_t(info.st_size) > maxBytes)
        problem = "has " + std::to_string(uint64_t(info.st_size)) +
                  " bytes, more than the limit of " + std::to_string(maxBytes);
    return problem;
}

// Closes the descriptor on every return path.
struct Descriptor {
    int fd;
    ~Descriptor() {
        if (fd >= 0)
            ::close(fd);
    }
};

template <typename Buffer>
std::string readInto(const std::filesystem::path& path, Buffer* bytes, uint64_t maxBytes) {
    bytes->clear();
    if (std::string problem = regularFileProblem(path, maxBytes); !problem.empty())
        return problem;
    // O_NONBLOCK: if the path became a FIFO since the check, open() must not wait for a writer.
    const Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
    if (file.fd < 0)
        return std::string("cannot be opened: ") + std::strerror(errno);
    struct stat info;
    if (::fstat(file.fd, &info) != 0)
        return std::string("cannot be read: ") + std::strerror(errno);
    if (std::string problem = statProblem(info, maxBytes); !problem.empty())
        return problem;
    bytes->resize(size_t(info.st_size));
    size_t done = 0;
    while (done < bytes->size()) {
        const ssize_t got =
            ::read(file.fd, reinterpret_cast<char*>(bytes->data()) + done, bytes->size() - done);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            const int error = errno;
            bytes->clear();
            return std::string("cannot be read: ") + std::strerror(error);
        }
        if (got == 0)
            break; // the file shrank since fstat: keep what it has
        done += size_t(got);
    }
    bytes->resize(done);
    return "";
}

} // namespace

std::string regularFileProblem(const std::filesystem::path& path, uint64_t maxBytes) {
    struct stat info;
    if (::stat(path.c_str(), &info) != 0) {
        if (errno == ENOENT)
            return "file not found";
        return std::string("cannot be read: ") + std::strerror(errno);
    }
    return statProblem(info, maxBytes);
}

std::string readWholeFile(const std::filesystem::path& path, std::string* bytes,
                          uint64_t maxBytes) {
    return readInto(path, bytes, maxBytes);
}

std::string readWholeFile(const std::filesystem::path& path, std::vector<unsigned char>* bytes,
                          uint64_t maxBytes) {
    return readInto(path, bytes, maxBytes);
}

} // namespace scenes
