// Flip: computeFlip (Flip.h). The map is computed in row ranges in parallel; per range and
// exposure, each row of both images goes through
//   a horizontal pass: expose, tone map and clamp each pixel, convert to YCxCz, and filter the row
//               with the 1D contrast sensitivity kernels (Y, Cx, Cz twice) and the 1D feature
//               kernels (Gaussian, first and second derivative) of the normalised luminance, into
//               a ring of the rows the next pass needs;
//   a vertical pass: filter the columns of those seven planes, then per pixel: back to linear
//               RGB, clamped, to Hunt-adjusted CIELAB, HyAB, compressed colour error; edge and
//               point magnitudes, feature difference; error = colour^(1 - feature), kept if the
//               largest over the exposures.
// Borders clamp to the edge. Every value is computed by the same float operations in the same
// order whatever the split into ranges and threads, so the map is bitwise independent of them;
// the ring keeps the memory at a few rows per thread instead of whole filtered planes.
#include "experiments/compare/Flip.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "experiments/compare/FlipInternal.h"

namespace experiments::compare {

namespace {

using namespace flip;

// Above this the colour filters' radius passes 1350 pixels: no display is seen that way, and a
// typo (a distance in mm) would otherwise allocate and run for minutes.
constexpr double kMaxPixelsPerDegree = 10000.0;
// Rows per parallel task of the input scan.
constexpr int kRowsPerTask = 16;
// The map is computed in this many row ranges (enough for two threads to balance on a busy
// machine), each at least kMinRowsPerChunk rows: a range also filters R rows above and below it
// horizontally (R = 10 at the default ppd), work that shorter ranges would repeat more often.
constexpr int kChunksPerImage = 8;
constexpr int kMinRowsPerChunk = 32;

void checkImage(const FlipImage& image, const char* role) {
    if (image.width <= 0 || image.height <= 0)
        throw std::invalid_argument(std::string("ꟻLIP: the ") + role + " image is empty (" +
                                    std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + ")");
    if (!image.r || !image.g || !image.b)
        throw std::invalid_argument(std::string("ꟻLIP: the ") + role +
                                    " image has a null colour plane");
}

std::string describe(std::size_t count, const char* what) {
    return std::to_string(count) + (count == 1 ? " pixel " : " pixels ") + what;
}

// What the passes read: the caller's planes, or, when a pixel of either image is not finite,
// copies in which such pixels take the other image's value (black if neither is finite; see
// Flip.h). Negative values and (LDR) values above 1 are clamped as the rows are read.
struct Inputs {
    FlipImage test, reference;
    std::vector<float> copies;                              // only when a pixel is not finite
    std::vector<unsigned char> testFinite, referenceFinite; // empty when every pixel is finite
    std::size_t nonFinite[2] = {}, negative[2] = {}, aboveOne[2] = {}; // test, reference

