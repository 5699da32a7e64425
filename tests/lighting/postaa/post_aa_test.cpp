// Post-process anti-aliasing (lighting/postaa/): edge-blur finds depth steps, normal creases and
// silhouettes and blurs only there; FXAA leaves flat and smooth images alone and brings an aliased
// edge closer to its exact coverage; both are bitwise the same on 1 and 2 threads; names parse.
// Oracles: closed-form edges (which columns of a step are edges), and for the aliasing tests the
// exact area coverage of a half-plane by each pixel (supersampled 64x64, exact to 1/4096).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "gbuffer/GBuffer.h"
#include "gbuffer/GBufferLayout.h"
#include "gbuffer/visibility/CameraView.h"
#include "lighting/postaa/PostAa.h"
#include "scenes/Scene.h"

namespace {

using namespace lighting::postaa;

// An image and its filtered copy, with the views the filters take.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> rgb[3];

    Image(int w, int h, float value = 0.0f) : width(w), height(h) {
        for (std::vector<float>& plane : rgb)
            plane.assign(size_t(w) * size_t(h), value);
    }
    size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
    void set(int x, int y, float value) {
        for (std::vector<float>& plane : rgb)
            plane[index(x, y)] = value;
    }
    RadianceIn in() const { return {width, height, {rgb[0].data(), rgb[1].data(), rgb[2].data()}}; }
};

struct Filtered {
    Image image;
    std::vector<float> edges;
    Filtered(int w, int h) : image(w, h), edges(size_t(w) * size_t(h), -1.0f) {}
    RadianceOut out() {
        return {{image.rgb[0].data(), image.rgb[1].data(), image.rgb[2].data()}, edges.data()};
    }
};

// A frontal plane at `depthMetres` with normal +z everywhere.
SurfacePlanes flatSurface(int w, int h, float depthMetres) {
    SurfacePlanes s;
    s.width = w;
    s.height = h;
    s.inverseDepth.assign(size_t(w) * size_t(h), 1.0f / depthMetres);
    s.normal[0].assign(size_t(w) * size_t(h), 0.0f);
    s.normal[1].assign(size_t(w) * size_t(h), 0.0f);
    s.normal[2].assign(size_t(w) * size_t(h), 1.0f);
    return s;
}

Filtered runEdgeBlur(const SurfacePlanes& surface, const Image& image) {
    Filtered filtered(image.width, image.height);
    edgeBlur(surface, EdgeBlurParameters{}, image.in(), filtered.out());
    return filtered;
}

Filtered runFxaa(const Image& image) {
    Filtered filtered(image.width, image.height);
    std::vector<float> luma;
    fxaa(FxaaParameters{}, image.in(), filtered.out(), luma);
    return filtered;
}

Image noise(int w, int h, uint32_t seed) {
    Image image(w, h);
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> value(0.0f, 4.0f);
    for (std::vector<float>& plane : image.rgb)
        for (float& v : plane)
            v = value(random);
    return image;
}

bool bitwiseEqual(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// The exact fraction of pixel (x, y) (centre at (x, y), spanning +-0.5) where inside(px, py),
// by 64x64 supersampling: the antialiased image a post-process filter should approach.
template <class Inside> float coverage(int x, int y, Inside inside) {
    constexpr int kSamples = 64;
    int count = 0;
    for (int j = 0; j < kSamples; ++j)
        for (int i = 0; i < kSamples; ++i)
            count += inside(float(x) - 0.5f + (float(i) + 0.5f) / kSamples,
                            float(y) - 0.5f + (float(j) + 0.5f) / kSamples);
    return float(count) / float(kSamples * kSamples);
}

double rmse(const Image& image, const Image& reference) {
    double sum = 0.0;
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < image.rgb[c].size(); ++i) {
            const double d = double(image.rgb[c][i]) - double(reference.rgb[c][i]);
            sum += d * d;
        }
    return std::sqrt(sum / double(3 * image.rgb[0].size()));
}

// ---- names ------------------------------------------------------------------------------------

