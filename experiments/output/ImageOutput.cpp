// EXR, preview PNG and heatmap PNG writers on OpenImageIO. Arguments are checked, and PNG pixels
// (including the legend text) are drawn into an in-memory ImageBuf, before writeFileAtomically is
// called, so a bad argument or a missing font never creates even a temporary file.
//
// The Turbo colormap below is the polynomial approximation published by Google LLC (2019,
// Apache-2.0): colormap design by Anton Mikhailov, GLSL approximation by Ruofei Du
// (gist mikhailov-work/0d177465a8151eb6ede1768d51d476c7; ai.googleblog.com/2019/08/
// turbo-improved-rainbow-colormap-for.html). It returns display (sRGB-encoded) values.
#include "experiments/output/ImageOutput.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "experiments/output/AtomicFile.h"

namespace experiments {

namespace fs = std::filesystem;

namespace {

// fonts-dejavu-core installs it here on Debian; an explicit path makes OpenImageIO skip its font
// search, whose default face (DroidSans) Debian does not ship.
constexpr const char* kLegendFontPath = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
constexpr int kLegendFontSize = 13; // pixels; DejaVu digits stay legible down to about 11
// EXR ZIP compresses blocks of 16 scanlines; handing over whole blocks avoids partial buffering.
constexpr int kExrRowsPerChunk = 16;
// The largest half value: beyond it the ACES fit is 1 to within 8-bit precision, and clamping
// there keeps x * x finite for +Inf input.
constexpr float kMaxToneMapInput = 65504.0f;

using Rgb = std::array<float, 3>;
constexpr Rgb kCountZeroColour{0.0f, 0.0f, 0.0f};
constexpr Rgb kSaturatedColour{1.0f, 1.0f, 1.0f};
constexpr Rgb kLegendBackground{0.22f, 0.22f, 0.22f};
constexpr Rgb kLegendTextColour{0.95f, 0.95f, 0.95f};

void checkImageSize(const fs::path& path, int width, int height) {
    if (width <= 0 || height <= 0)
        throw std::invalid_argument("cannot write " + path.string() + ": image size " +
                                    std::to_string(width) + "x" + std::to_string(height) +
                                    " is not positive");
}

void checkPointer(const fs::path& path, const void* data, std::string_view what) {
    if (!data)
        throw std::invalid_argument("cannot write " + path.string() + ": " + std::string(what) +
                                    " is null");
}

// A file output for OpenImageIO that remembers the first failed write: OpenImageIO's own file
// output ignores short writes, so a full disk left truncated (or empty) files that were then
// renamed to their final names. Writes are buffered by stdio, so finish() flushes before it
// judges.
class CheckedFileOutput final : public OIIO::Filesystem::IOFile {
public:
    explicit CheckedFileOutput(const fs::path& path)
        : IOFile(path.string(), IOProxy::Write), mOpened(handle() != nullptr),
          mError(mOpened ? 0 : errno) {}

    size_t write(const void* data, size_t size) override {
        return checked(IOFile::write(data, size), size);
    }
    size_t pwrite(const void* data, size_t size, int64_t offset) override {
        return checked(IOFile::pwrite(data, size, offset), size);
    }
    // OpenImageIO may close the proxy itself (ImageOutput::close); the buffered bytes are
    // flushed and judged here, before IOFile closes without looking.
    void close() override {
        if (handle() && mError == 0 && std::fflush(handle()) != 0)
            mError = errno;
        if (handle() && mError == 0 && std::ferror(handle()))
            mError = EIO;
        IOFile::close();
    }

    // Closes if still open; throws std::runtime_error naming finalPath when the file could not
    // be created or any byte could not be written.
    void finish(const fs::path& finalPath) {
        close();
        if (!mOpened || mError != 0)
            throw std::runtime_error(
                "cannot write " + finalPath.string() + ": " +
                std::error_code(mError ? mError : EIO, std::generic_category()).message());
    }

private:
    size_t checked(size_t written, size_t size) {
        if (written != size && mError == 0)
            mError = errno != 0 ? errno : EIO;
        return written;
    }