    bool finite(std::size_t i) const {
        return testFinite.empty() || (testFinite[i] && referenceFinite[i]);
    }
};

bool finitePixel(const FlipImage& image, std::size_t i) {
    return std::isfinite(image.r[i]) && std::isfinite(image.g[i]) && std::isfinite(image.b[i]);
}

void prepareInputs(const FlipImage& test, const FlipImage& reference, bool ldr, Inputs& out) {
    const int width = test.width, height = test.height;
    const std::size_t n = std::size_t(width) * height;
    const std::array<const FlipImage*, 2> images = {&test, &reference};
    // Counted per row, then added (integers: the same totals in any order).
    struct RowCounts {
        std::uint32_t nonFinite[2] = {}, negative[2] = {}, aboveOne[2] = {};
    };
    std::vector<RowCounts> counts(height);
    tbb::parallel_for(tbb::blocked_range<int>(0, height, kRowsPerTask), [&](const auto& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (std::size_t i = std::size_t(y) * width; i < std::size_t(y + 1) * width; ++i)
                for (int k = 0; k < 2; ++k) {
                    const FlipImage& im = *images[k];
                    if (!finitePixel(im, i)) {
                        ++counts[y].nonFinite[k];
                        continue;
                    }
                    counts[y].negative[k] += im.r[i] < 0.0f || im.g[i] < 0.0f || im.b[i] < 0.0f;
                    counts[y].aboveOne[k] +=
                        ldr && (im.r[i] > 1.0f || im.g[i] > 1.0f || im.b[i] > 1.0f);
                }
    });
    for (const RowCounts& row : counts)
        for (int k = 0; k < 2; ++k) {
            out.nonFinite[k] += row.nonFinite[k];
            out.negative[k] += row.negative[k];
            out.aboveOne[k] += row.aboveOne[k];
        }
    out.test = test;
    out.reference = reference;
    if (out.nonFinite[0] == 0 && out.nonFinite[1] == 0)
        return;
    out.copies.resize(6 * n);
    out.testFinite.resize(n);
    out.referenceFinite.resize(n);
    float* planes[6];
    for (int c = 0; c < 6; ++c)
        planes[c] = out.copies.data() + c * n;
    out.test = {width, height, planes[0], planes[1], planes[2]};
    out.reference = {width, height, planes[3], planes[4], planes[5]};
    for (std::size_t i = 0; i < n; ++i) {
        const bool finite[2] = {finitePixel(test, i), finitePixel(reference, i)};
        out.testFinite[i] = finite[0];
        out.referenceFinite[i] = finite[1];
        for (int k = 0; k < 2; ++k) {
            const FlipImage& source = *images[finite[k] ? k : 1 - k];
            const bool any = finite[k] || finite[1 - k];
            planes[3 * k][i] = any ? source.r[i] : 0.0f;
            planes[3 * k + 1][i] = any ? source.g[i] : 0.0f;
            planes[3 * k + 2][i] = any ? source.b[i] : 0.0f;
        }
    }
}

// A group of N filters on S sources, folded about the centre tap: filter i reads source
// kSourceOf[i] and is even (w[-k] = w[k]: the CSF Gaussians, G, G'') or odd (w[-k] = -w[k]: G',
// whose centre tap is 0), so that out = w[0] c + sum over k = 1..R of w[k] (right_k + left_k),
// or of w[k] (right_k - left_k) for an odd filter: one multiply per pair of taps, and one pair
// sum (or difference) per source shared by its filters. Summed from the centre outwards, in the
// same order for every pixel. sources[s][k] is the input for tap k (k = 0..2R): in the
// horizontal pass the padded row shifted by k - R, in the vertical pass the edge-clamped row at
// offset k - R. A block of 8 outputs per filter stays in registers (the fixed-size inner loops
// are what GCC vectorises); one radius for the group.
template <int S, int N, std::array<int, N> kSourceOf, std::array<bool, N> kOdd>
void convolveFolded(const std::array<const float* const*, S>& sources,
                    const std::array<const Kernel1d*, N>& kernels,
                    const std::array<float*, N>& outs, int count) {
    constexpr int kBlock = 8;
    const int radius = kernels[0]->radius;
    const float* weights[N]; // weights[i][k]: tap at offset +k
    for (int i = 0; i < N; ++i)
        weights[i] = kernels[i]->taps.data() + radius;
    auto block = [&](int x, int width, float(&acc)[N][kBlock]) {
        for (int i = 0; i < N; ++i) {
            const float* c = sources[kSourceOf[i]][radius] + x;
            for (int j = 0; j < width; ++j)
                acc[i][j] = kOdd[i] ? 0.0f : weights[i][0] * c[j];
        }
        for (int k = 1; k <= radius; ++k) {
            float sum[S][kBlock], difference[S][kBlock];
            for (int s = 0; s < S; ++s) {
                const float* left = sources[s][radius - k] + x;
                const float* right = sources[s][radius + k] + x;
                for (int j = 0; j < width; ++j) {
                    sum[s][j] = right[j] + left[j];
                    difference[s][j] = right[j] - left[j];
                }
            }
            for (int i = 0; i < N; ++i) {
                const float w = weights[i][k];
                const float* pair = kOdd[i] ? difference[kSourceOf[i]] : sum[kSourceOf[i]];
                for (int j = 0; j < width; ++j)
                    acc[i][j] += w * pair[j];
            }
        }
    };
    int x = 0;
    for (; x + kBlock <= count; x += kBlock) {
        float acc[N][kBlock];
        block(x, kBlock, acc);
        for (int i = 0; i < N; ++i)
            std::memcpy(outs[i] + x, acc[i], sizeof acc[i]);
    }
    for (; x < count; ++x) {
        float acc[N][kBlock];
        block(x, 1, acc);
        for (int i = 0; i < N; ++i)
            outs[i][x] = acc[i][0];
    }
}

// The groups the passes use: two filters on two sources (Y and Cx; Cz1 and Cz2 vertically;
// the x-feature planes), two on one (the blue-yellow pair horizontally), and the Gaussian with its
// derivatives on one (G, G', G'' horizontally; G' and G'' vertically).
constexpr std::array<int, 2> kOwnSources = {0, 1};
constexpr std::array<int, 2> kSharedSource2 = {0, 0};
constexpr std::array<int, 3> kSharedSource3 = {0, 0, 0};
constexpr std::array<bool, 2> kEvenEven = {false, false};
constexpr std::array<bool, 2> kOddEven = {true, false};
constexpr std::array<bool, 3> kEvenOddEven = {false, true, false};

struct Filters {
    CsfKernels csf;
    FeatureKernels features;
    float cmax = 0.0f;