TEST(PostAaNames, ParseEveryNameAndRefuseOthersNamingTheValidOnes) {
    for (PostAa mode : {PostAa::None, PostAa::EdgeBlur, PostAa::Fxaa})
        EXPECT_EQ(parsePostAa(postAaName(mode)), mode);
    EXPECT_EQ(postAaNames(), (std::vector<std::string>{"none", "edge-blur", "fxaa"}));
    for (const char* bad : {"", "FXAA", "smaa", "edge_blur", "fxaa "}) {
        try {
            parsePostAa(bad);
            ADD_FAILURE() << "'" << bad << "' accepted";
        } catch (const std::invalid_argument& error) {
            const std::string message = error.what();
            EXPECT_NE(message.find("'" + std::string(bad) + "'"), std::string::npos) << message;
            EXPECT_NE(message.find("none, edge-blur, fxaa"), std::string::npos) << message;
        }
    }
    try {
        parsePostAa("fxa");
        ADD_FAILURE() << "'fxa' accepted";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("did you mean 'fxaa'?"), std::string::npos);
    }
}

TEST(PostAaNames, EdgeBlurDeclaresDepthAndNormalsFxaaNothing) {
    EXPECT_EQ(requiredChannels(PostAa::EdgeBlur),
              (std::vector<gbuffer::Channel>{gbuffer::Channel::Depth, gbuffer::Channel::Normal}));
    EXPECT_TRUE(requiredChannels(PostAa::Fxaa).empty());
    EXPECT_TRUE(requiredChannels(PostAa::None).empty());
}

// ---- edge-blur --------------------------------------------------------------------------------

TEST(EdgeBlur, FlatSurfaceHasNoEdgesAndLeavesTheImageBitwiseUnchanged) {
    const int w = 40, h = 30;
    const Image image = noise(w, h, 1);
    // A frontal plane, and a tilted one (1/depth affine in the pixel coordinates, as a plane's
    // is): neither has an edge, whatever the image holds.
    SurfacePlanes tilted = flatSurface(w, h, 5.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            tilted.inverseDepth[size_t(y) * w + x] = 0.2f + 0.003f * float(x) - 0.002f * float(y);
    for (const SurfacePlanes& surface : {flatSurface(w, h, 5.0f), tilted}) {
        const Filtered filtered = runEdgeBlur(surface, image);
        for (float edge : filtered.edges)
            ASSERT_EQ(edge, 0.0f);
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(bitwiseEqual(filtered.image.rgb[c], image.rgb[c]));
    }
}

// A vertical step at column `step` (left: columns < step). Edge columns are step - 1 and step.
void expectBlurredAtColumnsOnly(const Filtered& filtered, const Image& image, int step,
                                const std::string& what) {
    SCOPED_TRACE(what);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const size_t i = image.index(x, y);
            if (x == step - 1 || x == step) {
                EXPECT_EQ(filtered.edges[i], 1.0f) << x << "," << y;
                // Blurred across the step: strictly between the two sides' values.
                EXPECT_GT(filtered.image.rgb[0][i], 0.0f) << x << "," << y;
                EXPECT_LT(filtered.image.rgb[0][i], 1.0f) << x << "," << y;
            } else {
                EXPECT_EQ(filtered.edges[i], 0.0f) << x << "," << y;
                EXPECT_EQ(filtered.image.rgb[0][i], image.rgb[0][i]) << x << "," << y;
            }
        }
}

TEST(EdgeBlur, BlursAcrossADepthStepOnly) {
    const int w = 20, h = 12, step = 9;
    SurfacePlanes surface = flatSurface(w, h, 10.0f);
    Image image(w, h, 0.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < step; ++x) {
            surface.inverseDepth[size_t(y) * w + x] = 1.0f / 2.0f; // 2 m in front of 10 m
            image.set(x, y, 1.0f);
        }
    const Filtered filtered = runEdgeBlur(surface, image);
    expectBlurredAtColumnsOnly(filtered, image, step, "depth step 2 m / 10 m");
    // At full weight (s = 0.25): centre 9/16, sides 3/32, corners 1/64; the column left of the
    // step has 3 sides and 2 corners at 1, the column right of it 1 side and 2 corners.
    EXPECT_FLOAT_EQ(filtered.image.rgb[0][image.index(step - 1, 5)], 0.875f);
    EXPECT_FLOAT_EQ(filtered.image.rgb[0][image.index(step, 5)], 0.125f);
}

