#include "experiments/compare/DiffCommand.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "experiments/CommandErrors.h"
#include "experiments/compare/FlipMetric.h"
#include "experiments/compare/ImageMetrics.h"
#include "experiments/output/AtomicFile.h"
#include "experiments/output/ImageOutput.h"
#include "experiments/output/JsonText.h"
#include "experiments/output/PlotScript.h"
#include "experiments/output/ReportHtml.h"
#include "scenes/input/Limits.h"
#include "scenes/input/WholeFile.h"

namespace experiments {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kBeauty[3] = {"R", "G", "B"};

std::string lowercase(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return text;
}

// The metrics compare radiance, so both inputs must hold linear colour (see DiffCommand.h): an
// OpenEXR file whose beauty channels are half or float and whose colour-space attribute, if any,
// names a linear space. Anything else (a PNG or JPEG preview, 8-bit or integer channels, an EXR
// tagged sRGB or log) is refused, saying what it is, rather than compared as if linear.
void checkLinearExr(const fs::path& path, const std::string& format,
                    const OIIO::ImageSpec& header) {
    // header: the file's own spec (its channel formats, before any conversion for reading).
    auto refuse = [&](const std::string& what) {
        throw std::runtime_error(path.string() + " is not a linear EXR: " + what +
                                 "; diff compares linear HDR renders (render.exr, a "
                                 "sweep's references/*.exr), not display images");
    };
    if (format != "openexr")
        refuse("it is a " + (format.empty() ? std::string("non-image") : format) + " file (" +
               header.format.c_str() + " channels" +
               (format == "png" || format == "jpeg" ? ", display-encoded, e.g. sRGB" : "") + ")");
    for (const char* name : kBeauty) {
        const int channel = header.channelindex(name);
        if (channel < 0)
            continue; // reported later, with the other file
        const OIIO::TypeDesc type = header.channelformat(channel);
        if (type != OIIO::TypeDesc::HALF && type != OIIO::TypeDesc::FLOAT)
            refuse(std::string("channel ") + name + " is " + type.c_str() +
                   " (linear colour is stored as half or float)");
    }
    // OpenEXR has no transfer-function field: its pixels are linear by the format's convention.
    // Some writers tag a colour space anyway (a string attribute such as `colorspace`); a tag
    // naming a non-linear one (sRGB, Rec.709 display, ACEScct, log) is refused.
    for (const OIIO::ParamValue& attribute : header.extra_attribs) {
        const std::string name = lowercase(attribute.name().string());
        if (attribute.type() != OIIO::TypeDesc::STRING || name.size() < 10 ||
            name.compare(name.size() - 10, 10, "colorspace") != 0)
            continue;
        const std::string value = attribute.get_string();
        const std::string space = lowercase(value);
        const bool linear = space.empty() || space.find("linear") != std::string::npos ||
                            space.rfind("lin_", 0) == 0 || space == "acescg" ||
                            space == "aces2065-1" || space == "raw";
        if (!linear)
            refuse("its " + attribute.name().string() + " attribute says '" + value +
                   "', not a linear colour space");
    }
}

// The header is read first, so a file that declares an absurd size is refused before its pixels
// are allocated (scenes/input/Limits.h: the render limits, and limits::kMaxImageChannels), and a
// file that holds no linear colour before anything is compared (checkLinearExr).
OIIO::ImageBuf readImage(const fs::path& path) {
    runImageLibraryOnTheCallingThread();
    // A regular file first (scenes/input/WholeFile.h): OpenEXR would block opening a FIFO and
    // read /dev/zero as long as it is asked to. Not read whole, so no byte cap: the header
    // limits below bound what is allocated.
    if (const std::string problem =
            scenes::regularFileProblem(path, std::numeric_limits<uint64_t>::max());
        !problem.empty())
        throw std::runtime_error("cannot read " + path.string() + ": " + problem);
    checkExrAttributeSizes(path);
    // One ImageInput gives the header and the pixels. Not ImageBuf(path): an ImageBuf made from
    // a file name takes its spec through OpenImageIO's shared ImageCache, which remembers the
    // spec of a path it has opened, so a file rewritten at the same path (a re-rendered
    // reference, the fuzzer's input file) was read into a buffer sized for the OLD spec: an
    // 8704-byte write into 1088 bytes (heap-buffer-overflow found by exr_fuzzer in CI).
    std::unique_ptr<OIIO::ImageInput> input = OIIO::ImageInput::open(path.string());
    if (!input)
        throw std::runtime_error("cannot read " + path.string() + ": " + OIIO::geterror());
    const OIIO::ImageSpec header = input->spec();
    checkLinearExr(path, input->format_name(), header);
    if (header.width <= 0 || header.height <= 0 || header.depth != 1 ||
        header.width > scenes::limits::kMaxImageSide ||
        header.height > scenes::limits::kMaxImageSide ||
        uint64_t(header.width) * uint64_t(header.height) > scenes::limits::kMaxPixels ||
        header.nchannels <= 0 || header.nchannels > scenes::limits::kMaxImageChannels ||
        uint64_t(header.width) * uint64_t(header.height) * uint64_t(header.nchannels) >
            scenes::limits::kMaxImageValues ||
        header.deep)
        throw std::runtime_error(
            "cannot read " + path.string() + ": " + std::to_string(header.width) + "x" +
            std::to_string(header.height) + "x" + std::to_string(header.depth) + " pixels of " +
            std::to_string(header.nchannels) + (header.deep ? " deep" : "") +
            " channels is outside the limits (sides 1.." +
            std::to_string(scenes::limits::kMaxImageSide) + ", " +
            std::to_string(scenes::limits::kMaxPixels) + " pixels, 1.." +
            std::to_string(scenes::limits::kMaxImageChannels) + " flat channels, " +
            std::to_string(scenes::limits::kMaxImageValues) + " values)");
    OIIO::ImageSpec pixels = header;
    pixels.set_format(OIIO::TypeDesc::FLOAT);
    pixels.channelformats.clear();
    OIIO::ImageBuf image(pixels);
    if (!input->read_image(0, 0, 0, header.nchannels, OIIO::TypeDesc::FLOAT, image.localpixels()))
        throw std::runtime_error("cannot read " + path.string() + ": " + input->geterror());
    return image;
}

int channelIndex(const OIIO::ImageBuf& image, const std::string& name) {
    return image.spec().channelindex(name);
}

// The named channels of image, in the given order, as a new float image.
OIIO::ImageBuf selectChannels(const OIIO::ImageBuf& image, const std::vector<int>& indices) {
    OIIO::ImageBuf selected;
    if (!OIIO::ImageBufAlgo::channels(selected, image, int(indices.size()), indices))
        throw std::runtime_error("cannot select channels: " + selected.geterror());
    return selected;
}

std::vector<float> channelPlane(const OIIO::ImageBuf& image, int channel) {
    const OIIO::ImageSpec& spec = image.spec();
    std::vector<float> plane(size_t(spec.width) * spec.height);
    OIIO::ROI roi = image.roi();
    roi.chbegin = channel;
    roi.chend = channel + 1;
    if (!image.get_pixels(roi, OIIO::TypeDesc::FLOAT, plane.data()))
        throw std::runtime_error("cannot read channel " + std::to_string(channel) + ": " +
                                 image.geterror());
    return plane;
}

lighting::StageResult beautyAsStageResult(const OIIO::ImageBuf& rgb) {
    lighting::StageResult result;
    result.width = rgb.spec().width;
    result.height = rgb.spec().height;
    for (int c = 0; c < 3; ++c)
        result.radiance[c] = channelPlane(rgb, c);
    return result;
}

OIIO::ImageBufAlgo::PixelStats pixelStats(const OIIO::ImageBuf& image) {
    OIIO::ImageBufAlgo::PixelStats stats = OIIO::ImageBufAlgo::computePixelStats(image);
    if (image.has_error())
        throw std::runtime_error("cannot compute statistics: " + image.geterror());
    return stats;
}

json numberOrText(double value) {
    if (std::isfinite(value))
        return value;
    return std::isnan(value) ? "nan" : value > 0 ? "inf" : "-inf";
}

std::string formatNumber(double value) {
    return displayNumber(value, 6);
}

void writeDiffPlot(const DiffCommandOptions& options, const ImageDiff& diff, const fs::path& png) {
    const fs::path script = requirePlotScript(options.plotsScript, "report.py");
    const std::string python = requirePythonWithMatplotlib(options.python);
    // The plot script reads raw float32; the temporary file is removed whatever happens.
    // Named as AtomicFile names temporaries, so that a killed run's leftover is cleaned.
    const fs::path raw = temporaryPathFor(options.out / "absdiff.f32");
    struct RemoveOnExit {
        fs::path path;
        ~RemoveOnExit() {
            std::error_code ignored;
            fs::remove(path, ignored);
        }
    } cleanup{raw};
    {
        std::ofstream file(raw, std::ios::binary);
        file.write(reinterpret_cast<const char*>(diff.maxAbsDifference.data()),
                   std::streamsize(diff.maxAbsDifference.size() * sizeof(float)));
        file.close(); // flushes: a full disk may only show here
        if (!file)
            throw std::runtime_error("cannot write " + raw.string());
    }
    const int status =
        runProcess({python, script.string(), "diff", "--raw", raw.string(), "--width",
                    std::to_string(diff.width), "--height", std::to_string(diff.height), "--vmax",
                    formatNumber(diff.metrics.maxAbs), "--out", png.string()});
    if (status != 0)
        throw std::runtime_error("plot script " + script.string() + " failed (exit status " +
                                 std::to_string(status) + ")");
}

std::string statsCells(double min, double max, double mean) {
    return "<td>" + formatNumber(min) + "</td><td>" + formatNumber(max) + "</td><td>" +
           formatNumber(mean) + "</td>";
}

std::string diffPage(const ImageDiff& diff, const DiffCommandOptions& options) {
    const DiffMetrics& m = diff.metrics;
    std::ostringstream html;
    const std::string a = options.a.string(), b = options.b.string();
    html << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>testbed "
            "diff: "
         << htmlEscape(options.a.filename().string()) << " vs "
         << htmlEscape(options.b.filename().string()) << "</title>\n"
         << pageCheckScript()
         << "<style>\nbody { font-family: DejaVu Sans, sans-serif; margin: 1.5em; color: #222; }\n"
            "table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0; }\n"
            "th, td { border: 1px solid #ccc; padding: 2px 8px; text-align: right; }\n"
            "th { background: #eee; } td.text { text-align: left; }\n"
            "figure { display: inline-block; margin: 0.5em; vertical-align: top; }\n"
            "figure img { max-width: 640px; border: 1px solid #ddd; }\n"
            "figure img.preview { width: 480px; image-rendering: pixelated; }\n"
            "#page-check { font-size: 0.7em; color: #888; }\n</style>\n</head>\n<body>\n";
    html << "<h1>Image diff</h1>\n<p>A = <code>" << htmlEscape(a) << "</code><br>B = <code>"
         << htmlEscape(b) << "</code> (the reference)<br>" << diff.width << " &times; "
         << diff.height << " pixels</p>\n";
    html << "<h2>Metrics on the beauty R, G, B</h2>\n<table>\n"
         << "<tr><th>RMSE</th><th>relative RMSE</th><th>PSNR (dB)</th><th>max abs</th><th>mean "
            "abs</th>"
            "<th>relative mean</th><th>99th percentile abs</th><th>ꟻLIP (HDR)</th></tr>\n"
            "<tr><td>"
         << formatNumber(m.rmse) << "</td><td>" << formatNumber(m.relativeRmse) << "</td><td>"
         << formatNumber(m.psnr) << "</td><td>" << formatNumber(m.maxAbs) << "</td><td>"
         << formatNumber(m.meanAbs) << "</td><td>" << formatNumber(m.relativeMean) << "</td><td>"
         << formatNumber(m.p99Abs) << "</td><td class=\"flip\">"
         << (m.flip ? formatNumber(*m.flip) : std::string("&mdash;")) << "</td></tr>\n</table>\n"
         << "<p>relative RMSE = RMSE / RMS of B; relative mean = mean |A &minus; B| / |mean of B|; "
            "PSNR peak = "
            "the largest channel value of B.</p>\n";
    if (m.flip)
        html << "<p>ꟻLIP: mean HDR-ꟻLIP of A against B " << formatNumber(*m.flip)
             << ", weighted median " << formatNumber(m.flipWeightedMedian.value_or(0.0))
             << ", 95th percentile " << formatNumber(m.flipP95.value_or(0.0))
             << ", 99th percentile " << formatNumber(m.flipP99.value_or(0.0))
             << " (the testbed's HDR-ꟻLIP, experiments/compare/Flip.h; parameters: "
             << htmlEscape(diff.flipParameters.dump()) << ").</p>\n";
    else
        html << "<p class=\"flip-unavailable\"><b>ꟻLIP unavailable:</b> "
             << htmlEscape(m.flipUnavailable) << "</p>\n";
    html << "<h2>Images</h2>\n"
         << "<figure><a href=\"a.png\"><img class=\"preview\" src=\"a.png\" "
            "alt=\"A\"></a><figcaption>A (tone-mapped, exposure "
         << formatNumber(options.exposure) << ")</figcaption></figure>\n"
         << "<figure><a href=\"b.png\"><img class=\"preview\" src=\"b.png\" "
            "alt=\"B\"></a><figcaption>B (tone-mapped, exposure "
         << formatNumber(options.exposure) << ")</figcaption></figure>\n"
         << "<figure><a href=\"absdiff.png\"><img class=\"plot\" src=\"absdiff.png\" "
            "alt=\"|A-B|\"></a>"
            "<figcaption>|A &minus; B|, maximum over R, G, B, linear radiance; the full-precision "
            "difference (and the raw ꟻLIP map, layer flip) is in <a "
            "href=\"absdiff.exr\">absdiff.exr</a>"
            "</figcaption></figure>\n";
    if (!diff.flipMap.empty())
        html << "<figure><a href=\"flip.png\"><img class=\"plot\" src=\"flip.png\" "
                "alt=\"HDR-FLIP map\"></a><figcaption>HDR-ꟻLIP of A against B per pixel "
                "(0 = no visible difference, 1 = the largest)</figcaption></figure>\n";
    html << "<h2>Per-channel statistics</h2>\n<p>Every channel present in both files; min, max and "
            "mean "
            "over finite values.</p>\n<table>\n<tr><th rowspan=\"2\">channel</th><th "
            "colspan=\"3\">A</th>"
            "<th colspan=\"3\">B</th><th colspan=\"3\">A &minus; B</th><th colspan=\"2\">|A "
            "&minus; B|</th>"
            "<th rowspan=\"2\">NaN / inf in A, B</th></tr>\n<tr>";
    for (int i = 0; i < 3; ++i)
        html << "<th>min</th><th>max</th><th>mean</th>";
    html << "<th>max</th><th>mean</th></tr>\n";
    for (const ChannelStatistics& c : diff.channels)
        html << "<tr><td class=\"text\">" << htmlEscape(c.name) << "</td>"
             << statsCells(c.minA, c.maxA, c.meanA) << statsCells(c.minB, c.maxB, c.meanB)
             << statsCells(c.minDifference, c.maxDifference, c.meanDifference) << "<td>"
             << formatNumber(c.maxAbsDifference) << "</td><td>" << formatNumber(c.meanAbsDifference)
             << "</td><td>" << c.nanA << " / " << c.infA << ", " << c.nanB << " / " << c.infB
             << "</td></tr>\n";
    html << "</table>\n";
    auto list = [&](const char* what, const std::vector<std::string>& names) {
        if (names.empty())
            return;
        html << "<p>Only in " << what << ":";
        for (const std::string& name : names)
            html << " <code>" << htmlEscape(name) << "</code>";
        html << "</p>\n";
    };
    list("A", diff.onlyInA);
    list("B", diff.onlyInB);
    html << "<pre id=\"page-check\" data-status=\"pending\">PAGE-CHECK: "
            "PENDING</pre>\n</body>\n</html>\n";
    return html.str();
}

} // namespace

