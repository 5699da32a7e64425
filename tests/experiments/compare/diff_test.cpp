// Tests for experiments/DiffCommand: metrics of known differences (identical images, a constant
// offset, an offset on part of the image), per-channel statistics of the layers both files
// share, the written report, and refusal of mismatched sizes. Images are written with
// writeMultiLayerExr into <build>/test-output/experiments/<test>/ and left there.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "experiments/compare/DiffCommand.h"
#include "experiments/output/ImageOutput.h"
#include "tests/experiments/TestFolders.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kWidth = 40, kHeight = 20;

using experiments::test_files::freshTestFolder;
using experiments::test_files::readText;

// R, G, B = 0.5 (+ offset on the pixels where offsetWhere(x) holds), Z = depth, N.X = 0.25, and
// an extra channel only this file has when extraName is set. Values are exact in binary.
fs::path writeImage(const fs::path& path, float offset, bool (*offsetWhere)(int x), float depth,
                    const std::string& extraName = "", int width = kWidth, int height = kHeight) {
    const size_t n = size_t(width) * height;
    std::vector<float> rgb(n), z(n, depth), normal(n, 0.25f), extra(n, 1.0f);
    for (size_t i = 0; i < n; ++i)
        rgb[i] = 0.5f + (offsetWhere(int(i % width)) ? offset : 0.0f);
    std::vector<ImagePlane> planes = {{"R", rgb.data()},
                                      {"G", rgb.data()},
                                      {"B", rgb.data()},
                                      {"Z", z.data()},
                                      {"N.X", normal.data()}};
    if (!extraName.empty())
        planes.push_back({extraName, extra.data()});
    writeMultiLayerExr(path, width, height, planes, {});
    return path;
}

bool everywhere(int) {
    return true;
}
bool leftHalf(int x) {
    return x < kWidth / 2;
}
bool nowhere(int) {
    return false;
}

const ChannelStatistics* channel(const ImageDiff& diff, const std::string& name) {
    for (const ChannelStatistics& c : diff.channels)
        if (c.name == name)
            return &c;
    return nullptr;
}

TEST(ImageDiff, IdenticalImagesHaveZeroError) {
    const fs::path dir = freshTestFolder();
    const fs::path a = writeImage(dir / "a.exr", 0.0f, nowhere, 3.0f);
    const ImageDiff diff = diffImageFiles(a, a);
    EXPECT_EQ(diff.metrics.rmse, 0.0);
    EXPECT_EQ(diff.metrics.maxAbs, 0.0);
    EXPECT_EQ(diff.metrics.meanAbs, 0.0);
    EXPECT_EQ(diff.metrics.relativeMean, 0.0);
    EXPECT_EQ(diff.metrics.p99Abs, 0.0);
    EXPECT_TRUE(std::isinf(diff.metrics.psnr));
    ASSERT_EQ(diff.channels.size(), 5u);
    for (const ChannelStatistics& c : diff.channels) {
        EXPECT_EQ(c.maxAbsDifference, 0.0) << c.name;
        EXPECT_EQ(c.meanA, c.meanB) << c.name;
    }
}

TEST(ImageDiff, ConstantOffsetGivesThatOffsetAsEveryError) {
    const fs::path dir = freshTestFolder();
    const fs::path a = writeImage(dir / "a.exr", 0.125f, everywhere, 3.0f);
    const fs::path b = writeImage(dir / "b.exr", 0.0f, nowhere, 2.0f);
    const ImageDiff diff = diffImageFiles(a, b);
    EXPECT_EQ(diff.width, kWidth);
    EXPECT_EQ(diff.height, kHeight);
    EXPECT_NEAR(diff.metrics.rmse, 0.125, 1e-12);
    EXPECT_NEAR(diff.metrics.maxAbs, 0.125, 1e-12);
    EXPECT_NEAR(diff.metrics.meanAbs, 0.125, 1e-12);
    EXPECT_NEAR(diff.metrics.p99Abs, 0.125, 1e-12);
    EXPECT_NEAR(diff.metrics.relativeMean, 0.125 / 0.5, 1e-12);
    EXPECT_NEAR(diff.metrics.relativeRmse, 0.125 / 0.5, 1e-12);
    EXPECT_NEAR(diff.metrics.psnr, 20.0 * std::log10(0.5 / 0.125), 1e-9);
    const ChannelStatistics* z = channel(diff, "Z");
    ASSERT_NE(z, nullptr);
    EXPECT_EQ(z->meanA, 3.0);
    EXPECT_EQ(z->meanB, 2.0);
    EXPECT_EQ(z->minDifference, 1.0);
    EXPECT_EQ(z->maxDifference, 1.0);
    EXPECT_EQ(z->meanAbsDifference, 1.0);
    const ChannelStatistics* normal = channel(diff, "N.X");
    ASSERT_NE(normal, nullptr);
    EXPECT_EQ(normal->maxAbsDifference, 0.0);
}

