#include "lighting/SupersampledReference.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "lighting/PreparedScene.h"
#include "lighting/StageRegistry.h"
#include "lighting/shadows/RayShadows.h"

namespace lighting {

namespace {

// The D3D 16x standard sample pattern (D3D11_STANDARD_MULTISAMPLE_PATTERN), 1/16 pixel units
// from the pixel centre, y down.
constexpr int kD3d16Pattern[16][2] = {{1, 1},  {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5},
                                      {5, 3},  {3, -5},  {-2, 6}, {0, -7}, {-4, -6}, {-6, 4},
                                      {-8, 0}, {7, -4},  {6, 7},  {-7, -8}};

int squareRootOf(int n) {
    int k = int(std::lround(std::sqrt(double(n))));
    return k * k == n ? k : 0;
}

// splitmix64: a fixed, portable sequence (std::uniform_real_distribution is not the same on
// every standard library).
uint64_t splitMix64(uint64_t& state) {
    uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// Uniform in [0, 1), 53 bits.
double unitInterval(uint64_t& state) {
    return double(splitMix64(state) >> 11) * 0x1.0p-53;
}

// Per-pixel mean of `sum` over `count` sub-frames, rounded to nearest.
std::vector<uint32_t> meanCounts(const std::vector<uint64_t>& sum, int count) {
    std::vector<uint32_t> mean(sum.size());
    for (size_t i = 0; i < sum.size(); ++i)
        mean[i] = uint32_t((sum[i] + uint64_t(count) / 2) / uint64_t(count));
    return mean;
}

} // namespace

std::string referenceSppProblem(int samplesPerPixel) {
    if (samplesPerPixel < 1 || samplesPerPixel > kMaxReferenceSpp || !squareRootOf(samplesPerPixel))
        return "must be a square from 1 to " + std::to_string(kMaxReferenceSpp) +
               " (1, 4, 9, 16, 25, ..., 256): 1 is the pixel centre, 16 the D3D 16x pattern, "
               "other squares a stratified grid";
    return "";
}

std::string referenceSamplePattern(int samplesPerPixel) {
    if (samplesPerPixel == 1)
        return "centre";
    if (samplesPerPixel == 16)
        return "d3d16";
    const int k = squareRootOf(samplesPerPixel);
    return "stratified-" + std::to_string(k) + "x" + std::to_string(k);
}

std::vector<glm::dvec2> referenceSampleOffsets(int samplesPerPixel) {
    if (const std::string problem = referenceSppProblem(samplesPerPixel); !problem.empty())
        throw std::invalid_argument("reference samples per pixel " +
                                    std::to_string(samplesPerPixel) + ": " + problem);
    std::vector<glm::dvec2> offsets;
    if (samplesPerPixel == 1) {
        offsets.emplace_back(0.0, 0.0);
    } else if (samplesPerPixel == 16) {
        for (const auto& sample : kD3d16Pattern)
            offsets.emplace_back(sample[0] / 16.0, sample[1] / 16.0);
    } else {
        const int k = squareRootOf(samplesPerPixel);
        uint64_t state = kStratifiedSeed;
        for (int j = 0; j < k; ++j)
            for (int i = 0; i < k; ++i) {
                const double u = unitInterval(state), v = unitInterval(state);
                offsets.emplace_back((i + u) / k - 0.5, (j + v) / k - 0.5);
            }
    }
    return offsets;
}

StageResult renderSupersampledReference(scenes::Scene scene, int width, int height,
                                        int samplesPerPixel,
                                        const std::optional<ShadowSettings>& shadowSettings) {
    const std::vector<glm::dvec2> offsets = referenceSampleOffsets(samplesPerPixel);
    PreparedScene frame(std::move(scene), width, height, true);
    std::unique_ptr<shadows::RayShadows> rays;
    if (shadowSettings) {
        rays = std::make_unique<shadows::RayShadows>(frame.scene, frame.geometry, frame.view,
                                                     *shadowSettings);
        frame.inputs.exactShadows = rays.get();
    }
    const std::unique_ptr<ShadingStage> stage = makeStage("reference");
    if (samplesPerPixel == 1) { // the centre: the unjittered frame, bitwise the stage's image
        StageResult result;
        stage->shade(frame.inputs, result);
        result.parameters["reference_spp"] = "1";
        result.parameters["reference_pattern"] = referenceSamplePattern(1);
        return result;
    }
    const size_t pixels = size_t(width) * size_t(height);
    std::vector<double> sum[3];
    for (std::vector<double>& plane : sum)
        plane.assign(pixels, 0.0);
    std::vector<uint64_t> evaluated(pixels, 0), oracle;
    std::vector<std::pair<std::string, double>> timings;
    StageResult sub;
    for (const glm::dvec2& offset : offsets) {
        frame.setPixelOffset(offset);
        sub = StageResult();
        stage->shade(frame.inputs, sub);
        // Rows in parallel; each pixel sums its sub-frames in sample order.
        tbb::parallel_for(0, height, [&](int y) {
            const size_t begin = size_t(y) * size_t(width), end = begin + size_t(width);
            for (size_t i = begin; i < end; ++i) {
                for (int c = 0; c < 3; ++c)
                    sum[c][i] += double(sub.radiance[c][i]);
                evaluated[i] += sub.lightsEvaluated[i];
            }
        });
        if (!sub.lightsOracle.empty()) {
            oracle.resize(pixels, 0);
            for (size_t i = 0; i < pixels; ++i)
                oracle[i] += sub.lightsOracle[i];
        }
        for (const auto& timing : sub.timingsMs) {
            auto found = std::find_if(timings.begin(), timings.end(),
                                      [&timing](const auto& t) { return t.first == timing.first; });
            if (found == timings.end())
                timings.push_back(timing);
            else
                found->second += timing.second;
        }
    }
    StageResult result;
    result.resize(width, height, false);
    const double count = double(offsets.size());
    tbb::parallel_for(0, height, [&](int y) {
        const size_t begin = size_t(y) * size_t(width), end = begin + size_t(width);
        for (size_t i = begin; i < end; ++i)
            for (int c = 0; c < 3; ++c)
                result.radiance[c][i] = float(sum[c][i] / count);
    });
    result.lightsEvaluated = meanCounts(evaluated, int(offsets.size()));
    if (!oracle.empty())
        result.lightsOracle = meanCounts(oracle, int(offsets.size()));
    result.timingsMs = std::move(timings);
    result.parameters = sub.parameters;
    result.parameters["reference_spp"] = std::to_string(samplesPerPixel);
    result.parameters["reference_pattern"] = referenceSamplePattern(samplesPerPixel);
    return result;
}

} // namespace lighting