namespace {

// The byte counts of the attribute types OpenEXR reads by their content, whatever count the
// header declares (OpenEXR 3.1, ImfStandardAttributes and ImfAttribute.cpp).
std::optional<uint32_t> fixedExrAttributeSize(const std::string& type) {
    static const std::map<std::string, uint32_t> sizes = {{"box2f", 16},
                                                          {"box2i", 16},
                                                          {"chromaticities", 32},
                                                          {"compression", 1},
                                                          {"deepImageState", 1},
                                                          {"double", 8},
                                                          {"envmap", 1},
                                                          {"float", 4},
                                                          {"int", 4},
                                                          {"keycode", 28},
                                                          {"lineOrder", 1},
                                                          {"m33d", 72},
                                                          {"m33f", 36},
                                                          {"m44d", 128},
                                                          {"m44f", 64},
                                                          {"rational", 8},
                                                          {"tiledesc", 9},
                                                          {"timecode", 8},
                                                          {"v2d", 16},
                                                          {"v2f", 8},
                                                          {"v2i", 8},
                                                          {"v3d", 24},
                                                          {"v3f", 12},
                                                          {"v3i", 12}};
    const auto found = sizes.find(type);
    return found == sizes.end() ? std::nullopt : std::optional<uint32_t>(found->second);
}

uint32_t littleEndian32(const char* bytes) {
    const auto* b = reinterpret_cast<const unsigned char*>(bytes);
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
}

// How many bytes OpenEXR consumes reading a value of `type` from `value` (the declared count's
// bytes), or nullopt when it would read past them or allocate more than they hold.
std::optional<uint64_t> exrValueBytesRead(const std::string& type, const std::string& value) {
    if (const auto fixed = fixedExrAttributeSize(type))
        return *fixed;
    if (type == "chlist") { // {name\0, int32 type, uint8 linear, 3 reserved, 2 int32}*, \0
        size_t at = 0;
        for (;;) {
            const size_t end = value.find('\0', at);
            if (end == std::string::npos)
                return std::nullopt;
            if (end == at)
                return end + 1;
            at = end + 1 + 16;
            if (at > value.size())
                return std::nullopt;
        }
    }
    if (type == "preview") { // uint32 width, uint32 height, width x height RGBA8 pixels
        if (value.size() < 8)
            return std::nullopt;
        return 8 + uint64_t(littleEndian32(value.data())) * littleEndian32(value.data() + 4) * 4;
    }
    if (type == "stringvector") { // {int32 length, bytes}* up to the declared count
        for (size_t at = 0; at < value.size();) {
            if (value.size() - at < 4)
                return std::nullopt;
            const uint32_t length = littleEndian32(value.data() + at);
            if (length > value.size() - at - 4)
                return std::nullopt;
            at += 4 + length;
        }
    }
    return value.size(); // string, floatvector and opaque types: read by the declared count
}

} // namespace