    bool mOpened;
    int mError;
};

// Creates the named format's ImageOutput writing through file; throws naming path.
std::unique_ptr<OIIO::ImageOutput> checkedImageOutput(const fs::path& path, const char* formatName,
                                                      CheckedFileOutput& file) {
    std::unique_ptr<OIIO::ImageOutput> output = OIIO::ImageOutput::create(formatName);
    if (!output)
        throw std::runtime_error("cannot write " + path.string() + ": " + OIIO::geterror());
    if (!output->supports("ioproxy") || !output->set_ioproxy(&file))
        throw std::runtime_error("cannot write " + path.string() + ": OpenImageIO's " + formatName +
                                 " writer takes no I/O proxy");
    return output;
}

} // namespace

void runImageLibraryOnTheCallingThread() {
    static std::once_flag once;
    std::call_once(once, [] { OIIO::attribute("threads", 1); });
}

bool readFloatImage(const fs::path& path, OIIO::ImageBuf& image) {
    runImageLibraryOnTheCallingThread();
    std::unique_ptr<OIIO::ImageInput> input = OIIO::ImageInput::open(path.string());
    if (!input)
        return false;
    OIIO::ImageSpec spec = input->spec();
    if (spec.deep || spec.width <= 0 || spec.height <= 0 || spec.depth != 1 || spec.nchannels <= 0)
        return false;
    spec.set_format(OIIO::TypeDesc::FLOAT);
    spec.channelformats.clear();
    image.reset(spec);
    return input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.localpixels());
}

void writeImageAtomically(const fs::path& path, const OIIO::ImageBuf& image,
                          OIIO::TypeDesc fileType, const char* formatName) {
    runImageLibraryOnTheCallingThread();
    writeFileAtomically(path, [&](const fs::path& tempPath) {
        auto fail = [&](const std::string& reason) {
            return std::runtime_error("cannot write " + path.string() + ": " + reason);
        };
        CheckedFileOutput file(tempPath);
        std::unique_ptr<OIIO::ImageOutput> output = checkedImageOutput(path, formatName, file);
        OIIO::ImageSpec spec = image.spec();
        spec.set_format(fileType);
        if (!output->open(tempPath.string(), spec))
            throw fail(output->geterror());
        if (!image.write(output.get()))
            throw fail(image.geterror());
        if (!output->close())
            throw fail(output->geterror());
        file.finish(path);
    });
}