TEST(ImageDiff, OffsetOnHalfTheImage) {
    const fs::path dir = freshTestFolder();
    const fs::path a = writeImage(dir / "a.exr", -0.25f, leftHalf, 1.0f, "lights.evaluated");
    const fs::path b = writeImage(dir / "b.exr", 0.0f, nowhere, 1.0f, "albedo.R");
    const ImageDiff diff = diffImageFiles(a, b);
    EXPECT_NEAR(diff.metrics.rmse, std::sqrt(0.5 * 0.25 * 0.25), 1e-12);
    EXPECT_NEAR(diff.metrics.maxAbs, 0.25, 1e-12);
    EXPECT_NEAR(diff.metrics.meanAbs, 0.125, 1e-12);
    EXPECT_NEAR(diff.metrics.p99Abs, 0.25, 1e-12);
    const ChannelStatistics* red = channel(diff, "R");
    ASSERT_NE(red, nullptr);
    EXPECT_EQ(red->minDifference, -0.25);
    EXPECT_EQ(red->maxDifference, 0.0);
    EXPECT_EQ(red->meanDifference, -0.125);
    EXPECT_EQ(red->minA, 0.25);
    EXPECT_EQ(diff.onlyInA, std::vector<std::string>{"lights.evaluated"});
    EXPECT_EQ(diff.onlyInB, std::vector<std::string>{"albedo.R"});
    EXPECT_EQ(channel(diff, "albedo.R"), nullptr);
}