TEST(EdgeBlur, BlursAcrossANormalCreaseButNotAGentleCurve) {
    const int w = 20, h = 12, step = 9;
    SurfacePlanes surface = flatSurface(w, h, 10.0f);
    Image image(w, h, 0.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < step; ++x) {
            const size_t i = size_t(y) * w + x;
            surface.normal[0][i] = std::sin(1.0f); // 57 degrees from the right half's normal
            surface.normal[2][i] = std::cos(1.0f);
            image.set(x, y, 1.0f);
        }
    expectBlurredAtColumnsOnly(runEdgeBlur(surface, image), image, step, "crease of 57 degrees");

    // A curve turning 2 degrees per pixel: no edge anywhere, the image is untouched.
    SurfacePlanes curve = flatSurface(w, h, 10.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float angle = 0.035f * float(x);
            curve.normal[0][size_t(y) * w + x] = std::sin(angle);
            curve.normal[2][size_t(y) * w + x] = std::cos(angle);
        }
    const Filtered gentle = runEdgeBlur(curve, image);
    for (float edge : gentle.edges)
        ASSERT_EQ(edge, 0.0f);
    EXPECT_TRUE(bitwiseEqual(gentle.image.rgb[0], image.rgb[0]));
}

TEST(EdgeBlur, SilhouetteAgainstBackgroundIsAnEdgeOnBothSidesAndBackgroundStaysBlack) {
    const int w = 24, h = 24;
    SurfacePlanes surface = flatSurface(w, h, 3.0f);
    Image image(w, h, 0.0f);
    auto inside = [](int x, int y) { return x >= 8 && x < 16 && y >= 8 && y < 16; };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (inside(x, y))
                image.set(x, y, 2.0f);
            else
                surface.inverseDepth[size_t(y) * w + x] = 0.0f; // background
        }
    const Filtered filtered = runEdgeBlur(surface, image);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            bool differs = false; // a 4-neighbour on the other side of the silhouette
            for (auto [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
                const int nx = x + dx, ny = y + dy;
                if (nx >= 0 && nx < w && ny >= 0 && ny < h)
                    differs = differs || inside(nx, ny) != inside(x, y);
            }
            const size_t i = image.index(x, y);
            EXPECT_EQ(filtered.edges[i], differs ? 1.0f : 0.0f) << x << "," << y;
            if (differs) {
                // The background side gains some of the square, the square's side loses some.
                EXPECT_GT(filtered.image.rgb[0][i], 0.0f) << x << "," << y;
                EXPECT_LT(filtered.image.rgb[0][i], 2.0f) << x << "," << y;
            } else {
                EXPECT_EQ(filtered.image.rgb[0][i], image.rgb[0][i]) << x << "," << y;
            }
        }
}