// An OpenEXR header is a list of attributes (name, type name, int32 byte count, value) ending in
// an empty name, one such list per part of a multi-part file. OpenEXR allocates an attribute's
// declared count before reading it, so a 4 KB file declaring a 1.7 GB attribute made a 1.7 GB
// allocation (37 s under AddressSanitizer; found by exr_fuzzer). And it reads most types by their
// content, not by the count: a chlist declaring 373 bytes for 67 bytes of channels made it parse
// the rest as the next attribute, which declared 1.5 GB (exr_fuzzer again). So this walk checks
// every count against the bytes the file has left AND against what OpenEXR will read of it, and
// refuses a header where the two disagree: no valid file has one. Files that are not EXR, and
// headers this walk cannot follow (a name over 255 bytes), are left to the reader.
void checkExrAttributeSizes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char magic[8] = {};
    if (!in.read(reinterpret_cast<char*>(magic), 8) || magic[0] != 0x76 || magic[1] != 0x2f ||
        magic[2] != 0x31 || magic[3] != 0x01)
        return;
    std::error_code error;
    const uint64_t fileSize = fs::file_size(path, error);
    if (error)
        return;
    const bool multiPart = (magic[5] & 0x10) != 0; // version flag 0x1000
    auto readName = [&](std::string& name) {
        name.clear();
        for (char c; in.get(c);) {
            if (c == '\0')
                return true;
            if (name.size() >= 255)
                return false;
            name += c;
        }
        return false;
    };
    auto corrupt = [&](const std::string& what) {
        return std::runtime_error("cannot read " + path.string() + ": corrupt EXR header: " + what);
    };
    std::string name, type, value;
    for (;;) { // one header (part)
        if (!readName(name))
            return;
        if (name.empty())
            return; // the end of a single-part header, or the empty header ending the parts
        std::string dataWindow, displayWindow;
        while (!name.empty()) {
            if (!readName(type))
                return;
            char count[4];
            if (!in.read(count, 4))
                return;
            const int32_t size = int32_t(littleEndian32(count));
            const uint64_t left = fileSize - std::min<uint64_t>(fileSize, uint64_t(in.tellg()));
            if (size < 0 || uint64_t(size) > left)
                throw corrupt("attribute '" + name + "' declares " + std::to_string(size) +
                              " bytes, the file has " + std::to_string(left) + " left");
            value.resize(size_t(size));
            if (!in.read(value.data(), size))
                return;
            const std::optional<uint64_t> read = exrValueBytesRead(type, value);
            if (!read || *read != uint64_t(size))
                throw corrupt("attribute '" + name + "' of type " + type + " declares " +
                              std::to_string(size) + " bytes, its value " +
                              (read ? "holds " + std::to_string(*read) : "does not fit them"));
            if (name == "displayWindow" && type == "box2i")
                displayWindow = value;
            // The image size, before OpenEXR sees it: OpenImageIO opening a 5.7 KB file whose
            // data window was 983041 x 8 took 32-39 s under AddressSanitizer (13 s user, 12 s
            // system: a large allocation; exr_fuzzer's slowest input) before readImage's own
            // limit check could refuse it. The Release build refused it after the open as well.
            if (name == "dataWindow" && type == "box2i" && value.size() == 16) {
                dataWindow = value;
                const int64_t width = int64_t(int32_t(littleEndian32(value.data() + 8))) -
                                      int32_t(littleEndian32(value.data())) + 1;
                const int64_t height = int64_t(int32_t(littleEndian32(value.data() + 12))) -
                                       int32_t(littleEndian32(value.data() + 4)) + 1;
                if (width < 1 || height < 1 || width > scenes::limits::kMaxImageSide ||
                    height > scenes::limits::kMaxImageSide ||
                    uint64_t(width) * uint64_t(height) > scenes::limits::kMaxPixels)
                    throw std::runtime_error(
                        "cannot read " + path.string() + ": its data window is " +
                        std::to_string(width) + "x" + std::to_string(height) +
                        " pixels, outside the limits (sides 1.." +
                        std::to_string(scenes::limits::kMaxImageSide) + ", " +
                        std::to_string(scenes::limits::kMaxPixels) + " pixels)");
            }
            if (!readName(name))
                return;
        }
        // A data window other than the display window (overscan, or a crop) is refused: diff
        // compares whole renders, which never have one, and OpenImageIO 2.4 (Debian 12) wrote a
        // 80 x 8 data window's rows into a buffer sized for its 16 x 8 display window, a heap
        // overflow (found by exr_fuzzer in CI's one-minute run).
        if (!dataWindow.empty() && !displayWindow.empty() && dataWindow != displayWindow)
            throw std::runtime_error("cannot read " + path.string() +
                                     ": its data window differs from its display window "
                                     "(overscan or a crop); diff compares whole images");
        if (!multiPart)
            return;
    }
}

