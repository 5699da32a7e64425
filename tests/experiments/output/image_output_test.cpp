// Tests for experiments/AtomicFile and experiments/ImageOutput: files are written into a fresh
// folder per test under <build>/test-output/experiments/ and read back with OpenImageIO. The
// folders are left in place, so the images of a failed test can be inspected (failure messages
// print their paths).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "experiments/output/AtomicFile.h"
#include "experiments/output/ImageOutput.h"

namespace experiments {
namespace {

namespace fs = std::filesystem;

fs::path freshTestFolder() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const fs::path dir = fs::path(TESTBED_BINARY_DIR) / "test-output" / "experiments" /
                         (std::string(info->test_suite_name()) + "." + info->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::set<std::string> fileNamesIn(const fs::path& dir) {
    std::set<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir))
        names.insert(entry.path().filename().string());
    return names;
}

std::string readText(const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    std::ostringstream text;
    text << file.rdbuf();
    return text.str();
}

// Runs f, expects it to throw E, and returns the message (empty if nothing was thrown).
template <typename E, typename F> std::string thrownMessage(F&& f) {
    try {
        f();
    } catch (const E& error) {
        return error.what();
    }
    ADD_FAILURE() << "expected an exception";
    return {};
}

struct ReadImage {
    OIIO::ImageSpec spec;
    std::vector<float> floats;  // filled when read as FLOAT
    std::vector<uint8_t> bytes; // filled when read as UINT8
};

ReadImage readImage(const fs::path& path, OIIO::TypeDesc type) {
    ReadImage image;
    std::unique_ptr<OIIO::ImageInput> input = OIIO::ImageInput::open(path.string());
    if (!input) {
        ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
        return image;
    }
    image.spec = input->spec();
    const size_t valueCount = image.spec.image_pixels() * image.spec.nchannels;
    bool ok = false;
    if (type == OIIO::TypeDesc::FLOAT) {
        image.floats.resize(valueCount);
        ok = input->read_image(0, 0, 0, image.spec.nchannels, type, image.floats.data());
    } else {
        image.bytes.resize(valueCount);
        ok = input->read_image(0, 0, 0, image.spec.nchannels, type, image.bytes.data());
    }
    EXPECT_TRUE(ok) << "reading " << path << ": " << input->geterror();
    return image;
}

std::vector<std::string> channelList(const std::string& commaSeparated) {
    std::vector<std::string> names;
    std::istringstream stream(commaSeparated);
    for (std::string name; std::getline(stream, name, ',');)
        names.push_back(name);
    return names;
}

using Rgb8 = std::array<uint8_t, 3>;
Rgb8 pixelAt(const ReadImage& image, int x, int y) {
    const uint8_t* p = &image.bytes[(size_t(y) * image.spec.width + x) * 3];
    return {p[0], p[1], p[2]};
}

// ---------------------------------------------------------------------------------------------
// AtomicFile

TEST(AtomicFile, WritesTextAndLeavesOnlyTheFinalFile) {
    const fs::path dir = freshTestFolder();
    writeTextAtomically(dir / "stats.json", "{\"a\": 1}\n");
    EXPECT_EQ(readText(dir / "stats.json"), "{\"a\": 1}\n");
    EXPECT_EQ(fileNamesIn(dir), std::set<std::string>{"stats.json"});
}

TEST(AtomicFile, TemporaryFileIsAHiddenSiblingKeepingTheExtension) {
    const fs::path dir = freshTestFolder();
    const fs::path finalPath = dir / "render.exr";
    writeFileAtomically(finalPath, [&](const fs::path& tempPath) {
        EXPECT_EQ(tempPath.parent_path(), dir);
        EXPECT_EQ(tempPath.filename().string().front(), '.');
        EXPECT_EQ(tempPath.extension(), ".exr");
        EXPECT_FALSE(fs::exists(finalPath)) << "the final name must appear only at the end";
        std::ofstream(tempPath) << "complete";
    });
    EXPECT_EQ(readText(finalPath), "complete");
    EXPECT_EQ(fileNamesIn(dir), std::set<std::string>{"render.exr"});
}

TEST(AtomicFile, ThrowingWriterLeavesNoFinalAndNoTemporaryFile) {
    const fs::path dir = freshTestFolder();
    const fs::path finalPath = dir / "render.exr";
    EXPECT_THROW(writeFileAtomically(finalPath,
                                     [](const fs::path& tempPath) {
                                         std::ofstream(tempPath) << "half";
                                         throw std::runtime_error("encoder failed");
                                     }),
                 std::runtime_error);
    EXPECT_FALSE(fs::exists(finalPath));
    EXPECT_TRUE(fileNamesIn(dir).empty());
}

TEST(AtomicFile, ThrowingWriterKeepsThePreviousFile) {
    const fs::path dir = freshTestFolder();
    const fs::path finalPath = dir / "stats.json";
    writeTextAtomically(finalPath, "old");
    EXPECT_THROW(writeFileAtomically(finalPath,
                                     [](const fs::path& tempPath) {
                                         std::ofstream(tempPath) << "new but half";
                                         throw std::runtime_error("encoder failed");
                                     }),
                 std::runtime_error);
    EXPECT_EQ(readText(finalPath), "old");
    EXPECT_EQ(fileNamesIn(dir), std::set<std::string>{"stats.json"});
}

TEST(AtomicFile, WriterThatCreatesNothingIsAnError) {
    const fs::path dir = freshTestFolder();
    const fs::path finalPath = dir / "empty.png";
    const std::string message =
        thrownMessage<std::runtime_error>([&] { writeFileAtomically(finalPath, [](auto&) {}); });
    EXPECT_NE(message.find(finalPath.string()), std::string::npos) << message;
    EXPECT_TRUE(fileNamesIn(dir).empty());
}

TEST(AtomicFile, FailedRenameNamesThePathAndRemovesTheTemporaryFile) {
    const fs::path dir = freshTestFolder();
    const fs::path finalPath = dir / "occupied";
    fs::create_directories(finalPath / "child"); // rename cannot replace a non-empty folder
    const std::string message =
        thrownMessage<std::runtime_error>([&] { writeTextAtomically(finalPath, "text"); });
    EXPECT_NE(message.find(finalPath.string()), std::string::npos) << message;
    EXPECT_EQ(fileNamesIn(dir), std::set<std::string>{"occupied"});
}

TEST(AtomicFile, MissingFolderNamesThePathAndTheSystemError) {
    const fs::path finalPath = freshTestFolder() / "missing" / "stats.json";
    const std::string message =
        thrownMessage<std::runtime_error>([&] { writeTextAtomically(finalPath, "text"); });
    EXPECT_NE(message.find(finalPath.string()), std::string::npos) << message;
    EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------------------------
// ensureWritableDirectory

TEST(EnsureWritableDirectory, CreatesMissingParentsAndLeavesNoProbe) {
    const fs::path base = freshTestFolder();
    const fs::path dir = base / "a" / "b" / "c";
    ensureWritableDirectory(dir);
    EXPECT_TRUE(fs::is_directory(dir));
    EXPECT_TRUE(fileNamesIn(dir).empty());
    ensureWritableDirectory(dir); // an existing folder is fine too
}

TEST(EnsureWritableDirectory, PathUnderARegularFileThrowsNamingThePath) {
    const fs::path base = freshTestFolder();
    writeTextAtomically(base / "file.txt", "not a folder");
    const fs::path dir = base / "file.txt" / "sub";
    const std::string message =
        thrownMessage<std::runtime_error>([&] { ensureWritableDirectory(dir); });
    EXPECT_NE(message.find("cannot write to output folder " + dir.string()), std::string::npos)
        << message;
}

TEST(EnsureWritableDirectory, RegularFileThrowsNamingThePath) {
    const fs::path file = freshTestFolder() / "file.txt";
    writeTextAtomically(file, "not a folder");
    const std::string message =
        thrownMessage<std::runtime_error>([&] { ensureWritableDirectory(file); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("not a folder"), std::string::npos) << message;
}

TEST(EnsureWritableDirectory, FolderThatNobodyCanCreateThrows) {
    // procfs refuses new entries even to root, unlike permission bits.
    const fs::path dir = "/proc/testbed-forbidden/out";
    const std::string message =
        thrownMessage<std::runtime_error>([&] { ensureWritableDirectory(dir); });
    EXPECT_NE(message.find("cannot write to output folder " + dir.string()), std::string::npos)
        << message;
}

TEST(EnsureWritableDirectory, ReadOnlyFolderThrows) {
    const fs::path dir = freshTestFolder() / "read-only";
    fs::create_directories(dir);
    fs::permissions(dir, fs::perms(0555));
    // Root (CAP_DAC_OVERRIDE) writes through permission bits; ask the kernel, not getuid().
    const fs::path attempt = dir / "attempt";
    std::FILE* file = std::fopen(attempt.c_str(), "wb");
    if (file) {
        std::fclose(file);
        fs::remove(attempt);
        fs::permissions(dir, fs::perms(0755));
        GTEST_SKIP() << "this process can write into a 0555 folder (running as root), so a "
                        "read-only folder cannot be simulated; FolderThatNobodyCanCreateThrows "
                        "covers the failing probe path";
    }
    const std::string message =
        thrownMessage<std::runtime_error>([&] { ensureWritableDirectory(dir); });
    fs::permissions(dir, fs::perms(0755));
    EXPECT_NE(message.find("cannot write to output folder " + dir.string()), std::string::npos)
        << message;
    EXPECT_NE(message.find("Permission denied"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------------------------
// writeMultiLayerExr

TEST(MultiLayerExr, RoundTripsTwelveNamedFloatChannelsBitExactly) {
    const fs::path path = freshTestFolder() / "render.exr";
    // 21 rows: not a multiple of the 16-row chunks the writer hands to the encoder.
    constexpr int kWidth = 37, kHeight = 21;
    const std::vector<std::string> names = channelList(
        "R,G,B,N.X,N.Y,N.Z,Z,albedo.R,albedo.G,albedo.B,lights.evaluated,lights.oracle");
    // Values half cannot hold (0.1 steps, 1e30, denormals, -0, Inf, NaN) prove float32 storage.
    auto valueAt = [](size_t channel, size_t pixel) {
        switch (pixel % 7) {
        case 0:
            return 1e30f * float(channel + 1);
        case 1:
            return std::numeric_limits<float>::denorm_min() * float(pixel);
        case 2:
            return -0.0f;
        case 3:
            return std::numeric_limits<float>::infinity();
        case 4:
            return std::numeric_limits<float>::quiet_NaN();
        default:
            return 0.1f * float(pixel) + 1000.0f * float(channel);
        }
    };
    std::vector<std::vector<float>> planeData(names.size());
    std::vector<ImagePlane> planes;
    for (size_t c = 0; c < names.size(); ++c) {
        for (size_t i = 0; i < size_t(kWidth) * kHeight; ++i)
            planeData[c].push_back(valueAt(c, i));
        planes.push_back({names[c], planeData[c].data()});
    }
    writeMultiLayerExr(path, kWidth, kHeight, planes,
                       {{"testbed:stage", "tiled"}, {"testbed:scene", "sponza"}});
    EXPECT_EQ(fileNamesIn(path.parent_path()), std::set<std::string>{"render.exr"});

    const ReadImage image = readImage(path, OIIO::TypeDesc::FLOAT);
    ASSERT_EQ(image.spec.width, kWidth) << path;
    ASSERT_EQ(image.spec.height, kHeight) << path;
    ASSERT_EQ(image.spec.nchannels, int(names.size())) << path;
    // EXR keeps no channel order; OpenImageIO presents the order documented in ImageOutput.h.
    const std::vector<std::string> readOrder = channelList(
        "R,G,B,Z,N.X,N.Y,N.Z,albedo.R,albedo.G,albedo.B,lights.evaluated,lights.oracle");
    EXPECT_EQ(image.spec.channelnames, readOrder);
    EXPECT_EQ(image.spec.format, OIIO::TypeDesc::FLOAT);
    for (int c = 0; c < image.spec.nchannels; ++c)
        EXPECT_EQ(image.spec.channelformat(c), OIIO::TypeDesc::FLOAT) << image.spec.channelnames[c];
    EXPECT_EQ(image.spec.get_string_attribute("compression"), "zip");
    EXPECT_EQ(image.spec.get_string_attribute("testbed:stage"), "tiled");
    EXPECT_EQ(image.spec.get_string_attribute("testbed:scene"), "sponza");

    for (int readChannel = 0; readChannel < image.spec.nchannels; ++readChannel) {
        const std::string& name = image.spec.channelnames[readChannel];
        const size_t written = size_t(std::find(names.begin(), names.end(), name) - names.begin());
        ASSERT_LT(written, names.size()) << "unexpected channel " << name;
        int mismatches = 0;
        for (size_t i = 0; i < size_t(kWidth) * kHeight; ++i) {
            const float read = image.floats[i * image.spec.nchannels + readChannel];
            if (std::bit_cast<uint32_t>(read) != std::bit_cast<uint32_t>(valueAt(written, i)))
                ++mismatches;
        }
        EXPECT_EQ(mismatches, 0) << "channel " << name << " in " << path;
    }
}

TEST(MultiLayerExr, RejectsDuplicateChannelNamesWithoutWriting) {
    const fs::path path = freshTestFolder() / "render.exr";
    const std::vector<float> data(4, 1.0f);
    const std::string message = thrownMessage<std::invalid_argument>([&] {
        writeMultiLayerExr(path, 2, 2, {{"R", data.data()}, {"R", data.data()}}, {});
    });
    EXPECT_NE(message.find("channel R is given twice"), std::string::npos) << message;
    EXPECT_TRUE(fileNamesIn(path.parent_path()).empty());
}

TEST(MultiLayerExr, MissingFolderThrowsNamingThePath) {
    const fs::path path = freshTestFolder() / "missing" / "render.exr";
    const std::vector<float> data(4, 1.0f);
    const std::string message = thrownMessage<std::runtime_error>([&] {
        writeMultiLayerExr(path, 2, 2, {{"R", data.data()}}, {});
    });
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

// ---------------------------------------------------------------------------------------------
// writePreviewPng

// runImageLibraryOnTheCallingThread (ImageOutput.h): once the testbed has handed pixels to
// OpenImageIO, its algorithms run on the calling thread, not in a pool of its own.
TEST(ImageLibrary, RunsOnTheCallingThreadOnceTheTestbedWritesAnImage) {
    const std::vector<float> grey(4, 0.18f);
    writePreviewPng(freshTestFolder() / "one-thread.png", 2, 2, grey.data(), grey.data(),
                    grey.data());
    int threads = -1;
    ASSERT_TRUE(OIIO::getattribute("threads", threads));
    EXPECT_EQ(threads, 1);
}

TEST(PreviewPng, ToneMapsAndMapsNanAndInfinityToBlackAndWhite) {
    const fs::path path = freshTestFolder() / "preview.png";
    constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
    constexpr float kInf = std::numeric_limits<float>::infinity();
    // Pixels: black, NaN/+Inf/-Inf, mid grey, a huge finite value, top row vs bottom row.
    const std::vector<float> r{0.0f, kNan, 0.18f, 1e30f, 0.5f, 0.0f, 0.0f, 0.0f};
    const std::vector<float> g{0.0f, kInf, 0.18f, 1e30f, 0.5f, 0.0f, 0.0f, 0.0f};
    const std::vector<float> b{0.0f, -kInf, 0.18f, 1e30f, 0.5f, 0.0f, 0.0f, 0.0f};
    writePreviewPng(path, 4, 2, r.data(), g.data(), b.data());

    const ReadImage image = readImage(path, OIIO::TypeDesc::UINT8);
    ASSERT_EQ(image.spec.width, 4) << path;
    ASSERT_EQ(image.spec.height, 2) << path;
    ASSERT_EQ(image.spec.nchannels, 3) << path;
    EXPECT_EQ(pixelAt(image, 0, 0), (Rgb8{0, 0, 0}));
    EXPECT_EQ(pixelAt(image, 1, 0), (Rgb8{0, 255, 0}));
    const Rgb8 grey = pixelAt(image, 2, 0);
    EXPECT_EQ(grey[0], grey[1]);
    EXPECT_GT(grey[0], 64) << "0.18 should land mid-range after tone mapping and sRGB";
    EXPECT_LT(grey[0], 192);
    EXPECT_EQ(pixelAt(image, 3, 0), (Rgb8{255, 255, 255}));
    EXPECT_GT(pixelAt(image, 0, 1)[0], grey[0]) << "row 0 of the input is the top row";
}

TEST(PreviewPng, ExposureScalesTheLinearInput) {
    const fs::path dir = freshTestFolder();
    const std::vector<float> dim{0.1f}, bright{0.2f};
    writePreviewPng(dir / "exposed.png", 1, 1, dim.data(), dim.data(), dim.data(), 2.0f);
    writePreviewPng(dir / "bright.png", 1, 1, bright.data(), bright.data(), bright.data());
    EXPECT_EQ(readImage(dir / "exposed.png", OIIO::TypeDesc::UINT8).bytes,
              readImage(dir / "bright.png", OIIO::TypeDesc::UINT8).bytes);
    EXPECT_THROW(writePreviewPng(dir / "bad.png", 1, 1, dim.data(), dim.data(), dim.data(), 0.0f),
                 std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// writeHeatmapPng

// A 64x40 count image: left half 0, right half a ramp 1..maxCount along x, and one pixel at
// hotCount in the top-right corner.
std::vector<uint32_t> heatmapCounts(int width, int height, uint32_t maxCount, uint32_t hotCount) {
    std::vector<uint32_t> counts(size_t(width) * height, 0);
    for (int y = 0; y < height; ++y)
        for (int x = width / 2; x < width; ++x)
            counts[size_t(y) * width + x] =
                1 + uint32_t((x - width / 2) * (maxCount - 1) / (width / 2 - 1));
    counts[width - 1] = hotCount;
    return counts;
}

// True if rows [y0, y1) contain a light grey or white pixel: legend text, tick marks or swatch.
bool hasBrightPixels(const ReadImage& image, int y0, int y1) {
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < image.spec.width; ++x) {
            const Rgb8 p = pixelAt(image, x, y);
            if (p[0] > 200 && p[1] > 200 && p[2] > 200)
                return true;
        }
    return false;
}

TEST(HeatmapPng, AutoScaleHasLegendStripAndDistinctColours) {
    const fs::path path = freshTestFolder() / "lights.png";
    constexpr int kWidth = 64, kHeight = 40;
    const std::vector<uint32_t> counts = heatmapCounts(kWidth, kHeight, 37, 37);
    writeHeatmapPng(path, kWidth, kHeight, counts.data(), 0);

    const ReadImage image = readImage(path, OIIO::TypeDesc::UINT8);
    ASSERT_EQ(image.spec.width, kHeatmapMinWidth) << path;
    ASSERT_EQ(image.spec.height, kHeight + kHeatmapLegendHeight) << path;
    ASSERT_EQ(image.spec.nchannels, 3) << path;
    const Rgb8 zero = pixelAt(image, 0, 0), one = pixelAt(image, kWidth / 2, 0);
    const Rgb8 max = pixelAt(image, kWidth - 1, 5);
    EXPECT_EQ(zero, (Rgb8{0, 0, 0})) << path;
    EXPECT_NE(one, zero) << path;
    EXPECT_NE(max, zero) << path;
    EXPECT_NE(max, one) << path;
    EXPECT_NE(max, (Rgb8{255, 255, 255})) << "auto scale must not saturate its maximum; " << path;
    EXPECT_FALSE(hasBrightPixels(image, 0, kHeight)) << path;
    // Labels sit below the bar and its ticks, in the last rows of the legend.
    EXPECT_TRUE(hasBrightPixels(image, kHeight + 28, kHeight + kHeatmapLegendHeight))
        << "no legend labels in " << path;
}

TEST(HeatmapPng, CountsAboveAnExplicitScaleAreWhite) {
    const fs::path path = freshTestFolder() / "lights.png";
    constexpr int kWidth = 400, kHeight = 30; // wider than kHeatmapMinWidth: no padding
    const std::vector<uint32_t> counts = heatmapCounts(kWidth, kHeight, 16, 500);
    writeHeatmapPng(path, kWidth, kHeight, counts.data(), 16);

    const ReadImage image = readImage(path, OIIO::TypeDesc::UINT8);
    ASSERT_EQ(image.spec.width, kWidth) << path;
    ASSERT_EQ(image.spec.height, kHeight + kHeatmapLegendHeight) << path;
    EXPECT_EQ(pixelAt(image, kWidth - 1, 0), (Rgb8{255, 255, 255})) << path;
    EXPECT_NE(pixelAt(image, kWidth - 1, 1), (Rgb8{255, 255, 255})) << path;
    EXPECT_EQ(pixelAt(image, 0, kHeight - 1), (Rgb8{0, 0, 0})) << path;
}

TEST(HeatmapPng, AutoScaleIsTheMaximumAndAtLeastOne) {
    EXPECT_EQ(heatmapAutoScale(nullptr, 0), 1u);
    const std::vector<uint32_t> zeros(5, 0), mixed{3, 9, 2};
    EXPECT_EQ(heatmapAutoScale(zeros.data(), zeros.size()), 1u);
    EXPECT_EQ(heatmapAutoScale(mixed.data(), mixed.size()), 9u);
}

TEST(HeatmapPng, AllZeroImageAndHugeScaleStillWrite) {
    const fs::path dir = freshTestFolder();
    const std::vector<uint32_t> zeros(8 * 8, 0);
    writeHeatmapPng(dir / "zeros.png", 8, 8, zeros.data(), 0);
    writeHeatmapPng(dir / "huge.png", 8, 8, zeros.data(), std::numeric_limits<uint32_t>::max());
    EXPECT_EQ(fileNamesIn(dir), (std::set<std::string>{"huge.png", "zeros.png"}));
}

// ---------------------------------------------------------------------------------------------
// Scalar maps (error.png, flip.png)

// A row of values 10^(-6 + 6 x / (w - 1)): six decades from 1e-6 to 1, then a zero row and a
// row with an outlier above the scale.
std::vector<float> decadeRamp(int width) {
    std::vector<float> values(size_t(width) * 3);
    for (int x = 0; x < width; ++x) {
        values[size_t(x)] = float(std::pow(10.0, -6.0 + 6.0 * x / (width - 1)));
        values[size_t(width + x)] = 0.0f;
        values[size_t(2 * width + x)] = x == 0 ? 50.0f : 0.5f;
    }
    return values;
}

int brightness(const Rgb8& c) {
    return int(c[0]) + int(c[1]) + int(c[2]);
}

TEST(ScalarMapPng, LinearScaleDarkensSmallValuesLogScaleSpreadsThem) {
    const fs::path dir = freshTestFolder();
    constexpr int kWidth = 200;
    const std::vector<float> values = decadeRamp(kWidth);
    ScalarMapStyle linear;
    linear.max = 1.0f;
    linear.title = "linear";
    ScalarMapStyle log = linear;
    log.scale = MapScale::Log;
    log.logDecades = 6.0f;
    log.title = "log";
    writeScalarMapPng(dir / "linear.png", kWidth, 3, values.data(), linear);
    writeScalarMapPng(dir / "log.png", kWidth, 3, values.data(), log);
    const ReadImage a = readImage(dir / "linear.png", OIIO::TypeDesc::UINT8);
    const ReadImage b = readImage(dir / "log.png", OIIO::TypeDesc::UINT8);
    ASSERT_EQ(a.spec.width, kScalarMapMinWidth);
    ASSERT_EQ(a.spec.height, 3 + kScalarMapLegendHeight);
    // 1e-3 (half-way on the log scale) is about the colour map's bottom on the linear scale, and
    // far from both ends on the log scale.
    const int middle = kWidth / 2;
    EXPECT_LE(std::abs(brightness(pixelAt(a, middle, 0)) - brightness(pixelAt(a, 1, 0))), 6) << dir;
    EXPECT_GT(std::abs(brightness(pixelAt(b, middle, 0)) - brightness(pixelAt(b, 1, 0))), 60)
        << dir;
    EXPECT_NE(pixelAt(b, middle, 0), pixelAt(b, kWidth - 1, 0)) << dir;
    // Exactly zero is black on both; above the maximum is white; the legend has labels.
    for (const ReadImage* image : {&a, &b}) {
        EXPECT_EQ(pixelAt(*image, 5, 1), (Rgb8{0, 0, 0})) << dir;
        EXPECT_EQ(pixelAt(*image, 0, 2), (Rgb8{255, 255, 255})) << dir;
        EXPECT_NE(pixelAt(*image, 1, 2), (Rgb8{255, 255, 255})) << dir;
        EXPECT_TRUE(hasBrightPixels(*image, 3 + 40, 3 + kScalarMapLegendHeight)) << dir;
    }
    EXPECT_GT(brightness(pixelAt(b, middle, 0)), brightness(pixelAt(b, 1, 0)));
}

TEST(ScalarMapPng, AutoRangeAndBadArguments) {
    const std::vector<float> values = {0.0f, 0.25f, std::numeric_limits<float>::infinity(), 2.0f};
    ScalarMapStyle style;
    EXPECT_EQ(scalarMapRange(values.data(), values.size(), style), std::make_pair(0.0f, 2.0f));
    style.scale = MapScale::Log;
    EXPECT_EQ(scalarMapRange(values.data(), values.size(), style).first, 2.0f / 10000.0f);
    style.max = 8.0f;
    EXPECT_EQ(scalarMapRange(values.data(), values.size(), style).second, 8.0f);
    EXPECT_EQ(parseMapScale("log"), MapScale::Log);
    EXPECT_EQ(parseMapScale("linear"), MapScale::Linear);
    EXPECT_NE(thrownMessage<std::invalid_argument>([] {
                  parseMapScale("logarithmic");
              }).find("expected linear or log"),
              std::string::npos);
    const fs::path dir = freshTestFolder();
    style.colourMap = "no-such-map";
    EXPECT_NE(thrownMessage<std::invalid_argument>([&] {
                  writeScalarMapPng(dir / "bad.png", 2, 2, values.data(), style);
              }).find("no-such-map"),
              std::string::npos);
    EXPECT_TRUE(fileNamesIn(dir).empty());
}

} // namespace
} // namespace experiments