namespace {

Rgb turbo(float t) {
    // Coefficients of 1, x, x^2, ..., x^5 per channel.
    constexpr std::array<float, 6> kRed{0.13572138f,   4.61539260f,    -42.66032258f,
                                        132.13108234f, -152.94239396f, 59.28637943f};
    constexpr std::array<float, 6> kGreen{0.09140261f,   2.19418839f, 4.84296658f,
                                          -14.18503333f, 4.27729857f, 2.82956604f};
    constexpr std::array<float, 6> kBlue{0.10667330f,   12.64194608f,  -60.58204836f,
                                         110.36276771f, -89.90310912f, 27.34824973f};
    const float x = std::clamp(t, 0.0f, 1.0f);
    const std::array<float, 6> powers{1.0f, x, x * x, x * x * x, x * x * x * x, x * x * x * x * x};
    Rgb rgb{};
    for (int i = 0; i < 6; ++i) {
        rgb[0] += kRed[i] * powers[i];
        rgb[1] += kGreen[i] * powers[i];
        rgb[2] += kBlue[i] * powers[i];
    }
    // The fit overshoots [0,1] by a few thousandths at the ends.
    for (float& c : rgb)
        c = std::clamp(c, 0.0f, 1.0f);
    return rgb;
}

Rgb heatColour(uint32_t count, uint32_t scaleMax) {
    if (count == 0)
        return kCountZeroColour;
    if (count > scaleMax)
        return kSaturatedColour;
    return turbo(float(count) / float(scaleMax));
}

// Narkowicz 2015, "ACES Filmic Tone Mapping Curve": a rational fit of the ACES RRT+ODT, applied
// per channel, followed by the sRGB OETF (IEC 61966-2-1).
float toneMapToSrgb(float linear) {
    if (std::isnan(linear))
        return 0.0f;
    const float x = std::clamp(linear, 0.0f, kMaxToneMapInput);
    const float mapped =
        std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
    return mapped <= 0.0031308f ? 12.92f * mapped : 1.055f * std::pow(mapped, 1.0f / 2.4f) - 0.055f;
}

// Legend text goes through OpenImageIO's FreeType renderer. Any failure (font file missing,
// FreeType absent from the build) is an error: a heatmap whose scale cannot be read is misleading.
[[noreturn]] void throwFontError(const fs::path& path, const std::string& reason) {
    throw std::runtime_error("cannot write " + path.string() + ": cannot draw the legend with " +
                             kLegendFontPath + " (install Debian package fonts-dejavu-core): " +
                             (reason.empty() ? "the font cannot be loaded" : reason));
}

int textWidth(const fs::path& path, const std::string& text) {
    const OIIO::ROI box = OIIO::ImageBufAlgo::text_size(text, kLegendFontSize, kLegendFontPath);
    if (!box.defined())
        throwFontError(path, OIIO::geterror());
    return box.width();
}

void drawLabel(const fs::path& path, OIIO::ImageBuf& canvas, int centreX, int topY,
               const std::string& text) {
    if (!OIIO::ImageBufAlgo::render_text(
            canvas, centreX, topY, text, kLegendFontSize, kLegendFontPath, kLegendTextColour,
            OIIO::ImageBufAlgo::TextAlignX::Center, OIIO::ImageBufAlgo::TextAlignY::Top))
        throwFontError(path, canvas.geterror());
}

void fillRect(OIIO::ImageBuf& canvas, const Rgb& colour, int x0, int x1, int y0, int y1) {
    OIIO::ImageBufAlgo::fill(canvas, colour, OIIO::ROI(x0, x1, y0, y1, 0, 1, 0, 3));
}

// The smallest of 1, 2, 5, 10, 20, 50, ... that is >= minimum, so tick labels are round numbers.
uint64_t roundTickStep(double minimum) {
    for (double decade = 1.0;; decade *= 10.0)
        for (double mantissa : {1.0, 2.0, 5.0})
            if (mantissa * decade >= minimum)
                return uint64_t(mantissa * decade);
}

// Draws the legend into rows [dataHeight, dataHeight + kHeatmapLegendHeight) of canvas.
//   [margin][ colour bar: one cell per count 0..scaleMax ][gap][white swatch][margin]
//            ticks + labels at cell centres                    ">scaleMax"
void drawHeatmapLegend(const fs::path& path, OIIO::ImageBuf& canvas, int dataHeight,
                       uint32_t scaleMax) {
    constexpr int kMargin = 10;         // pixels from the canvas edges
    constexpr int kBarTop = 8;          // pixels below the data
    constexpr int kBarHeight = 14;      // pixels
    constexpr int kTickLength = 4;      // pixels below the bar
    constexpr int kLabelGap = 8;        // minimum pixels between neighbouring labels
    constexpr int kSwatchHalfWidth = 7; // pixels
    const int canvasWidth = canvas.spec().width;
    const int barY0 = dataHeight + kBarTop, barY1 = barY0 + kBarHeight;
    const int labelTop = barY1 + kTickLength + 2;

    fillRect(canvas, kLegendBackground, 0, canvasWidth, dataHeight,
             dataHeight + kHeatmapLegendHeight);

    const std::string maxLabel = std::to_string(scaleMax);
    const std::string saturatedLabel = ">" + maxLabel;
    const int maxLabelWidth = textWidth(path, maxLabel);
    const int saturatedLabelWidth = textWidth(path, saturatedLabel);

    // Saturation swatch at the right, far enough in for its label to fit.
    const int swatchCentre =
        canvasWidth - kMargin - std::max(saturatedLabelWidth, 2 * kSwatchHalfWidth) / 2;
    fillRect(canvas, kSaturatedColour, swatchCentre - kSwatchHalfWidth,
             swatchCentre + kSwatchHalfWidth, barY0, barY1);
    drawLabel(path, canvas, swatchCentre, labelTop, saturatedLabel);

    // The bar ends where the scaleMax label (centred on the last cell) still clears the swatch
    // label.
    const int barX0 = kMargin;
    const int barX1 = swatchCentre - saturatedLabelWidth / 2 - kLabelGap - maxLabelWidth / 2;
    const int barWidth = barX1 - barX0;
    const double cellWidth = double(barWidth) / (double(scaleMax) + 1.0);
    for (int x = barX0; x < barX1; ++x) {
        const double cell = std::floor((x - barX0 + 0.5) / cellWidth);
        const uint32_t count = uint32_t(std::min(cell, double(scaleMax)));
        fillRect(canvas, heatColour(count, scaleMax), x, x + 1, barY0, barY1);
    }

    auto tickX = [&](uint32_t count) { return barX0 + int((count + 0.5) * cellWidth); };
    auto drawTick = [&](uint32_t count) {
        const int x = tickX(count);
        fillRect(canvas, kLegendTextColour, x, x + 1, barY1, barY1 + kTickLength);
        drawLabel(path, canvas, x, labelTop, std::to_string(count));
    };
    // Every label is at most as wide as maxLabel, so this spacing keeps labels apart.
    const int labelPitch = maxLabelWidth + kLabelGap;
    const int maxLabelCount = std::max(2, barWidth / labelPitch);
    const uint64_t step = roundTickStep(double(scaleMax) / double(maxLabelCount - 1));
    for (uint64_t count = 0; count < scaleMax; count += step)
        if (tickX(scaleMax) - tickX(uint32_t(count)) >= labelPitch)
            drawTick(uint32_t(count));
    drawTick(scaleMax);
}

} // namespace