// A real G-buffer: background where nothing was drawn, depth through the layout's decoder.
TEST(EdgeBlur, ReadsCoverageAndDepthFromTheGBuffer) {
    scenes::Camera camera;
    camera.verticalFovRadians = 0.9f;
    camera.nearMetres = 0.1f;
    camera.farMetres = 50.0f;
    const int w = 32, h = 24;
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(camera, w, h);
    gbuffer::GBufferLayout layout; // lossless float planes, reversed float depth
    gbuffer::GBuffer gb(layout, view);
    const glm::vec4 clip = view.clipFromView * glm::vec4(0.0f, 0.0f, -4.0f, 1.0f); // 4 m away
    const float depthNdc = clip.z / clip.w;
    const gbuffer::GBuffer::Writer writer = gb.writer();
    std::span<float> depth = gb.depthPlane();
    Image image(w, h, 0.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            if (x < 10) {
                writer.writeBackground(i);
                continue;
            }
            gbuffer::Surface s;
            s.normalView = glm::vec3(0.0f, 0.0f, 1.0f);
            depth[i] = depthNdc;
            writer.write(i, s);
            image.set(x, y, 1.0f);
        }
    SurfacePlanes surface;
    surface.extract(gb);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float inverse = surface.inverseDepth[size_t(y) * w + x];
            if (x < 10)
                EXPECT_EQ(inverse, 0.0f);
            else
                EXPECT_NEAR(inverse, 0.25f, 1e-5f) << x << "," << y;
        }
    std::vector<float> edges;
    PostAaPass pass(PostAa::EdgeBlur);
    std::vector<float> radiance[3] = {image.rgb[0], image.rgb[1], image.rgb[2]};
    pass.apply(gb, radiance, edges);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            EXPECT_EQ(edges[i], x == 9 || x == 10 ? 1.0f : 0.0f) << x << "," << y;
            if (x < 9)
                EXPECT_EQ(radiance[1][i], 0.0f) << x << "," << y;
            else if (x > 10)
                EXPECT_EQ(radiance[1][i], 1.0f) << x << "," << y;
        }
    EXPECT_FLOAT_EQ(radiance[1][5 * w + 9], 0.125f);
    EXPECT_FLOAT_EQ(radiance[1][5 * w + 10], 0.875f);
}

// ---- the aliasing oracle: a hard half-plane edge ----------------------------------------------

// The half-plane y > slope * (x - 20) + 14.3 is bright (4, HDR) over a dim background (0.1):
// `aliased` samples the pixel centres (what a stage renders), `exact` the covered fraction.
struct EdgeScene {
    Image aliased;
    Image exact;
    SurfacePlanes surface; // the bright side is a surface 2 m away, the rest 20 m
};

EdgeScene halfPlane(float slope) {
    const int w = 48, h = 32;
    EdgeScene scene{Image(w, h), Image(w, h), flatSurface(w, h, 20.0f)};
    auto inside = [slope](float px, float py) { return py > slope * (px - 20.0f) + 14.3f; };
    const float bright = 4.0f, dim = 0.1f;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool centre = inside(float(x), float(y));
            scene.aliased.set(x, y, centre ? bright : dim);
            const float covered = coverage(x, y, inside);
            scene.exact.set(x, y, dim + (bright - dim) * covered);
            if (centre)
                scene.surface.inverseDepth[scene.aliased.index(x, y)] = 1.0f / 2.0f;
        }
    return scene;
}

TEST(Fxaa, ReducesTheErrorOfAnAliasedEdgeAgainstItsExactCoverage) {
    for (float slope : {0.12f, 0.3f, 0.6f, 1.0f, 2.5f}) {
        const EdgeScene scene = halfPlane(slope);
        const double before = rmse(scene.aliased, scene.exact);
        const double after = rmse(runFxaa(scene.aliased).image, scene.exact);
        std::cout << "slope " << slope << ": rmse no AA " << before << ", FXAA " << after << "\n";
        EXPECT_LT(after, 0.8 * before) << "slope " << slope;
    }
}

TEST(EdgeBlur, ReducesTheErrorOfAnAliasedSilhouetteAgainstItsExactCoverage) {
    for (float slope : {0.12f, 0.3f, 0.6f, 1.0f, 2.5f}) {
        const EdgeScene scene = halfPlane(slope);
        const double before = rmse(scene.aliased, scene.exact);
        const double after = rmse(runEdgeBlur(scene.surface, scene.aliased).image, scene.exact);
        std::cout << "slope " << slope << ": rmse no AA " << before << ", edge-blur " << after
                  << "\n";
        EXPECT_LT(after, 0.8 * before) << "slope " << slope;
    }
}

// ---- FXAA on images without edges -------------------------------------------------------------

TEST(Fxaa, ConstantImageIsBitwiseUnchanged) {
    for (float value : {0.0f, 0.02f, 1.0f, 250.0f}) {
        const Image image(31, 17, value);
        const Filtered filtered = runFxaa(image);
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(bitwiseEqual(filtered.image.rgb[c], image.rgb[c])) << value;
        for (float edge : filtered.edges)
            ASSERT_EQ(edge, 0.0f);
    }
}

