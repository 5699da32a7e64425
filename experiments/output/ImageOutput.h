// Result images of one render, written through OpenImageIO and AtomicFile (a failed write never
// leaves a partial file under the final name):
//   - a multi-layer float32 OpenEXR with the beauty, G-buffer and light-count planes and the run's
//     metadata in the header;
//   - a tone-mapped 8-bit sRGB PNG preview of the beauty;
//   - a false-colour PNG heatmap of per-pixel light counts with a legend strip below the data;
//   - a false-colour PNG of per-pixel non-negative values (error maps), linear or log scale, with
//     a legend strip below the data.
//
// Conventions: every plane is width * height values in row-major order, rows top to bottom (row 0
// is the top of the image, as in OpenImageIO and EXR), no padding between rows. Colour planes are
// linear (scene-referred) radiance.
//
// Errors: a wrong argument (empty or duplicate channel name, null plane, non-positive size) throws
// std::invalid_argument; a failure to write (folder missing or read-only, disk full, codec error,
// legend font missing) throws std::runtime_error naming the final path and the reason.
//
// Thread safety: the functions share no state and may run concurrently for different paths.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <OpenImageIO/imagebuf.h>

namespace experiments {

// Makes OpenImageIO run its algorithms and pixel conversions on the calling thread
// (OIIO::attribute("threads", 1)), once per process; every function of the testbed that hands
// pixels to OpenImageIO calls it first (the writers below, compareImages, diff, the report's
// images, reading a sweep's reference). Their work is measurement and output, outside every timed
// pass, and OpenImageIO's own pool would
// - start a thread per core beside the --threads the user chose;
// - split reductions (compare, computePixelStats) however it likes, where error figures must not
//   depend on the machine;
// - hand work over inside the uninstrumented libOpenImageIO_Util, which ThreadSanitizer reported
//   as races (./run.sh sanitize: the RenderJob, RenderCommand and SweepRunner tests).
// Not set at start-up: setting it creates OpenImageIO's pool (a thread that then ends) in every
// process, `testbed sweep` included, which must have no thread but its start-up ones when it
// forks a job (JobProcess.h). Thread-safe.
void runImageLibraryOnTheCallingThread();

// Writes an in-memory image in the named OpenImageIO format ("png", "openexr"), pixels converted
// to fileType, through writeFileAtomically. Every byte goes through a file proxy that checks the
// write and the final flush (OpenImageIO's own file output ignores short writes), so a full disk
// throws std::runtime_error naming path and leaves no file under that name. Every image file
// the testbed writes goes through this or writeMultiLayerExr.
// Reads every channel of the file's first subimage as float into `image` through one
// ImageInput (header and pixels from the same open file). Returns false when the file cannot be
// opened or read. Never ImageBuf(path): an ImageBuf made from a file name takes its spec from
// OpenImageIO's shared ImageCache, which remembers a path's first spec, so a file rewritten at
// that path (a sweep's re-rendered reference or job) was read into a buffer sized for the old
// image: a heap overflow (exr_fuzzer found it in diff, tests/experiments/compare/diff_test.cpp).
bool readFloatImage(const std::filesystem::path& path, OIIO::ImageBuf& image);

void writeImageAtomically(const std::filesystem::path& path, const OIIO::ImageBuf& image,
                          OIIO::TypeDesc fileType, const char* formatName);

// One float plane of a multi-layer EXR. data is borrowed: it must hold width * height values and
// stay alive during the write call.
struct ImagePlane {
    std::string channelName; // e.g. "R", "N.X", "albedo.R", "lights.evaluated"
    const float* data;
};

// Writes one OpenEXR file with one float32 channel per plane (never half: stored values are
// bit-exact copies of the input), ZIP compression, and every metadata pair as a string attribute
// in the header (e.g. {"testbed:stage", "tiled"}). Dots in channel names make EXR layers
// ("N.X" is channel X of layer N), which viewers and `oiiotool --info -v` show.
//
// Channel order: EXR stores the channel list sorted by name, so the order of planes is not kept
// in the file. OpenImageIO reads channels back as the unlayered ones first in R,G,B,A,Z order,
// then each layer in name order (R,G,B,Z,N.X,N.Y,N.Z,albedo.R,...); look channels up by name.
// Cost: one pass over the planes, interleaving 16 rows at a time (the ZIP block height), so the
// extra memory is 16 rows of pixels, not a copy of the image.
void writeMultiLayerExr(const std::filesystem::path& path, int width, int height,
                        const std::vector<ImagePlane>& planes,
                        const std::vector<std::pair<std::string, std::string>>& metadata);

// Writes an 8-bit sRGB PNG of width x height: each linear channel is multiplied by exposure (a
// linear factor, not stops; must be finite and > 0), tone-mapped with Narkowicz's ACES filmic fit
// and encoded with the sRGB OETF. NaN and negative values show as 0 (black), +Inf as 1 (white),
// so a broken pixel never corrupts its neighbours or the file.
void writePreviewPng(const std::filesystem::path& path, int width, int height, const float* r,
                     const float* g, const float* b, float exposure = 1.0f);

// Layout of the heatmap PNG: the data occupies the top-left width x height pixels unchanged in
// position; a legend strip of kHeatmapLegendHeight rows is appended below it. The PNG is at least
// kHeatmapMinWidth wide so that the legend's labels fit for small images; columns right of the
// data are filled with the legend's grey, which no count maps to.
inline constexpr int kHeatmapLegendHeight = 52; // pixels: margin, colour bar, ticks, labels
inline constexpr int kHeatmapMinWidth = 320;    // pixels: fits ~10 labels of up to 4 digits

// Writes a false-colour heatmap of per-pixel light counts (width * height values) as an 8-bit
// PNG: 0 is black, 1..scaleMax follow the Turbo colormap linearly from dark blue to dark red, and
// counts above scaleMax are white (saturated). The legend shows the colour of every count from 0
// to scaleMax on a bar with labelled ticks (0, round intermediate values, scaleMax) and a white
// swatch labelled ">scaleMax". scaleMax == 0 means heatmapAutoScale() of the image. Use the same
// explicit scaleMax for images that are to be compared side by side.
// Labels are drawn with OpenImageIO's render_text and the DejaVu Sans font from Debian's
// fonts-dejavu-core package; without it this throws std::runtime_error saying so.
void writeHeatmapPng(const std::filesystem::path& path, int width, int height,
                     const uint32_t* counts, uint32_t scaleMax);

// The largest of the n counts, at least 1 (so an all-zero image still has a valid scale).
uint32_t heatmapAutoScale(const uint32_t* counts, size_t n);

// How a false-colour map of non-negative values (an error image) maps values to colours.
enum class MapScale {
    Linear, // 0 .. max
    Log,    // max / 10^decades .. max, one colour step per equal ratio
};
// "linear" or "log"; throws std::invalid_argument naming the valid words otherwise.
MapScale parseMapScale(const std::string& text);
const char* mapScaleName(MapScale scale);

struct ScalarMapStyle {
    MapScale scale = MapScale::Linear;
    float max = 0.0f;                // top of the scale; 0 = the image's largest finite value
    float logDecades = 4.0f;         // log scale: the bottom of the scale is max / 10^logDecades
    std::string colourMap = "turbo"; // an OpenImageIO color_map name ("turbo", "magma", ...)
    std::string title;               // legend title, e.g. "|render - reference|, max of R,G,B"
};

// The range a style gives to the n values: {bottom, top}. top is style.max, or the largest
// finite value (at least the smallest positive float, so an all-zero image has a valid scale);
// bottom is 0 (linear) or top / 10^logDecades (log).
std::pair<float, float> scalarMapRange(const float* values, size_t n, const ScalarMapStyle& style);

// Why `max` cannot be a ScalarMapStyle::max (a scale's top): "" when it is >= 0 and finite as the
// float it is stored in (1e300 is finite as a double, inf as a float), else what is expected.
// writeScalarMapPng refuses such a style; `render --error-max` and a sweep file's error-max are
// checked with it before any work (issue 32, class 4).
std::string scaleMaximumProblem(double max);

inline constexpr int kScalarMapLegendHeight = 70; // pixels: title, colour bar, ticks, labels
inline constexpr int kScalarMapMinWidth = 420;    // pixels: fits the title and ~8 labels

// Writes a false-colour PNG of width x height non-negative values (e.g. the largest channel
// error per pixel) with a legend strip of kScalarMapLegendHeight rows below the data, laid out
// like the heatmap's: exactly 0 is black (the swatch "0" at the left of the bar), values in
// (0, top] follow the colour map (linearly, or by log10 on a log scale, where values below the
// bottom take the bar's first colour), values above top and non-finite values are white (the
// swatch ">top"). The bar's ticks are round numbers (linear) or powers of ten (log). Use the
// same explicit style.max for images that are to be compared side by side. Throws like
// writeHeatmapPng (invalid argument, font missing, write failure), and std::invalid_argument
// for an unknown colour map or a non-positive logDecades.
void writeScalarMapPng(const std::filesystem::path& path, int width, int height,
                       const float* values, const ScalarMapStyle& style);

} // namespace experiments