void writeMultiLayerExr(const fs::path& path, int width, int height,
                        const std::vector<ImagePlane>& planes,
                        const std::vector<std::pair<std::string, std::string>>& metadata) {
    runImageLibraryOnTheCallingThread();
    checkImageSize(path, width, height);
    if (planes.empty())
        throw std::invalid_argument("cannot write " + path.string() + ": no image planes");
    std::set<std::string> channelNames;
    for (const ImagePlane& plane : planes) {
        if (plane.channelName.empty())
            throw std::invalid_argument("cannot write " + path.string() + ": empty channel name");
        checkPointer(path, plane.data, "the data of channel " + plane.channelName);
        if (!channelNames.insert(plane.channelName).second)
            throw std::invalid_argument("cannot write " + path.string() + ": channel " +
                                        plane.channelName + " is given twice");
    }
    std::set<std::string> keys;
    for (const auto& [key, value] : metadata)
        if (key.empty() || !keys.insert(key).second)
            throw std::invalid_argument("cannot write " + path.string() + ": metadata key '" + key +
                                        "' is empty or given twice");

    const int channelCount = int(planes.size());
    OIIO::ImageSpec spec(width, height, channelCount, OIIO::TypeDesc::FLOAT);
    spec.channelnames.clear();
    for (const ImagePlane& plane : planes)
        spec.channelnames.push_back(plane.channelName);
    spec.attribute("compression", "zip");
    for (const auto& [key, value] : metadata)
        spec.attribute(key, value);

    writeFileAtomically(path, [&](const fs::path& tempPath) {
        auto fail = [&](const std::string& reason) {
            return std::runtime_error("cannot write " + path.string() + ": " + reason);
        };
        CheckedFileOutput file(tempPath);
        std::unique_ptr<OIIO::ImageOutput> output = checkedImageOutput(path, "openexr", file);
        if (!output->open(tempPath.string(), spec))
            throw fail(output->geterror());
        std::vector<float> chunk(size_t(width) * kExrRowsPerChunk * channelCount);
        for (int y0 = 0; y0 < height; y0 += kExrRowsPerChunk) {
            const int y1 = std::min(height, y0 + kExrRowsPerChunk);
            for (int y = y0; y < y1; ++y)
                for (int x = 0; x < width; ++x) {
                    const size_t source = size_t(y) * width + x;
                    float* pixel = &chunk[(size_t(y - y0) * width + x) * channelCount];
                    for (int c = 0; c < channelCount; ++c)
                        pixel[c] = planes[c].data[source];
                }
            if (!output->write_scanlines(y0, y1, 0, OIIO::TypeDesc::FLOAT, chunk.data()))
                throw fail(output->geterror());
        }
        if (!output->close())
            throw fail(output->geterror());
        file.finish(path);
    });
}

