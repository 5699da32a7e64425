// libFuzzer target: the image inputs of `testbed diff` (experiments::diffImageFiles): the input is
// read as an EXR (OpenImageIO picks the reader by content, so other formats are reached too) and
// compared with itself and with a fixed valid image. Errors are std::runtime_error with the
// file's name; nothing else may leave.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "FuzzInput.h"
#include "experiments/DiffCommand.h"
#include "experiments/ImageOutput.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::filesystem::path reference = [] {
        const std::filesystem::path path = fuzz::inputFolder() / "reference.exr";
        std::vector<float> plane(4 * 4, 0.5f);
        experiments::writeMultiLayerExr(
            path, 4, 4, {{"R", plane.data()}, {"G", plane.data()}, {"B", plane.data()}}, {});
        return path;
    }();
    const std::filesystem::path path = fuzz::writeInput(data, size, "input.exr");
    try {
        (void)experiments::diffImageFiles(path, path);
        (void)experiments::diffImageFiles(path, reference);
    } catch (const std::runtime_error&) {
    }
    return 0;
}