TEST(DiffCommand, WritesPageJsonAndImages) {
    const fs::path dir = freshTestFolder();
    DiffCommandOptions options;
    options.a = writeImage(dir / "a.exr", 0.125f, leftHalf, 3.0f);
    options.b = writeImage(dir / "b.exr", 0.0f, nowhere, 3.0f);
    options.out = dir / "diff";
    ASSERT_EQ(runDiffCommand(options), 0);
    for (const char* file :
         {"index.html", "diff.json", "a.png", "b.png", "absdiff.png", "absdiff.exr"})
        EXPECT_TRUE(fs::is_regular_file(options.out / file)) << file;
    const json result = json::parse(readText(options.out / "diff.json"));
    EXPECT_NEAR(result["metrics"]["rmse"].get<double>(), std::sqrt(0.5) * 0.125, 1e-12);
    EXPECT_NEAR(result["metrics"]["p99_abs"].get<double>(), 0.125, 1e-12);
    EXPECT_EQ(result["channels"].size(), 5u);
    const std::string html = readText(options.out / "index.html");
    // ꟻLIP beside the other metrics: its value and map, or a visible note saying why not.
    ASSERT_TRUE(result["metrics"].contains("flip"));
    ASSERT_TRUE(result["metrics"]["flip"].is_number()) << result["metrics"].dump();
    for (const char* key : {"flip_weighted_median", "flip_p95", "flip_p99"})
        EXPECT_TRUE(result["metrics"][key].is_number()) << key;
    // The raw map is the layer "flip" of absdiff.exr, and its mean is the reported mean.
    {
        OIIO::ImageBuf exr((options.out / "absdiff.exr").string());
        ASSERT_TRUE(exr.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << exr.geterror();
        const int channel = exr.spec().channelindex("flip");
        ASSERT_GE(channel, 0);
        double sum = 0.0;
        std::vector<float> pixel(exr.nchannels());
        for (int y = 0; y < exr.spec().height; ++y)
            for (int x = 0; x < exr.spec().width; ++x) {
                exr.getpixel(x, y, pixel.data());
                sum += pixel[channel];
            }
        EXPECT_NEAR(sum / (double(exr.spec().width) * exr.spec().height),
                    result["metrics"]["flip"].get<double>(), 1e-6);
    }
    EXPECT_TRUE(fs::is_regular_file(options.out / "flip.png"));
    EXPECT_NE(html.find("src=\"flip.png\""), std::string::npos);
    EXPECT_NE(html.find("src=\"absdiff.png\""), std::string::npos);
    EXPECT_NE(html.find("<td class=\"text\">Z</td>"), std::string::npos);
    EXPECT_EQ(html.find("http"), std::string::npos);
    for (const fs::directory_entry& entry : fs::directory_iterator(options.out))
        EXPECT_NE(entry.path().filename().string()[0], '.')
            << "temporary file left: " << entry.path();

    options.out = dir / "identical";
    options.a = options.b;
    ASSERT_EQ(runDiffCommand(options), 0);
    EXPECT_EQ(json::parse(readText(options.out / "diff.json"))["metrics"]["psnr"], "inf");
}

TEST(DiffCommand, RefusesImagesOfDifferentSizes) {
    const fs::path dir = freshTestFolder();
    DiffCommandOptions options;
    options.a = writeImage(dir / "a.exr", 0.0f, nowhere, 1.0f);
    options.b = writeImage(dir / "b.exr", 0.0f, nowhere, 1.0f, "", kWidth / 2, kHeight);
    options.out = dir / "diff";
    testing::internal::CaptureStderr();
    EXPECT_EQ(runDiffCommand(options), 1);
    const std::string error = testing::internal::GetCapturedStderr();
    EXPECT_NE(error.find("testbed: error: image sizes differ: " + options.a.string() +
                         " is 40x20, " + options.b.string() + " is 20x20"),
              std::string::npos)
        << error;
    EXPECT_FALSE(fs::exists(options.out)) << "nothing written";

    options.b = dir / "missing.exr";
    testing::internal::CaptureStderr();
    EXPECT_EQ(runDiffCommand(options), 1);
    EXPECT_NE(testing::internal::GetCapturedStderr().find("cannot read"), std::string::npos);
}

// A file rewritten at the same path with another size and channel count is read as it is now:
// diff once read images through an ImageBuf made from the file name, whose spec came from
// OpenImageIO's shared ImageCache, which remembered the path's first spec; the second read then
// wrote the new image into a buffer sized for the old one (a heap overflow exr_fuzzer found,
// since it writes every input to one path). Under AddressSanitizer the old code crashes here.
TEST(DiffCommand, ReadsAFileRewrittenAtTheSamePathAsItIsNow) {
    const fs::path dir = freshTestFolder();
    const fs::path path = dir / "rewritten.exr";
    writeImage(path, 0.0f, nowhere, 1.0f, "", kWidth, 1);
    ImageDiff first = diffImageFiles(path, path);
    EXPECT_EQ(first.height, 1);
    writeImage(path, 0.25f, everywhere, 2.0f, "extra", kWidth, kHeight);
    const ImageDiff second = diffImageFiles(path, path);
    EXPECT_EQ(second.width, kWidth);
    EXPECT_EQ(second.height, kHeight);
    ASSERT_EQ(second.beautyA[0].size(), size_t(kWidth) * kHeight);
    EXPECT_EQ(second.beautyA[0].back(), 0.75f);
    EXPECT_NE(channel(second, "extra"), nullptr);
}

// A valid EXR whose "channels" attribute is made to declare 1 769 108 595 bytes (as in the input
// exr_fuzzer found): refused from the header's counts, before OpenEXR allocates that much.
TEST(DiffCommand, RefusesAnExrAttributeLongerThanTheFile) {
    const fs::path dir = freshTestFolder();
    const fs::path path = writeImage(dir / "a.exr", 0.0f, nowhere, 1.0f);
    std::string bytes = readText(path);
    const std::string attribute = std::string("channels") + '\0' + "chlist" + '\0';
    const size_t at = bytes.find(attribute);
    ASSERT_NE(at, std::string::npos);
    const uint32_t huge = 1769108595u;
    for (int i = 0; i < 4; ++i)
        bytes[at + attribute.size() + size_t(i)] = char((huge >> (8 * i)) & 0xff);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    try {
        (void)diffImageFiles(path, path);
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("corrupt EXR header: attribute 'channels' declares "
                                             "1769108595 bytes"),
                  std::string::npos)
            << e.what();
    }
}

