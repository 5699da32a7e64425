// libFuzzer target: the image inputs of `testbed diff` (experiments::diffImageFiles): the input is
// read as an EXR (OpenImageIO picks the reader by content, so other formats are reached too) and
// compared with itself and with a fixed valid image. Errors are std::runtime_error with the
// file's name; nothing else may leave.
//
// Work per input is bounded: an input whose header declares more than kMaxFuzzPixels pixels (or a
// depth) is read up to its header only. diff's own limit (scenes/input/Limits.h, 2^26 pixels) is
// tested by tests/experiments/compare/diff_test.cpp; here a few bytes declaring an 8192 x 8192
// image made one input take 37 s under AddressSanitizer (54 executions in 600 s), and the decoding
// and diff code are reached as well by small images.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "FuzzInput.h"
#include "experiments/compare/DiffCommand.h"
#include "experiments/output/ImageOutput.h"

namespace {

constexpr int64_t kMaxFuzzPixels = 256 * 256;

// The header's pixel count within the fuzz bound (and a readable header at all: else diff's own
// error path runs, which is cheap). The attribute sizes are checked first, as diffImageFiles
// does: opening the header here before that check let OpenEXR allocate a 1.7 GB attribute that
// a 4 KB input declared (75-105 s per input under ASan, reported as timeouts), in this harness
// only, since diff itself refused the input in milliseconds.
bool smallEnough(const std::filesystem::path& path) {
    try {
        experiments::checkExrAttributeSizes(path);
    } catch (const std::runtime_error&) {
        return true; // diffImageFiles refuses it the same way, at once
    }
    auto input = OIIO::ImageInput::open(path.string());
    if (!input)
        return true;
    const OIIO::ImageSpec& spec = input->spec();
    return spec.depth <= 1 && spec.width >= 0 && spec.height >= 0 &&
           int64_t(spec.width) * int64_t(spec.height) <= kMaxFuzzPixels &&
           int64_t(spec.full_width) * int64_t(spec.full_height) <= kMaxFuzzPixels;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::filesystem::path reference = [] {
        const std::filesystem::path path = fuzz::inputFolder() / "reference.exr";
        std::vector<float> plane(4 * 4, 0.5f);
        experiments::writeMultiLayerExr(
            path, 4, 4, {{"R", plane.data()}, {"G", plane.data()}, {"B", plane.data()}}, {});
        return path;
    }();
    const std::filesystem::path path = fuzz::writeInput(data, size, "input.exr");
    if (!smallEnough(path))
        return 0;
    try {
        (void)experiments::diffImageFiles(path, path);
        (void)experiments::diffImageFiles(path, reference);
    } catch (const std::runtime_error&) {
    }
    return 0;
}