    // The ring of filtered rows must reach this far either side of a row.
    int radius() const { return std::max(csf.achromatic.radius, features.gaussian.radius); }
};

// One row exposed by `scale`, negatives clamped to 0, tone mapped (HDR) or clamped to [0, 1]
// (LDR), converted to YCxCz, plus the feature detectors' input, Y normalised to [0, 1].
// __restrict: the streams do not overlap, which GCC cannot prove for this many pointers and
// would otherwise not vectorise.
template <bool kToneMap>
void convertRow(const float* __restrict r, const float* __restrict g, const float* __restrict b,
                int width, float scale, float* __restrict yy, float* __restrict cx,
                float* __restrict cz, float* __restrict luma) {
    constexpr float kMaxFloat = std::numeric_limits<float>::max();
    for (int x = 0; x < width; ++x) {
        float rr, gg, bb;
        if constexpr (kToneMap) {
            rr = toneMapAces(clampBits(r[x] * scale, 0.0f, kMaxFloat));
            gg = toneMapAces(clampBits(g[x] * scale, 0.0f, kMaxFloat));
            bb = toneMapAces(clampBits(b[x] * scale, 0.0f, kMaxFloat));
        } else {
            rr = clamp01(r[x]);
            gg = clamp01(g[x]);
            bb = clamp01(b[x]);
        }
        float y, chromaX, chromaZ;
        linearRgbToYCxCz(rr, gg, bb, y, chromaX, chromaZ);
        yy[x] = y;
        cx[x] = chromaX;
        cz[x] = chromaZ;
        luma[x] = y * (1.0f / 116.0f) + 16.0f / 116.0f;
    }
}

// The horizontal pass's planes of one filtered row.
enum Plane { kPlaneY, kPlaneCx, kPlaneCz1, kPlaneCz2, kPlaneGauss, kPlaneFirst, kPlaneSecond };
constexpr int kPlaneCount = 7;

// An image's horizontally filtered rows that the vertical pass needs: row y of each plane in
// slot y mod (2 R + 1), so that rows y - R ... y + R are all there while row y is finished.
class RowRing {
public:
    RowRing(int width, int radius)
        : mWidth(width), mSlots(2 * radius + 1), mData(std::size_t(kPlaneCount) * mSlots * width) {}
    float* row(Plane plane, int y) {
        return mData.data() + (std::size_t(plane) * mSlots + y % mSlots) * mWidth;
    }

private:
    int mWidth, mSlots;
    std::vector<float> mData;
};

// One image's vertically filtered row: the filtered YCxCz and the four feature responses.
struct FilteredRow {
    std::vector<float> y, cx, cz, czSecond, dx, ddx, dy, ddy;
    explicit FilteredRow(int width)
        : y(width), cx(width), cz(width), czSecond(width), dx(width), ddx(width), dy(width),
          ddy(width) {}
};

// A task's buffers, reused for all its rows and exposures.
struct Scratch {
    RowRing rings[2];                  // test, reference
    std::vector<float> padded;         // 4 converted channels, edge-padded
    std::vector<const float*> taps[4]; // tap pointers per channel or plane group
    FilteredRow filtered[2];
    std::vector<float> colour, exponent;