// OpenEXR reads a chlist (and the fixed-size types) by its content, not by the count the header
// declares; a count larger than the content made it parse the rest as another attribute that
// declared 1.5 GB (exr_fuzzer). A count that disagrees with the value is refused before OpenEXR
// opens the file, for a chlist and for a fixed-size attribute.
TEST(DiffCommand, RefusesAnExrAttributeWhoseCountDisagreesWithItsValue) {
    const fs::path dir = freshTestFolder();
    const fs::path path = writeImage(dir / "a.exr", 0.0f, nowhere, 1.0f);
    const std::string original = readText(path);
    auto withCount = [&](const std::string& name, const std::string& type, int32_t change) {
        std::string bytes = original;
        const std::string attribute = name + '\0' + type + '\0';
        const size_t at = bytes.find(attribute);
        EXPECT_NE(at, std::string::npos) << name;
        if (at == std::string::npos)
            return std::pair<std::string, uint32_t>{};
        const size_t countAt = at + attribute.size();
        uint32_t count = 0;
        for (int i = 0; i < 4; ++i)
            count |= uint32_t(uint8_t(bytes[countAt + size_t(i)])) << (8 * i);
        const uint32_t changed = count + uint32_t(change);
        for (int i = 0; i < 4; ++i)
            bytes[countAt + size_t(i)] = char((changed >> (8 * i)) & 0xff);
        return std::pair{bytes, count};
    };
    for (const auto& [name, type] : {std::pair<std::string, std::string>{"channels", "chlist"},
                                     {"compression", "compression"}}) {
        const auto [bytes, count] = withCount(name, type, 4);
        const fs::path changed = dir / (name + ".exr");
        std::ofstream(changed, std::ios::binary | std::ios::trunc) << bytes;
        try {
            (void)diffImageFiles(changed, path);
            ADD_FAILURE() << name << ": no error";
        } catch (const std::runtime_error& e) {
            const std::string expected = "corrupt EXR header: attribute '" + name + "' of type " +
                                         type + " declares " + std::to_string(count + 4) +
                                         " bytes, its value holds " + std::to_string(count);
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        }
    }
    EXPECT_NO_THROW((void)diffImageFiles(path, path)); // the unchanged file still compares
}

// A copy of the EXR at `path`, at `copy`, whose data window ends at column xMax.
fs::path withDataWindowXMax(const fs::path& path, uint32_t xMax, const fs::path& copy) {
    std::string bytes = readText(path);
    const std::string attribute = std::string("dataWindow") + '\0' + "box2i" + '\0';
    const size_t at = bytes.find(attribute);
    EXPECT_NE(at, std::string::npos);
    const size_t xMaxAt = at + attribute.size() + 4 + 8; // count, xMin, yMin
    for (int i = 0; i < 4 && at != std::string::npos; ++i)
        bytes[xMaxAt + size_t(i)] = char((xMax >> (8 * i)) & 0xff);
    std::ofstream(copy, std::ios::binary | std::ios::trunc) << bytes;
    return copy;
}