ImageDiff diffImageFiles(const fs::path& aPath, const fs::path& bPath) {
    const OIIO::ImageBuf a = readImage(aPath), b = readImage(bPath);
    const OIIO::ImageSpec &specA = a.spec(), &specB = b.spec();
    if (specA.width != specB.width || specA.height != specB.height)
        throw std::runtime_error("image sizes differ: " + aPath.string() + " is " +
                                 std::to_string(specA.width) + "x" + std::to_string(specA.height) +
                                 ", " + bPath.string() + " is " + std::to_string(specB.width) +
                                 "x" + std::to_string(specB.height));
    std::vector<int> beautyA, beautyB;
    for (const char* name : kBeauty) {
        beautyA.push_back(channelIndex(a, name));
        beautyB.push_back(channelIndex(b, name));
        if (beautyA.back() < 0 || beautyB.back() < 0)
            throw std::runtime_error("beauty channel " + std::string(name) + " missing in " +
                                     (beautyA.back() < 0 ? aPath : bPath).string());
    }
    ImageDiff diff;
    diff.width = specA.width;
    diff.height = specA.height;

    // Beauty metrics: the same comparison as the sweep's error against the reference.
    const OIIO::ImageBuf rgbA = selectChannels(a, beautyA), rgbB = selectChannels(b, beautyB);
    lighting::StageResult resultA = beautyAsStageResult(rgbA), resultB = beautyAsStageResult(rgbB);
    DiffMetrics& m = diff.metrics;
    static_cast<ErrorMetrics&>(m) = compareImages(resultA, resultB);
    FlipComparison flip = computeFlip(resultA, resultB);
    m.flip = flip.mean;
    m.flipWeightedMedian = flip.weightedMedian;
    m.flipP95 = flip.p95;
    m.flipP99 = flip.p99;
    m.flipUnavailable = flip.unavailableReason;
    diff.flipMap = std::move(flip.errorMap);
    diff.flipParameters = std::move(flip.parameters);
    OIIO::ImageBuf absRgb;
    if (!OIIO::ImageBufAlgo::absdiff(absRgb, rgbA, rgbB))
        throw std::runtime_error("cannot compute |A - B|: " + absRgb.geterror());
    const auto absStats = pixelStats(absRgb);
    for (int c = 0; c < 3; ++c) {
        m.meanAbs += absStats.avg[size_t(c)] / 3.0;
        diff.beautyA[c] = std::move(resultA.radiance[c]);
        diff.beautyB[c] = std::move(resultB.radiance[c]);
        diff.absDifference[c] = channelPlane(absRgb, c);
    }
    if (m.nonFinitePixels > 0 || m.referenceNonFinitePixels > 0) // as compareImages' figures
        m.meanAbs = std::numeric_limits<double>::infinity();
    OIIO::ImageBuf maxAbs;
    if (!OIIO::ImageBufAlgo::maxchan(maxAbs, absRgb))
        throw std::runtime_error("cannot compute max over channels: " + maxAbs.geterror());
    diff.maxAbsDifference = channelPlane(maxAbs, 0);

    // Per-channel statistics over the channels both files have, in A's order.
    std::vector<int> commonA, commonB;
    for (int c = 0; c < specA.nchannels; ++c) {
        const std::string& name = specA.channelnames[size_t(c)];
        const int inB = channelIndex(b, name);
        if (inB < 0) {
            diff.onlyInA.push_back(name);
            continue;
        }
        commonA.push_back(c);
        commonB.push_back(inB);
    }
    for (int c = 0; c < specB.nchannels; ++c)
        if (channelIndex(a, specB.channelnames[size_t(c)]) < 0)
            diff.onlyInB.push_back(specB.channelnames[size_t(c)]);
    const OIIO::ImageBuf allA = selectChannels(a, commonA), allB = selectChannels(b, commonB);
    OIIO::ImageBuf difference, absDifference;
    if (!OIIO::ImageBufAlgo::sub(difference, allA, allB) ||
        !OIIO::ImageBufAlgo::absdiff(absDifference, allA, allB))
        throw std::runtime_error("cannot compute A - B: " + difference.geterror() +
                                 absDifference.geterror());
    const auto statsA = pixelStats(allA), statsB = pixelStats(allB),
               statsDifference = pixelStats(difference), statsAbs = pixelStats(absDifference);
    for (size_t i = 0; i < commonA.size(); ++i) {
        ChannelStatistics s;
        s.name = specA.channelnames[size_t(commonA[i])];
        s.minA = statsA.min[i], s.maxA = statsA.max[i], s.meanA = statsA.avg[i];
        s.nanA = long(statsA.nancount[i]), s.infA = long(statsA.infcount[i]);
        s.minB = statsB.min[i], s.maxB = statsB.max[i], s.meanB = statsB.avg[i];
        s.nanB = long(statsB.nancount[i]), s.infB = long(statsB.infcount[i]);
        s.minDifference = statsDifference.min[i], s.maxDifference = statsDifference.max[i];
        s.meanDifference = statsDifference.avg[i];
        s.maxAbsDifference = statsAbs.max[i], s.meanAbsDifference = statsAbs.avg[i];
        diff.channels.push_back(s);
    }
    return diff;
}