    Scratch(int width, int radius)
        : rings{RowRing(width, radius), RowRing(width, radius)},
          padded(4 * std::size_t(width + 2 * radius)), filtered{FilteredRow(width),
                                                                FilteredRow(width)},
          colour(width), exponent(width) {
        for (auto& t : taps)
            t.resize(2 * radius + 1);
    }
};

// Horizontal pass of row y of one image into its ring.
void horizontalRow(const FlipImage& image, int y, float scale, bool toneMap, const Filters& filters,
                   Scratch& scratch, RowRing& ring) {
    const int width = image.width, pad = filters.radius(), stride = width + 2 * pad;
    float* channels[4];
    for (int c = 0; c < 4; ++c)
        channels[c] = scratch.padded.data() + std::size_t(c) * stride + pad;
    const std::size_t row = std::size_t(y) * width;
    if (toneMap)
        convertRow<true>(image.r + row, image.g + row, image.b + row, width, scale, channels[0],
                         channels[1], channels[2], channels[3]);
    else
        convertRow<false>(image.r + row, image.g + row, image.b + row, width, scale, channels[0],
                          channels[1], channels[2], channels[3]);
    // Clamp to the edge: the pad either side repeats the edge pixel.
    for (float* channel : channels) {
        std::fill(channel - pad, channel, channel[0]);
        std::fill(channel + width, channel + width + pad, channel[width - 1]);
    }
    auto shifted = [&](int c, int radius) {
        std::vector<const float*>& pointers = scratch.taps[c];
        for (int k = 0; k <= 2 * radius; ++k)
            pointers[k] = channels[c] - radius + k;
        return static_cast<const float* const*>(pointers.data());
    };
    const CsfKernels& csf = filters.csf;
    const FeatureKernels& f = filters.features;
    const int rc = csf.achromatic.radius, rf = f.gaussian.radius;
    convolveFolded<2, 2, kOwnSources, kEvenEven>(
        {shifted(0, rc), shifted(1, rc)}, {&csf.achromatic, &csf.redGreen},
        {ring.row(kPlaneY, y), ring.row(kPlaneCx, y)}, width);
    convolveFolded<1, 2, kSharedSource2, kEvenEven>(
        {shifted(2, rc)}, {&csf.blueYellow1, &csf.blueYellow2},
        {ring.row(kPlaneCz1, y), ring.row(kPlaneCz2, y)}, width);
    convolveFolded<1, 3, kSharedSource3, kEvenOddEven>(
        {shifted(3, rf)}, {&f.gaussian, &f.firstDerivative, &f.secondDerivative},
        {ring.row(kPlaneGauss, y), ring.row(kPlaneFirst, y), ring.row(kPlaneSecond, y)}, width);
}

// Vertical pass of row y of one image from its ring.
void verticalRow(RowRing& ring, int y, int height, const Filters& filters, Scratch& scratch,
                 FilteredRow& out) {
    const int width = int(out.y.size());
    auto rows = [&](int group, Plane plane, int radius) {
        std::vector<const float*>& pointers = scratch.taps[group];
        for (int k = 0; k <= 2 * radius; ++k)
            pointers[k] = ring.row(plane, std::clamp(y - radius + k, 0, height - 1));
        return static_cast<const float* const*>(pointers.data());
    };
    const CsfKernels& csf = filters.csf;
    const FeatureKernels& f = filters.features;
    const int rc = csf.achromatic.radius, rf = f.gaussian.radius;
    convolveFolded<2, 2, kOwnSources, kEvenEven>({rows(0, kPlaneY, rc), rows(1, kPlaneCx, rc)},
                                                 {&csf.achromatic, &csf.redGreen},
                                                 {out.y.data(), out.cx.data()}, width);
    convolveFolded<2, 2, kOwnSources, kEvenEven>({rows(0, kPlaneCz1, rc), rows(1, kPlaneCz2, rc)},
                                                 {&csf.blueYellow1, &csf.blueYellow2},
                                                 {out.cz.data(), out.czSecond.data()}, width);
    for (int x = 0; x < width; ++x)
        out.cz[x] += out.czSecond[x];
    // Edges in x are G'(x) G(y): the x-derivative plane filtered by the Gaussian; in y, the
    // Gaussian plane filtered by the derivative. Points likewise with the second derivative.
    convolveFolded<2, 2, kOwnSources, kEvenEven>(
        {rows(0, kPlaneFirst, rf), rows(1, kPlaneSecond, rf)}, {&f.gaussian, &f.gaussian},
        {out.dx.data(), out.ddx.data()}, width);
    convolveFolded<1, 2, kSharedSource2, kOddEven>({rows(2, kPlaneGauss, rf)},
                                                   {&f.firstDerivative, &f.secondDerivative},
                                                   {out.dy.data(), out.ddy.data()}, width);
}

inline void filteredToHuntLab(float yy, float cx, float cz, float& l, float& a, float& b) {
    float r, g, bl;
    yCxCzToLinearRgb(yy, cx, cz, r, g, bl);
    linearRgbToHuntLab(clamp01(r), clamp01(g), clamp01(bl), l, a, b);
}

// The per-pixel end of LDR-ꟻLIP for one row: colour error, feature difference, their
// combination; written into `map` (first exposure) or kept where larger. Straight-line loops
// over arrays (selects, no branches) so that GCC vectorises them.
void errorRow(const FilteredRow& reference, const FilteredRow& test, float cmax, bool first,
              Scratch& scratch, float* map) {
    const int width = int(reference.y.size());
    // __restrict views of the rows (distinct vectors), so that GCC vectorises without checks.
    struct View {
        const float* __restrict y;
        const float* __restrict cx;
        const float* __restrict cz;
        const float* __restrict dx;
        const float* __restrict ddx;
        const float* __restrict dy;
        const float* __restrict ddy;
    };
    auto view = [](const FilteredRow& f) {
        return View{f.y.data(),   f.cx.data(), f.cz.data(), f.dx.data(),
                    f.ddx.data(), f.dy.data(), f.ddy.data()};
    };
    const View re = view(reference), te = view(test);
    float* __restrict colour = scratch.colour.data();
    for (int x = 0; x < width; ++x) {
        float l0, a0, b0, l1, a1, b1;
        filteredToHuntLab(re.y[x], re.cx[x], re.cz[x], l0, a0, b0);
        filteredToHuntLab(te.y[x], te.cx[x], te.cz[x], l1, a1, b1);
        const float distance = hyab(l0, a0, b0, l1, a1, b1);
        colour[x] = redistributeColourError(powNonNegative(distance, kColourExponent), cmax);
    }
    float* __restrict exponent = scratch.exponent.data();
    constexpr float kInverseSqrt2 = 0.707106781186547524f;
    for (int x = 0; x < width; ++x) {
        const float edgeDifference =
            std::fabs(std::sqrt(re.dx[x] * re.dx[x] + re.dy[x] * re.dy[x]) -
                      std::sqrt(te.dx[x] * te.dx[x] + te.dy[x] * te.dy[x]));
        const float pointDifference =
            std::fabs(std::sqrt(re.ddx[x] * re.ddx[x] + re.ddy[x] * re.ddy[x]) -
                      std::sqrt(te.ddx[x] * te.ddx[x] + te.ddy[x] * te.ddy[x]));
        // qf = 0.5: the square root. Rounding can put the difference a hair above sqrt(2); the
        // exponent 1 - feature is kept at or above 0 so that the error stays in [0, 1].
        const float feature = std::sqrt(kInverseSqrt2 * std::max(edgeDifference, pointDifference));
        exponent[x] = std::max(1.0f - feature, 0.0f);
    }
    if (first) {
        for (int x = 0; x < width; ++x)
            map[x] = powNonNegative(colour[x], exponent[x]);
    } else {
        for (int x = 0; x < width; ++x) {
            const float error = powNonNegative(colour[x], exponent[x]);
            map[x] = select(error > map[x], error, map[x]);
        }
    }
}

// Rows [begin, end) of the map, every exposure (`scales`; empty: LDR). Each exposure runs the
// horizontal pass once per needed row (R rows either side of the range too), the vertical pass
// and the error per row; a task's rows are its own, so the maximum needs no synchronisation.
void computeRows(const Inputs& inputs, const Filters& filters, const std::vector<float>& scales,
                 int begin, int end, Scratch& scratch, float* map) {
    const int width = inputs.test.width, height = inputs.test.height, radius = filters.radius();
    const bool toneMap = !scales.empty();
    const int exposures = toneMap ? int(scales.size()) : 1;
    const FlipImage* images[2] = {&inputs.test, &inputs.reference};
    for (int e = 0; e < exposures; ++e) {
        const float scale = toneMap ? scales[e] : 1.0f;
        int next = std::max(0, begin - radius); // the next row for the horizontal pass
        for (int y = begin; y < end; ++y) {
            for (const int last = std::min(height - 1, y + radius); next <= last; ++next)
                for (int k = 0; k < 2; ++k)
                    horizontalRow(*images[k], next, scale, toneMap, filters, scratch,
                                  scratch.rings[k]);
            for (int k = 0; k < 2; ++k)
                verticalRow(scratch.rings[k], y, height, filters, scratch, scratch.filtered[k]);
            errorRow(scratch.filtered[1], scratch.filtered[0], filters.cmax, e == 0, scratch,
                     map + std::size_t(y) * width);
        }
    }
}

// The whole map: row ranges in parallel. Each range recomputes R rows of horizontal pass above
// and below it, so ranges are long (kChunksPerImage of them, at least kMinRowsPerChunk rows);
// the split changes no value (every row is computed by the same operations in any range).
void computeMap(const Inputs& inputs, const Filters& filters, const std::vector<float>& scales,
                float* map) {
    const int height = inputs.test.height;
    const int rowsPerChunk =
        std::max(kMinRowsPerChunk, (height + kChunksPerImage - 1) / kChunksPerImage);
    const int chunks = (height + rowsPerChunk - 1) / rowsPerChunk;
    // One scratch per thread, not per range: every value a range reads from it, it wrote first.
    tbb::enumerable_thread_specific<Scratch> scratches(
        [&] { return Scratch(inputs.test.width, filters.radius()); });
    tbb::parallel_for(0, chunks, [&](int chunk) {
        Scratch& scratch = scratches.local();
        const int begin = chunk * rowsPerChunk;
        computeRows(inputs, filters, scales, begin, std::min(height, begin + rowsPerChunk), scratch,
                    map);
    });
}

} // namespace

FlipResult computeFlip(const FlipImage& test, const FlipImage& reference,
                       const FlipOptions& options) {
    checkImage(test, "test");
    checkImage(reference, "reference");
    if (test.width != reference.width || test.height != reference.height)
        throw std::invalid_argument("ꟻLIP: the test image is " + std::to_string(test.width) + "x" +
                                    std::to_string(test.height) + " but the reference is " +
                                    std::to_string(reference.width) + "x" +
                                    std::to_string(reference.height));
    if (!std::isfinite(options.pixelsPerDegree) || options.pixelsPerDegree <= 0.0 ||
        options.pixelsPerDegree > kMaxPixelsPerDegree)
        throw std::invalid_argument("ꟻLIP: pixels per degree must be in (0, 10000], not " +
                                    std::to_string(options.pixelsPerDegree));
    const int width = test.width, height = test.height;
    const std::size_t n = std::size_t(width) * height;
    const bool hdr = options.mode == FlipMode::Hdr;

    FlipResult result;
    result.pixelsPerDegree = options.pixelsPerDegree;
    Inputs inputs;
    prepareInputs(test, reference, !hdr, inputs);
    result.nonFiniteTest = inputs.nonFinite[0];
    result.nonFiniteReference = inputs.nonFinite[1];
    if (inputs.nonFinite[0] || inputs.nonFinite[1])
        result.warnings.push_back(
            describe(inputs.nonFinite[0], "of the test image and ") +
            describe(inputs.nonFinite[1], "of the reference") +
            " have NaN or infinite values: their error is 1, and their neighbours see the other "
            "image's pixel there (black if neither is finite)");
    const char* roles[2] = {"test", "reference"};
    for (int k = 0; k < 2; ++k) {
        if (inputs.negative[k])
            result.warnings.push_back(describe(inputs.negative[k], "of the ") + roles[k] +
                                      " image have negative values, clamped to 0");
        if (inputs.aboveOne[k])
            result.warnings.push_back(describe(inputs.aboveOne[k], "of the ") + roles[k] +
                                      " image have values above 1, clamped to 1 (LDR mode; use "
                                      "HDR mode for radiance)");
    }

    const float ppd = static_cast<float>(options.pixelsPerDegree);
    const Filters filters{makeCsfKernels(ppd), makeFeatureKernels(ppd), maxColourDistance()};
    std::vector<float> scales; // 2^exposure per exposure; empty for LDR
    if (hdr) {
        auto flags = [](const std::vector<unsigned char>& finite) {
            return finite.empty() ? nullptr : finite.data();
        };
        const LuminanceSource test{inputs.test.r, inputs.test.g, inputs.test.b, n,
                                   flags(inputs.testFinite)};
        const LuminanceSource reference{inputs.reference.r, inputs.reference.g, inputs.reference.b,
                                        n, flags(inputs.referenceFinite)};
        const ExposureBracket bracket =
            exposureBracket(reference, test, options.startExposure, options.stopExposure,
                            options.exposureCount, result.warnings);
        result.startExposure = bracket.start;
        result.stopExposure = bracket.stop;
        result.exposureCount = bracket.count;
        const float step =
            bracket.count > 1 ? (bracket.stop - bracket.start) / float(bracket.count - 1) : 0.0f;
        // Equal exposures (start == stop) give equal maps: computed once.
        const int distinct = step == 0.0f ? 1 : bracket.count;
        for (int i = 0; i < distinct; ++i)
            scales.push_back(std::exp2(bracket.start + float(i) * step));
    } else if (options.startExposure || options.stopExposure || options.exposureCount) {
        result.warnings.push_back("exposure options apply to HDR mode only: ignored");
    }
    result.errorMap.resize(n);
    computeMap(inputs, filters, scales, result.errorMap.data());
    if (!inputs.testFinite.empty())
        for (std::size_t i = 0; i < n; ++i)
            if (!inputs.finite(i))
                result.errorMap[i] = 1.0f;
    const PooledValues pooled = poolValues(result.errorMap, width);
    result.mean = pooled.mean;
    result.weightedMedian = pooled.weightedMedian;
    result.p95 = pooled.p95;
    result.p99 = pooled.p99;
    result.max = pooled.max;
    return result;
}

} // namespace experiments::compare