void writePreviewPng(const fs::path& path, int width, int height, const float* r, const float* g,
                     const float* b, float exposure) {
    runImageLibraryOnTheCallingThread();
    checkImageSize(path, width, height);
    checkPointer(path, r, "the red plane");
    checkPointer(path, g, "the green plane");
    checkPointer(path, b, "the blue plane");
    if (!std::isfinite(exposure) || exposure <= 0.0f)
        throw std::invalid_argument("cannot write " + path.string() + ": exposure " +
                                    std::to_string(exposure) + " is not a finite positive factor");

    OIIO::ImageBuf image(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT));
    float* pixels = static_cast<float*>(image.localpixels());
    const size_t pixelCount = size_t(width) * height;
    for (size_t i = 0; i < pixelCount; ++i) {
        pixels[3 * i + 0] = toneMapToSrgb(r[i] * exposure);
        pixels[3 * i + 1] = toneMapToSrgb(g[i] * exposure);
        pixels[3 * i + 2] = toneMapToSrgb(b[i] * exposure);
    }
    writeImageAtomically(path, image, OIIO::TypeDesc::UINT8, "png");
}

void writeHeatmapPng(const fs::path& path, int width, int height, const uint32_t* counts,
                     uint32_t scaleMax) {
    runImageLibraryOnTheCallingThread();
    checkImageSize(path, width, height);
    checkPointer(path, counts, "the count plane");
    const size_t pixelCount = size_t(width) * height;
    if (scaleMax == 0)
        scaleMax = heatmapAutoScale(counts, pixelCount);

    const int canvasWidth = std::max(width, kHeatmapMinWidth);
    OIIO::ImageBuf canvas(
        OIIO::ImageSpec(canvasWidth, height + kHeatmapLegendHeight, 3, OIIO::TypeDesc::FLOAT));
    fillRect(canvas, kLegendBackground, width, canvasWidth, 0, height);
    float* pixels = static_cast<float*>(canvas.localpixels());
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const Rgb colour = heatColour(counts[size_t(y) * width + x], scaleMax);
            std::copy(colour.begin(), colour.end(), &pixels[(size_t(y) * canvasWidth + x) * 3]);
        }
    drawHeatmapLegend(path, canvas, height, scaleMax);
    writeImageAtomically(path, canvas, OIIO::TypeDesc::UINT8, "png");
}

MapScale parseMapScale(const std::string& text) {
    if (text == "linear")
        return MapScale::Linear;
    if (text == "log")
        return MapScale::Log;
    throw std::invalid_argument("error scale '" + text + "': expected linear or log");
}

const char* mapScaleName(MapScale scale) {
    return scale == MapScale::Log ? "log" : "linear";
}

std::string scaleMaximumProblem(double max) {
    if (max >= 0.0 && std::isfinite(float(max)))
        return "";
    return "must be a number >= 0 that is finite as a 32-bit float (at most 3.4e38; 0 = the "
           "image's largest value)";
}

std::pair<float, float> scalarMapRange(const float* values, size_t n, const ScalarMapStyle& style) {
    float top = style.max;
    if (!(top > 0.0f)) {
        top = 0.0f;
        for (size_t i = 0; i < n; ++i)
            if (std::isfinite(values[i]))
                top = std::max(top, values[i]);
        top = std::max(top, std::numeric_limits<float>::min());
    }
    const float bottom =
        style.scale == MapScale::Log ? float(double(top) / std::pow(10.0, style.logDecades)) : 0.0f;
    return {bottom, top};
}