json diffJson(const ImageDiff& diff, const fs::path& a, const fs::path& b) {
    const DiffMetrics& m = diff.metrics;
    json channels = json::array();
    for (const ChannelStatistics& c : diff.channels)
        channels.push_back(
            {{"name", c.name},
             {"a",
              {{"min", c.minA},
               {"max", c.maxA},
               {"mean", c.meanA},
               {"nan", c.nanA},
               {"inf", c.infA}}},
             {"b",
              {{"min", c.minB},
               {"max", c.maxB},
               {"mean", c.meanB},
               {"nan", c.nanB},
               {"inf", c.infB}}},
             {"difference",
              {{"min", c.minDifference}, {"max", c.maxDifference}, {"mean", c.meanDifference}}},
             {"abs_difference", {{"max", c.maxAbsDifference}, {"mean", c.meanAbsDifference}}}});
    return {{"a", pathForJson(a)}, // reversible escapes: a file name need not be UTF-8
            {"b", pathForJson(b)},
            {"width", diff.width},
            {"height", diff.height},
            {"metrics",
             {{"rmse", numberOrText(m.rmse)},
              {"relative_rmse", numberOrText(m.relativeRmse)},
              {"psnr", numberOrText(m.psnr)},
              {"max_abs", numberOrText(m.maxAbs)},
              {"mean_abs", numberOrText(m.meanAbs)},
              {"relative_mean", numberOrText(m.relativeMean)},
              {"p99_abs", numberOrText(m.p99Abs)},
              {metric::kNonFinitePixels, m.nonFinitePixels},
              {metric::kReferenceNonFinitePixels, m.referenceNonFinitePixels},
              {"unreliable", nonFiniteNote(m)},
              {metric::kFlip, m.flip ? json(*m.flip) : json()},
              {metric::kFlipWeightedMedian,
               m.flipWeightedMedian ? json(*m.flipWeightedMedian) : json()},
              {metric::kFlipP95, m.flipP95 ? json(*m.flipP95) : json()},
              {metric::kFlipP99, m.flipP99 ? json(*m.flipP99) : json()},
              {metric::kFlipUnavailable, m.flipUnavailable},
              {"flip_parameters", diff.flipParameters}}},
            {"channels", channels},
            {"only_in_a", diff.onlyInA},
            {"only_in_b", diff.onlyInB}};
}

