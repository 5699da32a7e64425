// FuzzInput: the loaders take paths, so each fuzz input is written to a file first, in a folder
// of this process under /dev/shm (memory; /tmp when it is missing), under the name the reader
// dispatches on. Files a glTF input names by relative URI resolve in that folder, where nothing
// else lives. Not thread-safe: libFuzzer runs one input at a time per process.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace fuzz {

inline std::filesystem::path inputFolder() {
    static const std::filesystem::path folder = [] {
        const std::filesystem::path base =
            std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
        const std::filesystem::path dir = base / ("testbed-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(dir);
        return dir;
    }();
    return folder;
}

inline std::filesystem::path writeInput(const uint8_t* data, size_t size, const std::string& name) {
    const std::filesystem::path path = inputFolder() / name;
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return path;
}

} // namespace fuzz