void writeScalarMapPng(const fs::path& path, int width, int height, const float* values,
                       const ScalarMapStyle& style) {
    runImageLibraryOnTheCallingThread();
    checkImageSize(path, width, height);
    checkPointer(path, values, "the value plane");
    if (style.scale == MapScale::Log && !(style.logDecades > 0.0f && style.logDecades <= 30.0f))
        throw std::invalid_argument("cannot write " + path.string() +
                                    ": log scale needs 0 < decades <= 30");
    if (const std::string problem = scaleMaximumProblem(style.max); !problem.empty())
        throw std::invalid_argument("cannot write " + path.string() + ": the scale maximum " +
                                    problem);
    const size_t pixelCount = size_t(width) * height;
    // Not a structured binding: the lambda below captures both, which clang 14 (the sanitizer
    // and fuzzer builds) refuses for bindings.
    const std::pair<float, float> range = scalarMapRange(values, pixelCount, style);
    const float bottom = range.first, top = range.second;
    const double logBottom = std::log10(double(bottom)), logTop = std::log10(double(top));
    // Position on the colour bar, 0..1, of a value inside (0, top].
    auto position = [&](double v) -> float {
        if (style.scale == MapScale::Linear)
            return float(v / top);
        return v <= bottom ? 0.0f : float((std::log10(v) - logBottom) / (logTop - logBottom));
    };

    const int canvasWidth = std::max(width, kScalarMapMinWidth);
    const int canvasHeight = height + kScalarMapLegendHeight;
    // One channel of bar positions for the data and the colour bar, coloured in one color_map
    // call; the pixels that are not on the scale (zero, saturated, legend) are painted after.
    constexpr float kZero = -1.0f, kSaturated = 2.0f, kBackground = -2.0f;
    OIIO::ImageBuf positions(OIIO::ImageSpec(canvasWidth, canvasHeight, 1, OIIO::TypeDesc::FLOAT));
    float* t = static_cast<float*>(positions.localpixels());
    std::fill(t, t + size_t(canvasWidth) * canvasHeight, kBackground);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float v = values[size_t(y) * width + x];
            t[size_t(y) * canvasWidth + x] = !std::isfinite(v) || v > top ? kSaturated
                                             : v <= 0.0f                  ? kZero
                                                                          : position(v);
        }

    // Legend geometry: [margin][0 swatch][gap][ colour bar ][gap][>top swatch][margin], the
    // title above, ticks and labels below.
    constexpr int kMargin = 10, kTitleTop = 4, kBarTop = 24, kBarHeight = 14, kTickLength = 4;
    constexpr int kLabelGap = 8, kSwatchHalfWidth = 7;
    const int barY0 = height + kBarTop, barY1 = barY0 + kBarHeight;
    const int labelTop = barY1 + kTickLength + 2;
    // Powers of ten on a log scale as 1e-04; the maximum and linear ticks with 3 digits.
    auto label = [&](double v) {
        char text[32];
        const bool powerOfTen = std::fabs(std::log10(v) - std::round(std::log10(v))) < 1e-9;
        if (style.scale == MapScale::Log && powerOfTen)
            std::snprintf(text, sizeof text, "%.0e", v);
        else
            std::snprintf(text, sizeof text, "%.3g", v);
        return std::string(text);
    };
    const std::string topLabel = label(top), saturatedLabel = ">" + label(top);
    const int saturatedLabelWidth = textWidth(path, saturatedLabel);
    const int topLabelWidth = textWidth(path, topLabel);
    const int zeroLabelWidth = textWidth(path, "0");
    const int zeroCentre = kMargin + std::max(zeroLabelWidth, 2 * kSwatchHalfWidth) / 2;
    const int saturatedCentre =
        canvasWidth - kMargin - std::max(saturatedLabelWidth, 2 * kSwatchHalfWidth) / 2;
    const int barX0 = zeroCentre + kSwatchHalfWidth + kLabelGap + topLabelWidth / 2;
    const int barX1 = saturatedCentre - saturatedLabelWidth / 2 - kLabelGap - topLabelWidth / 2;
    const int barWidth = std::max(1, barX1 - barX0);
    for (int y = barY0; y < barY1; ++y) {
        for (int x = barX0; x < barX1; ++x)
            t[size_t(y) * canvasWidth + x] = (float(x - barX0) + 0.5f) / float(barWidth);
        for (int x = zeroCentre - kSwatchHalfWidth; x < zeroCentre + kSwatchHalfWidth; ++x)
            t[size_t(y) * canvasWidth + x] = kZero;
        for (int x = saturatedCentre - kSwatchHalfWidth; x < saturatedCentre + kSwatchHalfWidth;
             ++x)
            t[size_t(y) * canvasWidth + x] = kSaturated;
    }

    OIIO::ImageBuf clamped(positions.spec());
    float* c = static_cast<float*>(clamped.localpixels());
    for (size_t i = 0; i < size_t(canvasWidth) * canvasHeight; ++i)
        c[i] = std::clamp(t[i], 0.0f, 1.0f);
    OIIO::ImageBuf canvas = OIIO::ImageBufAlgo::color_map(clamped, 0, style.colourMap);
    if (canvas.has_error() || canvas.nchannels() != 3)
        throw std::invalid_argument("cannot write " + path.string() + ": colour map '" +
                                    style.colourMap + "' unknown to OpenImageIO (" +
                                    canvas.geterror() + ")");
    float* rgb = static_cast<float*>(canvas.localpixels());
    for (size_t i = 0; i < size_t(canvasWidth) * canvasHeight; ++i) {
        const Rgb* special = t[i] == kZero         ? &kCountZeroColour
                             : t[i] == kSaturated  ? &kSaturatedColour
                             : t[i] == kBackground ? &kLegendBackground
                                                   : nullptr;
        if (special)
            std::copy(special->begin(), special->end(), &rgb[3 * i]);
    }

    drawLabel(path, canvas, zeroCentre, labelTop, "0");
    drawLabel(path, canvas, saturatedCentre, labelTop, saturatedLabel);
    if (!style.title.empty() &&
        !OIIO::ImageBufAlgo::render_text(canvas, kMargin, height + kTitleTop, style.title,
                                         kLegendFontSize, kLegendFontPath, kLegendTextColour,
                                         OIIO::ImageBufAlgo::TextAlignX::Left,
                                         OIIO::ImageBufAlgo::TextAlignY::Top))
        throwFontError(path, canvas.geterror());
    auto tickX = [&](double v) { return barX0 + int(std::lround(position(v) * barWidth)); };
    auto drawTick = [&](double v) {
        const int x = std::min(tickX(v), barX1 - 1);
        fillRect(canvas, kLegendTextColour, x, x + 1, barY1, barY1 + kTickLength);
        drawLabel(path, canvas, x, labelTop, label(v));
    };
    // Labels between 0 and the top may be wider than the top's ("0.02" beside "1"): the pitch
    // takes the widest a 3-digit tick label can be, so labels never overlap.
    const int tickLabelWidth = std::max(
        topLabelWidth, style.scale == MapScale::Linear ? textWidth(path, label(double(top) * 0.123))
                                                       : textWidth(path, "1e-04"));
    const int labelPitch = tickLabelWidth + kLabelGap;
    const int maxLabelCount = std::max(2, barWidth / labelPitch);
    std::vector<double> ticks;
    if (style.scale == MapScale::Linear) {
        // The smallest of 1, 2, 5 x 10^k that keeps the labels apart.
        const double minimumStep = double(top) / double(maxLabelCount - 1);
        double step = std::pow(10.0, std::floor(std::log10(minimumStep)));
        for (double mantissa : {1.0, 2.0, 5.0, 10.0})
            if (mantissa * step >= minimumStep) {
                step *= mantissa;
                break;
            }
        for (double v = step; v < double(top); v += step) // 0 is the black swatch's label
            ticks.push_back(v);
    } else {
        const int decades = int(std::ceil(logTop - logBottom));
        const int every = std::max(1, int(std::ceil(double(decades) / double(maxLabelCount - 1))));
        for (int k = int(std::ceil(logBottom)); k < int(std::floor(logTop)) + 1; k += every)
            ticks.push_back(std::pow(10.0, k));
    }
    for (double v : ticks)
        if (tickX(top) - tickX(v) >= labelPitch && tickX(v) - barX0 >= 0)
            drawTick(v);
    drawTick(top);
    writeImageAtomically(path, canvas, OIIO::TypeDesc::UINT8, "png");
}

uint32_t heatmapAutoScale(const uint32_t* counts, size_t n) {
    if (n == 0)
        return 1;
    if (!counts)
        throw std::invalid_argument("heatmapAutoScale: counts is null");
    return std::max<uint32_t>(1, *std::max_element(counts, counts + n));
}

} // namespace experiments
