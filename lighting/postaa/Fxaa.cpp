#include "lighting/postaa/Fxaa.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <tbb/parallel_for.h>

namespace lighting::postaa {

namespace {

// Reinhard's x / (1 + x), with +inf to 1 and negative or NaN radiance to 0, so that the luma
// plane is finite whatever the stage wrote.
float toneMapped(float value) {
    if (!(value > 0.0f))
        return 0.0f;
    if (std::isinf(value))
        return 1.0f;
    return value / (1.0f + value);
}

std::string text(float value) {
    std::ostringstream stream;
    stream << value;
    return stream.str();
}

// A luma plane read with clamp-to-edge.
struct LumaPlane {
    const float* luma;
    int width;
    int height;

    float bilinear(float x, float y) const {
        return BilinearTap::at(width, height, x, y).apply(luma);
    }
};

// The offset of pixel (x, y) towards its pair, in pixels, and along which axis; FxaaPixelShader's
// quality path with Lottes' variable names where they help following it.
struct FxaaOffset {
    float pixels = 0.0f;     // 0: the pixel is copied
    bool horizontal = false; // the edge runs along x: the pair is above or below
    float sign = 0.0f;       // -1 or +1 along the axis across the edge
};

FxaaOffset fxaaOffset(const LumaPlane& l, int x, int y, const FxaaParameters& p) {
    // The 3x3 neighbourhood, clamped to the border once.
    const size_t xW = size_t(std::max(x - 1, 0)), xM = size_t(x);
    const size_t xE = size_t(std::min(x + 1, l.width - 1));
    const float* rowN = l.luma + size_t(std::max(y - 1, 0)) * size_t(l.width);
    const float* rowM = l.luma + size_t(y) * size_t(l.width);
    const float* rowS = l.luma + size_t(std::min(y + 1, l.height - 1)) * size_t(l.width);
    const float lumaM = rowM[xM];
    float lumaN = rowN[xM];
    float lumaS = rowS[xM];
    const float lumaW = rowM[xW];
    const float lumaE = rowM[xE];
    const float rangeMax = std::max({lumaM, lumaN, lumaS, lumaW, lumaE});
    const float rangeMin = std::min({lumaM, lumaN, lumaS, lumaW, lumaE});
    const float range = rangeMax - rangeMin;
    if (range < std::max(p.edgeThresholdMin, rangeMax * p.edgeThreshold))
        return {};

    const float lumaNW = rowN[xW], lumaNE = rowN[xE];
    const float lumaSW = rowS[xW], lumaSE = rowS[xE];
    // Edge direction from the second differences, the centre row and column weighted twice.
    const float lumaNS = lumaN + lumaS, lumaWE = lumaW + lumaE;
    const float edgeHorz1 = -2.0f * lumaM + lumaNS, edgeVert1 = -2.0f * lumaM + lumaWE;
    const float lumaNESE = lumaNE + lumaSE, lumaNWNE = lumaNW + lumaNE;
    const float edgeHorz2 = -2.0f * lumaE + lumaNESE, edgeVert2 = -2.0f * lumaN + lumaNWNE;
    const float lumaNWSW = lumaNW + lumaSW, lumaSWSE = lumaSW + lumaSE;
    const float edgeHorz3 = -2.0f * lumaW + lumaNWSW, edgeVert3 = -2.0f * lumaS + lumaSWSE;
    const float edgeHorz = std::abs(edgeHorz3) + (std::abs(edgeHorz1) * 2.0f + std::abs(edgeHorz2));
    const float edgeVert = std::abs(edgeVert3) + (std::abs(edgeVert1) * 2.0f + std::abs(edgeVert2));
    const bool horzSpan = edgeHorz >= edgeVert;

    // Sub-pixel term: the 3x3 low-pass (edges weighted 2, corners 1) against the centre.
    const float subpixA = (lumaNS + lumaWE) * 2.0f + (lumaNWSW + lumaNESE);
    const float subpixB = subpixA * (1.0f / 12.0f) - lumaM;
    const float subpixC = std::clamp(std::abs(subpixB) / range, 0.0f, 1.0f);
    const float subpixD = -2.0f * subpixC + 3.0f;
    const float subpixF = subpixD * subpixC * subpixC;
    const float subpixH = subpixF * subpixF * p.subpix;

    // The pair: across the edge, the neighbour with the steeper gradient.
    if (!horzSpan) {
        lumaN = lumaW;
        lumaS = lumaE;
    }
    const float gradientN = lumaN - lumaM, gradientS = lumaS - lumaM;
    const bool pairN = std::abs(gradientN) >= std::abs(gradientS);
    const float gradient = std::max(std::abs(gradientN), std::abs(gradientS));
    const float sign = pairN ? -1.0f : 1.0f;
    const float lumaNN = (pairN ? lumaN : lumaS) + lumaM; // pixel + pair
    const float gradientScaled = gradient * 0.25f;
    const float lumaMM = lumaM - lumaNN * 0.5f; // the pixel against the pair's average
    const bool lumaMLTZero = lumaMM < 0.0f;

    // End-of-edge search from the point half-way to the pair, both ways along the edge; each
    // fetch averages the pixel's row (or column) and the pair's.
    const float bx = horzSpan ? float(x) : float(x) + 0.5f * sign;
    const float by = horzSpan ? float(y) + 0.5f * sign : float(y);
    const float stepX = horzSpan ? 1.0f : 0.0f, stepY = horzSpan ? 0.0f : 1.0f;
    float distanceN = kSearchSteps[0], distanceP = kSearchSteps[0];
    float lumaEndN = l.bilinear(bx - stepX * distanceN, by - stepY * distanceN) - lumaNN * 0.5f;
    float lumaEndP = l.bilinear(bx + stepX * distanceP, by + stepY * distanceP) - lumaNN * 0.5f;
    bool doneN = std::abs(lumaEndN) >= gradientScaled;
    bool doneP = std::abs(lumaEndP) >= gradientScaled;
    for (size_t i = 1; i < std::size(kSearchSteps) && !(doneN && doneP); ++i) {
        if (!doneN) {
            distanceN += kSearchSteps[i];
            lumaEndN = l.bilinear(bx - stepX * distanceN, by - stepY * distanceN) - lumaNN * 0.5f;
            doneN = std::abs(lumaEndN) >= gradientScaled;
        }
        if (!doneP) {
            distanceP += kSearchSteps[i];
            lumaEndP = l.bilinear(bx + stepX * distanceP, by + stepY * distanceP) - lumaNN * 0.5f;
            doneP = std::abs(lumaEndP) >= gradientScaled;
        }
    }
    // The nearer end decides: if its luma is on the other side of the pair's average than the
    // pixel's, the pixel lies on the part of the staircase to be blended, by how close it is to
    // that end (0.5 at the end, 0 at the span's middle).
    const bool goodSpanN = (lumaEndN < 0.0f) != lumaMLTZero;
    const bool goodSpanP = (lumaEndP < 0.0f) != lumaMLTZero;
    const float spanLength = distanceN + distanceP;
    const bool directionN = distanceN < distanceP;
    const float distance = std::min(distanceN, distanceP);
    const bool goodSpan = directionN ? goodSpanN : goodSpanP;
    const float pixelOffset = distance * (-1.0f / spanLength) + 0.5f;
    const float pixelOffsetGood = goodSpan ? pixelOffset : 0.0f;
    return {std::max(pixelOffsetGood, subpixH), horzSpan, sign};
}

} // namespace

std::map<std::string, std::string> FxaaParameters::describe() const {
    std::string steps;
    for (float step : kSearchSteps) {
        if (!steps.empty())
            steps += ',';
        steps += text(step);
    }
    return {{"subpix", text(subpix)},
            {"edge_threshold", text(edgeThreshold)},
            {"edge_threshold_min", text(edgeThresholdMin)},
            {"search_steps", steps},
            {"luma", "sqrt(rec601(x/(1+x)))"}};
}

void fxaaLuma(const RadianceIn& in, std::vector<float>& luma) {
    luma.resize(size_t(in.width) * size_t(in.height));
    tbb::parallel_for(0, in.height, [&](int y) {
        for (int x = 0; x < in.width; ++x) {
            const size_t c = size_t(y) * size_t(in.width) + size_t(x);
            const float linear = 0.299f * toneMapped(in.rgb[0][c]) +
                                 0.587f * toneMapped(in.rgb[1][c]) +
                                 0.114f * toneMapped(in.rgb[2][c]);
            luma[c] = std::sqrt(linear);
        }
    });
}

void fxaa(const FxaaParameters& p, const RadianceIn& in, const RadianceOut& out,
          std::vector<float>& luma) {
    fxaaLuma(in, luma);
    const LumaPlane plane{luma.data(), in.width, in.height};
    tbb::parallel_for(0, in.height, [&](int y) {
        for (int x = 0; x < in.width; ++x) {
            const size_t c = size_t(y) * size_t(in.width) + size_t(x);
            const FxaaOffset offset = fxaaOffset(plane, x, y, p);
            out.edges[c] = std::min(offset.pixels, 1.0f);
            if (offset.pixels <= 0.0f) {
                for (int ch = 0; ch < 3; ++ch)
                    out.rgb[ch][c] = in.rgb[ch][c];
                continue;
            }
            const float move = offset.pixels * offset.sign;
            const BilinearTap tap =
                BilinearTap::at(in.width, in.height, offset.horizontal ? float(x) : float(x) + move,
                                offset.horizontal ? float(y) + move : float(y));
            for (int ch = 0; ch < 3; ++ch)
                out.rgb[ch][c] = tap.apply(in.rgb[ch]);
        }
    });
}

} // namespace lighting::postaa