int runDiffCommand(const DiffCommandOptions& options) {
    try {
        if (!(options.exposure > 0.0f) || !std::isfinite(options.exposure))
            throw std::runtime_error("--exposure must be a finite number > 0");
        const ImageDiff diff = diffImageFiles(options.a, options.b);
        ensureWritableDirectory(options.out);
        const int w = diff.width, h = diff.height;
        writePreviewPng(options.out / "a.png", w, h, diff.beautyA[0].data(), diff.beautyA[1].data(),
                        diff.beautyA[2].data(), options.exposure);
        writePreviewPng(options.out / "b.png", w, h, diff.beautyB[0].data(), diff.beautyB[1].data(),
                        diff.beautyB[2].data(), options.exposure);
        // |A - B| per channel, and the raw HDR-ꟻLIP map as the layer "flip" when computed.
        std::vector<ImagePlane> layers = {{"R", diff.absDifference[0].data()},
                                          {"G", diff.absDifference[1].data()},
                                          {"B", diff.absDifference[2].data()}};
        if (!diff.flipMap.empty())
            layers.push_back({"flip", diff.flipMap.data()});
        writeMultiLayerExr(
            options.out / "absdiff.exr", w, h, layers,
            {{"testbed:diff", "|A - B| of " + options.a.string() + " and " + options.b.string()}});
        writeDiffPlot(options, diff, options.out / "absdiff.png");
        const fs::path flipPng = options.out / "flip.png";
        if (!diff.flipMap.empty())
            writeScalarMapPng(flipPng, w, h, diff.flipMap.data(), flipMapStyle());
        else
            fs::remove(flipPng); // an older diff's map must not pass for this one's
        writeTextAtomically(options.out / "diff.json",
                            diffJson(diff, options.a, options.b).dump(2) + "\n");
        writeTextAtomically(options.out / "index.html", diffPage(diff, options));
        const DiffMetrics& m = diff.metrics;
        std::cout << "testbed: diff of " << options.a.string() << " and " << options.b.string()
                  << " (" << w << "x" << h << "): rmse " << formatNumber(m.rmse) << ", psnr "
                  << formatNumber(m.psnr) << " dB, max_abs " << formatNumber(m.maxAbs)
                  << ", relative_mean " << formatNumber(m.relativeMean) << ", p99_abs "
                  << formatNumber(m.p99Abs) << ", HDR-FLIP "
                  << (m.flip ? formatNumber(*m.flip) : "unavailable (" + m.flipUnavailable + ")")
                  << "\n  report: " << (options.out / "index.html").string() << "\n";
        if (const std::string note = nonFiniteNote(m); !note.empty())
            std::cout << "  WARNING: " << note << "\n";
        return 0;
    } catch (const std::exception& e) {
        return reportError(e);
    }
}

} // namespace experiments