// A few bytes declaring a huge data window: refused by the header walk, before OpenImageIO opens
// the file (which took 32-39 s under AddressSanitizer on such a 5.7 KB file, found by
// exr_fuzzer).
TEST(DiffCommand, RefusesAnExrDataWindowOutsideTheLimitsBeforeOpeningIt) {
    const fs::path dir = freshTestFolder();
    const fs::path path = writeImage(dir / "a.exr", 0.0f, nowhere, 1.0f);
    const fs::path wide = withDataWindowXMax(path, 983040, dir / "wide.exr");
    try {
        experiments::checkExrAttributeSizes(wide);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("its data window is 983041x"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW((void)diffImageFiles(wide, path), std::runtime_error);
    EXPECT_NO_THROW(experiments::checkExrAttributeSizes(path)); // the unchanged file passes
}

// exr_fuzzer's heap overflow in CI: a render whose data window (80 x 8) is wider than its display
// window (16 x 8) made OpenImageIO 2.4 write 40960 bytes into an 8192-byte buffer. Such a file is
// refused by the header walk before OpenImageIO reads it.
TEST(DiffCommand, RefusesAnExrWhoseDataWindowIsNotItsDisplayWindow) {
    const fs::path dir = freshTestFolder();
    const fs::path path = writeImage(dir / "a.exr", 0.0f, nowhere, 1.0f);
    const fs::path overscan = withDataWindowXMax(path, 79, dir / "overscan.exr");
    try {
        (void)diffImageFiles(overscan, path);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("its data window differs from its display window"),
                  std::string::npos)
            << e.what();
    }
}

// The message diffImageFiles refuses `path` with, or "" when it compares it.
std::string refusalOf(const fs::path& path, const fs::path& other) {
    try {
        (void)diffImageFiles(path, other);
        return "";
    } catch (const std::runtime_error& e) {
        return e.what();
    }
}

// Inputs that are not linear EXR are refused, naming the file and what it is (issue 16), in either
// position; a linear EXR tagged linear is compared.
TEST(DiffCommand, RefusesInputsThatAreNotLinearExr) {
    const fs::path dir = freshTestFolder();
    const fs::path exr = writeImage(dir / "linear.exr", 0.0f, nowhere, 1.0f);
    const size_t n = size_t(kWidth) * kHeight;
    const std::vector<float> grey(n, 0.5f);

    // A tone-mapped PNG preview (8-bit, sRGB-encoded).
    const fs::path png = dir / "preview.png";
    writePreviewPng(png, kWidth, kHeight, grey.data(), grey.data(), grey.data());
    for (const auto& [a, b] : {std::pair{png, exr}, std::pair{exr, png}}) {
        const std::string message = refusalOf(a, b);
        EXPECT_NE(message.find(png.string() + " is not a linear EXR: it is a png file (uint8"),
                  std::string::npos)
            << message;
    }

    // A JPEG.
    const fs::path jpeg = dir / "preview.jpg";
    {
        auto out = OIIO::ImageOutput::create(jpeg.string());
        ASSERT_TRUE(out);
        std::vector<unsigned char> pixels(n * 3, 128);
        ASSERT_TRUE(
            out->open(jpeg.string(), OIIO::ImageSpec(kWidth, kHeight, 3, OIIO::TypeDesc::UINT8)));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
        out->close();
    }
    EXPECT_NE(refusalOf(jpeg, exr).find("it is a jpeg file"), std::string::npos);

    // An EXR with 32-bit unsigned integer beauty channels.
    const fs::path integers = dir / "integers.exr";
    {
        auto out = OIIO::ImageOutput::create(integers.string());
        ASSERT_TRUE(out);
        std::vector<uint32_t> pixels(n * 3, 1);
        ASSERT_TRUE(out->open(integers.string(),
                              OIIO::ImageSpec(kWidth, kHeight, 3, OIIO::TypeDesc::UINT32)));
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT32, pixels.data()));
        out->close();
    }
    EXPECT_NE(refusalOf(integers, exr).find("channel R is uint"), std::string::npos)
        << refusalOf(integers, exr);

    // An EXR tagged with a display colour space, and one tagged linear.
    const std::vector<ImagePlane> planes = {
        {"R", grey.data()}, {"G", grey.data()}, {"B", grey.data()}};
    const fs::path srgb = dir / "srgb.exr";
    writeMultiLayerExr(srgb, kWidth, kHeight, planes, {{"colorspace", "sRGB"}});
    EXPECT_NE(refusalOf(exr, srgb).find("its colorspace attribute says 'sRGB', not a linear "
                                        "colour space"),
              std::string::npos)
        << refusalOf(exr, srgb);
    const fs::path tagged = dir / "tagged-linear.exr";
    writeMultiLayerExr(tagged, kWidth, kHeight, planes, {{"colorspace", "lin_rec709"}});
    EXPECT_EQ(refusalOf(exr, tagged), "");

    // The command: one error line, exit code 1, nothing written.
    DiffCommandOptions options;
    options.a = png;
    options.b = exr;
    options.out = dir / "report";
    testing::internal::CaptureStderr();
    EXPECT_EQ(runDiffCommand(options), 1);
    const std::string error = testing::internal::GetCapturedStderr();
    EXPECT_EQ(error.rfind("testbed: error: ", 0), 0u) << error;
    EXPECT_EQ(std::count(error.begin(), error.end(), '\n'), 1) << error;
    EXPECT_FALSE(fs::exists(options.out / "index.html"));
}

} // namespace
} // namespace experiments