TEST(Fxaa, SmoothGradientsAreUnchanged) {
    const int w = 64, h = 40;
    // A gentle ramp (luma contrast below the thresholds): copied bitwise.
    Image gentle(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            gentle.set(x, y, 0.2f + 0.004f * float(x) + 0.002f * float(y));
    const Filtered filteredGentle = runFxaa(gentle);
    for (int c = 0; c < 3; ++c)
        EXPECT_TRUE(bitwiseEqual(filteredGentle.image.rgb[c], gentle.rgb[c]));
    // Steep ramps along x and along y (luma contrast above the thresholds, so FXAA runs its edge
    // search): a ramp has no staircase, so no end is found and the offset is only the sub-pixel
    // term of the tone-mapped luma's curvature, far below a pixel.
    for (bool alongX : {true, false}) {
        Image steep(w, h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                steep.set(x, y, 0.1f + 0.08f * float(alongX ? x : y));
        const Filtered filtered = runFxaa(steep);
        int searched = 0;
        for (int y = 1; y + 1 < h; ++y)
            for (int x = 1; x + 1 < w; ++x) {
                const size_t i = steep.index(x, y);
                searched += filtered.edges[i] > 0.0f;
                EXPECT_NEAR(filtered.image.rgb[0][i], steep.rgb[0][i], 1e-3f * 0.08f)
                    << x << "," << y << (alongX ? " along x" : " along y");
            }
        // The contrast test let the ramp's pixels through: the search ran and found no end.
        EXPECT_GT(searched, 0) << (alongX ? "along x" : "along y");
    }
}

// ---- determinism and the pass -----------------------------------------------------------------

TEST(PostAa, BitwiseTheSameOnOneAndTwoThreads) {
    const int w = 97, h = 61; // not a multiple of anything
    const Image image = noise(w, h, 3);
    SurfacePlanes surface = flatSurface(w, h, 6.0f);
    std::mt19937 random(5);
    std::uniform_int_distribution<int> pick(0, 5);
    for (size_t i = 0; i < surface.inverseDepth.size(); ++i)
        surface.inverseDepth[i] = pick(random) == 0 ? 0.0f : 1.0f / float(2 + pick(random));
    auto both = [&](int threads) {
        std::vector<Filtered> results;
        tbb::task_arena arena(threads);
        arena.execute([&] {
            results.push_back(runEdgeBlur(surface, image));
            results.push_back(runFxaa(image));
        });
        return results;
    };
    const std::vector<Filtered> one = both(1), two = both(2);
    for (size_t mode = 0; mode < one.size(); ++mode) {
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(bitwiseEqual(one[mode].image.rgb[c], two[mode].image.rgb[c])) << mode;
        EXPECT_TRUE(bitwiseEqual(one[mode].edges, two[mode].edges)) << mode;
        // Not a vacuous comparison: the filter changed something.
        EXPECT_FALSE(bitwiseEqual(one[mode].image.rgb[0], image.rgb[0])) << mode;
    }
}

TEST(PostAa, NoneLeavesTheImageAloneAndRefusesNoSize) {
    scenes::Camera camera;
    const gbuffer::CameraView view = gbuffer::CameraView::fromCamera(camera, 8, 4);
    gbuffer::GBuffer gb(gbuffer::GBufferLayout{}, view);
    const Image image = noise(8, 4, 9);
    std::vector<float> radiance[3] = {image.rgb[0], image.rgb[1], image.rgb[2]};
    std::vector<float> edges = {1.0f};
    PostAaPass(PostAa::None).apply(gb, radiance, edges);
    EXPECT_TRUE(edges.empty());
    EXPECT_TRUE(bitwiseEqual(radiance[0], image.rgb[0]));
    std::vector<float> wrongSize[3] = {{1.0f}, {1.0f}, {1.0f}};
    EXPECT_THROW(PostAaPass(PostAa::Fxaa).apply(gb, wrongSize, edges), std::invalid_argument);
}

} // namespace
