// `clustered`: implicit clustered deferred shading (Olsson, Billeter and Assarsson 2012; the CPU
// variant of Örtegren). The frustum is cut into a fixed grid of screen tiles x depth slices
// (lighting/culling/ClusterGrid.h); each frame the lights' conservative spheres are assigned to
// the clusters they may touch, then every covered pixel finds its cluster from its tile and view
// depth and shades with that cluster's ascending light list (same image as `brute`), through
// accumulateLights (LightAccumulation.h) by 4x4 packets whose lanes are grouped by cluster
// (ClusterListSource below).
//
// Options (defaults first):
//   grid=24x12x32        tile columns x tile rows x depth slices (each 1..1024, <= 2^20 clusters);
//                        or `adaptive`: the cluster size chosen per frame from the lights'
//                        projected sizes, each tile storing only the slices its samples span
//                        (culling/AdaptiveClusterGrid.h; options cells, max_clusters below)
//   slices=exp|uniform   geometric (self-similar clusters) or linear slice boundaries between the
//                        nearest and farthest view depth found in the G-buffer (a tighter range
//                        than the camera's near/far planes, so no slice is wasted on empty space)
//   assign=walk|binary|bvh  candidate ranges by walking the sorted planes or by binary search;
//                        bvh: each cluster's box queries a light BVH (culling/LightBvh.h), the
//                        lights found meet the same range and cluster tests (same lists)
//   test=aabb|frustum    cluster test: sphere vs AABB, or AABB and the four side planes
//   (slices, assign and test apply to a fixed grid; one given with grid=adaptive and a value
//   other than its default is an error)
//   cells=2              grid=adaptive: clusters across a typical light's diameter, per axis
//   max_clusters=1048576 grid=adaptive: stored clusters at most; the grid coarsens to fit
//                        (cells or max_clusters off their defaults with a fixed grid: an error)
// Passes: "assign" (light spheres, depth range, cluster bounds, light lists), "shading".
// Conventions: view space right-handed, -Z forward; a pixel's slice comes from the depth of its
// decoded position by the same comparisons that define the slices, so it always lies in its
// cluster (up to rounding, which the widened AABBs and spheres cover).
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "lighting/StageRegistry.h"
#include "lighting/culling/AdaptiveClusterGrid.h"
#include "lighting/culling/ClusterGrid.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PackedFragments.h"
#include "lighting/passes/PassNames.h"

#include "lighting/passes/BlendedPass.h"

namespace lighting {

namespace {

// A packet's lanes grouped by cluster (tile from the pixel, slice from the view depth of the
// decoded position, bitwise GBuffer::decode's), and shaded with their clusters' ascending lists:
// every lane walks exactly its own cluster's list, so the image and lights.evaluated are those of
// a per-pixel loop (and `brute`'s image, same ISA).
// - Most packets lie in one cluster: the tile of the first and last column and row, and the slice
//   of the nearest and farthest lane, agree (tiles and slices are monotonic in x, y and depth), so
//   two slice searches replace sixteen.
// - Otherwise each lane's slice lies between those two, and is the nearest lane's slice plus the
//   boundaries in between that its depth reaches (sliceOfDepth's own comparisons; usually one);
//   tiles come per column and row.
// - A packet across clusters gets the union of their lists with per-light lane masks
//   (PacketLightLists::addByKeyMerged): a light in several of them costs one packet-wide
//   evaluation, not one per cluster.
// Grid: ClusterGrid or AdaptiveClusterGrid (the same queries).
template <class Grid> class ClusterListSource final : public PacketListSource {
public:
    explicit ClusterListSource(const Grid& grid) : mGrid(grid) {}
    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        float nearest = INFINITY, farthest = -INFINITY;
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const float depth = -packet.positionView[2][__builtin_ctz(lanes)];
            nearest = std::min(nearest, depth);
            farthest = std::max(farthest, depth);
        }
        const int nearSlice = mGrid.sliceOfDepth(nearest);
        const int farSlice = mGrid.sliceOfDepth(farthest);
        const int firstTileX = mGrid.tileXOfPixel(packet.x0);
        const int firstTileY = mGrid.tileYOfPixel(packet.y0);
        const int lastTileX = mGrid.tileXOfPixel(packet.x0 + kernel::kPacketWidth - 1);
        const int lastTileY = mGrid.tileYOfPixel(packet.y0 + kernel::kPacketHeight - 1);
        if (firstTileX == lastTileX && firstTileY == lastTileY && nearSlice == farSlice) {
            lists.add(packet.laneMask,
                      mGrid.lightsOf(mGrid.clusterIndex(firstTileX, firstTileY, nearSlice)));
            return;
        }
        int tileX[kernel::kPacketWidth], tileY[kernel::kPacketHeight];
        for (int i = 0; i < kernel::kPacketWidth; ++i)
            tileX[i] = mGrid.tileXOfPixel(packet.x0 + i);
        for (int i = 0; i < kernel::kPacketHeight; ++i)
            tileY[i] = mGrid.tileYOfPixel(packet.y0 + i);
        size_t cluster[kernel::kPacketLanes];
        for (uint32_t lanes = packet.laneMask; lanes != 0; lanes &= lanes - 1) {
            const int lane = __builtin_ctz(lanes);
            const float depth = -packet.positionView[2][lane];
            int slice = nearSlice;
            for (int k = nearSlice + 1; k <= farSlice; ++k)
                slice += mGrid.sliceDepth(k) <= depth ? 1 : 0;
            cluster[lane] =
                mGrid.clusterIndex(tileX[kernel::laneX(lane)], tileY[kernel::laneY(lane)], slice);
        }
        lists.addByKeyMerged(
            packet, [&](int lane) { return cluster[lane]; },
            [&](size_t key) { return mGrid.lightsOf(key); });
    }

private:
    const Grid& mGrid;
};

// The stage's options: a fixed grid, or the density-adaptive grid (grid=adaptive).
struct ClusteredOptions {
    bool adaptive = false;
    ClusterGridOptions fixed;
    AdaptiveClusterOptions adaptiveGrid;
    std::string cellsText; // the canonical text of the cells option, as recorded
};

// A packed fragment's list: its cluster's (PackedFragments.h), found as ClusterListSource finds a
// lane's (tile from the pixel, slice from the decoded view depth).
class ClusterFragmentLists final : public FragmentListSource {
public:
    explicit ClusterFragmentLists(const ClusterGrid& grid) : mGrid(grid) {}
    std::span<const uint32_t> listOf(int x, int y, const glm::vec3& positionView) const override {
        return mGrid.lightsOf(mGrid.clusterIndex(mGrid.tileXOfPixel(x), mGrid.tileYOfPixel(y),
                                                 mGrid.sliceOfDepth(-positionView.z)));
    }

private:
    const ClusterGrid& mGrid;
};

class ClusteredStage final : public ShadingStage, public PackedFragmentShading {
public:
    explicit ClusteredStage(const ClusteredOptions& options) : mOptions(options) {}
    std::string name() const override { return "clustered"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        result.resize(gb.width(), gb.height(), false);
        PassTimer assign(result, pass::kAssign);
        boundingSpheresView(*inputs.lights, mSpheres);
        if (mOptions.adaptive)
            shadeAdaptive(inputs, assign, result);
        else
            shadeFixed(inputs, assign, result);
    }

    // A multisampled frame's other fragments in one run (PackedFragments.h) with the frame's grid
    // (built on layer 0 over every layer's depth range, shadeFixed), built and assigned again
    // over the union only if a fragment's stored depth falls outside it. The adaptive grid has no
    // packed run (false: the layers are run one by one).
    bool shadeFragments(const PackedFragmentRun& run, StageResult& result) override {
        if (mOptions.adaptive || !mFrameGrid.valid || !mGrid ||
            mFrameGrid.lightCount != mSpheres.size())
            return false;
        const PackedFragments& fragments = *run.fragments;
        const gbuffer::GBuffer& gb = *run.frame->gbuffer;
        result.resize(int(fragments.size()), 1, false);
        PassTimer assign(result, pass::kAssign);
        const MinMax ndcRange = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, fragments.size()), MinMax{INFINITY, -INFINITY},
            [&](const tbb::blocked_range<size_t>& range, MinMax m) {
                for (size_t i = range.begin(); i != range.end(); ++i) {
                    const float d = run.gbufferOf(i).depth()[fragments.pixel(i)];
                    m = {std::min(m.first, d), std::max(m.second, d)};
                }
                return m;
            },
            joinRanges);
        const MinMax viewRange = viewDepthRange(gb, ndcRange);
        if (viewRange.first < mFrameGrid.nearDepth || viewRange.second > mFrameGrid.farDepth) {
            mFrameGrid.nearDepth = std::min(viewRange.first, mFrameGrid.nearDepth);
            mFrameGrid.farDepth = std::max(viewRange.second, mFrameGrid.farDepth);
            mGrid->build(mOptions.fixed, gb.view(), mFrameGrid.nearDepth, mFrameGrid.farDepth);
            mGrid->assign(mSpheres);
        }
        assign.stop();
        PassTimer shading(result, pass::kShading);
        accumulatePackedFragments(run, ClusterFragmentLists(*mGrid), result);
        return true;
    }

private:
    void shadeAdaptive(const StageInputs& inputs, PassTimer& assign, StageResult& result) {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        // Blended surfaces lie anywhere in front of the opaque depth, and over background: every
        // tile then spans the whole view depth range so that their clusters exist.
        const bool blended = mBlended.prepare(inputs);
        AdaptiveClusterGrid& grid = mAdaptive;
        const bool built = grid.build(mOptions.adaptiveGrid, gb, mSpheres, blended,
                                      gb.view().nearMetres, gb.view().farMetres);
        if (built)
            grid.assign(mSpheres);
        assign.stop();
        PassTimer shading(result, pass::kShading);
        if (built)
            accumulateLights(inputs, ClusterListSource<AdaptiveClusterGrid>(grid), {}, result);
        shading.stop();
        if (blended)
            mBlended.shade(
                gb.depth(),
                [&](int x, int y, const gbuffer::Surface& point, uint32_t) {
                    return grid.lightsOf(
                        grid.clusterIndex(grid.tileXOfPixel(x), grid.tileYOfPixel(y),
                                          grid.sliceOfDepth(-point.positionView.z)));
                },
                result);
        result.parameters["grid"] = "adaptive";
        result.parameters["cells"] = mOptions.cellsText;
        result.parameters["max_clusters"] = std::to_string(mOptions.adaptiveGrid.maxClusters);
        result.parameters["adaptive_grid"] = built ? std::to_string(grid.tilesX()) + "x" +
                                                         std::to_string(grid.tilesY()) + "x" +
                                                         std::to_string(grid.slices())
                                                   : "none";
        result.parameters["tile_pixels"] = built ? std::to_string(grid.tilePixels()) : "0";
        result.parameters["clusters"] = std::to_string(built ? grid.clusterCount() : 0);
        result.parameters["cluster_bytes"] = std::to_string(grid.memoryBytes());
        result.parameters["cluster_light_pairs"] = std::to_string(built ? grid.pairCount() : 0);
    }

    using MinMax = std::pair<float, float>;

    // The range spanning both (min and max: the same for any order, so deterministic).
    static MinMax joinRanges(MinMax a, MinMax b) {
        return MinMax{std::min(a.first, b.first), std::max(a.second, b.second)};
    }

    // The view depths of the extremes of an NDC depth range (depth along -Z does not depend on
    // the pixel for a pinhole), widened so that rounding in the per-pixel reconstruction stays
    // inside: the grid's depth range.
    static MinMax viewDepthRange(const gbuffer::GBuffer& gb, MinMax ndcRange) {
        const gbuffer::DepthDecoder& decoder = gb.depthDecoder();
        const int x = gb.width() / 2, y = gb.height() / 2;
        const float depthA = decoder.viewDepthMetres(x, y, ndcRange.first);
        const float depthB = decoder.viewDepthMetres(x, y, ndcRange.second);
        const float nearDepth = std::max(std::min(depthA, depthB) * (1.0f - 1e-5f), 1e-6f);
        return {nearDepth, std::max(std::max(depthA, depthB) * (1.0f + 1e-5f), nearDepth)};
    }

    void shadeFixed(const StageInputs& inputs, PassTimer& assign, StageResult& result) {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        const int width = gb.width(), height = gb.height();
        const ClusterGridOptions& options = mOptions.fixed;
        if (inputs.fragmentLayer == 0)
            mFrameGrid.valid = false; // a new frame

        // Nearest and farthest covered NDC depth (min/max: order-independent, so deterministic).
        const std::span<const float> depth = gb.depth();
        const float clear = gb.view().clearDepth();
        MinMax ndcRange = tbb::parallel_reduce(
            tbb::blocked_range<int>(0, height), MinMax{INFINITY, -INFINITY},
            [&](const tbb::blocked_range<int>& rows, MinMax m) {
                for (int y = rows.begin(); y < rows.end(); ++y)
                    for (size_t p = size_t(y) * width, end = p + width; p < end; ++p)
                        if (depth[p] != clear)
                            m = {std::min(m.first, depth[p]), std::max(m.second, depth[p])};
                return m;
            },
            joinRanges);
        // A multisampled frame's layer 0: the range takes in the other layers' fragments too
        // (their rasterizer depths, at the columns that hold them), so that the frame's grid
        // serves them (the reuse below). Where a layer's stored depth still falls outside (a
        // lossy depth format), that layer builds its own grid: the check is on its G-buffer.
        if (inputs.fragmentLayer == 0 && inputs.fragmentLayers &&
            inputs.fragmentLayers->layerCount() > 1) {
            const gbuffer::FragmentLayers& layers = *inputs.fragmentLayers;
            const MinMax upper = tbb::parallel_reduce(
                tbb::blocked_range<int>(0, height), MinMax{INFINITY, -INFINITY},
                [&](const tbb::blocked_range<int>& rows, MinMax m) {
                    for (int y = rows.begin(); y < rows.end(); ++y)
                        for (const uint32_t x : layers.upperColumns(y))
                            for (int k = 1; k < layers.layerCount(); ++k) {
                                const size_t p = size_t(y) * width + x;
                                if (layers.codes(k)[p] == gbuffer::VisibilityPass::kNoTriangle)
                                    continue;
                                const float d = layers.depths(k)[p];
                                m = {std::min(m.first, d), std::max(m.second, d)};
                            }
                    return m;
                },
                joinRanges);
            ndcRange = joinRanges(ndcRange, upper);
        }

        std::string pairs = "0";
        if (ndcRange.first <= ndcRange.second) {
            const MinMax viewRange = viewDepthRange(gb, ndcRange);
            float nearDepth = viewRange.first, farDepth = viewRange.second;
            // Blended surfaces lie anywhere in front of the opaque depth, and over background:
            // the grid then spans the whole view depth range so that their clusters exist.
            const bool blended = mBlended.prepare(inputs);
            if (blended) {
                nearDepth = std::min(nearDepth, gb.view().nearMetres);
                farDepth = std::max(farDepth, gb.view().farMetres);
            }
            // A multisampled frame's layers above 0 (StageInputs::fragmentLayer >= 1) come after
            // its layer 0, with the same view and lights (the stage contract): a cluster's list
            // holds every light that may touch any point inside the cluster, so the frame's grid
            // serves the other fragments too wherever their depths lie inside its range, as one
            // grid per frame serves every sample on a GPU. It is built and assigned again only
            // for a layer that reaches outside that range. Without this each sparse upper layer
            // paid a whole grid's assignment (about 1 ms at 256 lights on atrium).
            const bool reuse = inputs.fragmentLayer >= 1 && mFrameGrid.valid && mGrid &&
                               nearDepth >= mFrameGrid.nearDepth &&
                               farDepth <= mFrameGrid.farDepth &&
                               mFrameGrid.lightCount == mSpheres.size();
            if (!reuse) {
                if (!mGrid)
                    mGrid.emplace(options, gb.view(), nearDepth, farDepth);
                else
                    mGrid->build(options, gb.view(), nearDepth, farDepth);
                mGrid->assign(mSpheres);
                if (inputs.fragmentLayer == 0 && inputs.fragmentLayers != nullptr)
                    mFrameGrid.valid = true;
                mFrameGrid.nearDepth = nearDepth;
                mFrameGrid.farDepth = farDepth;
                mFrameGrid.lightCount = mSpheres.size();
            }
            ClusterGrid& grid = *mGrid;
            assign.stop();
            pairs = std::to_string(grid.pairCount());

            PassTimer shading(result, pass::kShading);
            accumulateLights(inputs, ClusterListSource<ClusterGrid>(grid), {}, result);
            shading.stop();
            // Blended surfaces: each fragment with its own cluster's list.
            if (blended)
                mBlended.shade(
                    depth,
                    [&](int x, int y, const gbuffer::Surface& point, uint32_t) {
                        return grid.lightsOf(
                            grid.clusterIndex(grid.tileXOfPixel(x), grid.tileYOfPixel(y),
                                              grid.sliceOfDepth(-point.positionView.z)));
                    },
                    result);
        } else {
            assign.stop();
            result.timingsMs.emplace_back(pass::kShading, 0.0);
            // No opaque sample, no grid: blended surfaces with every light.
            if (mBlended.prepare(inputs))
                mBlended.shadeWithEveryLight(depth, result);
        }

        std::string grid = std::to_string(options.tilesX);
        grid.append("x")
            .append(std::to_string(options.tilesY))
            .append("x")
            .append(std::to_string(options.slices));
        result.parameters["grid"] = grid;
        result.parameters["slices"] =
            options.spacing == SliceSpacing::Exponential ? "exp" : "uniform";
        result.parameters["assign"] = options.assign == AssignMethod::Walk     ? "walk"
                                      : options.assign == AssignMethod::Binary ? "binary"
                                                                               : "bvh";
        result.parameters["test"] = options.test == ClusterTest::Aabb ? "aabb" : "frustum";
        result.parameters["cluster_light_pairs"] = pairs;
    }

    ClusteredOptions mOptions;
    std::vector<LightSphere> mSpheres; // reused across frames (LightBounds.h)
    std::optional<ClusterGrid> mGrid;  // reused across frames for its storage
    // What mGrid was last built for, when that was a multisampled frame's layer 0 or a layer
    // above it: the frame's other layers may shade with it (shadeFixed).
    struct FrameGrid {
        bool valid = false;
        float nearDepth = 0.0f, farDepth = 0.0f; // the grid's view depth range, metres
        size_t lightCount = 0;
    } mFrameGrid;
    AdaptiveClusterGrid mAdaptive; // likewise
    BlendedPass mBlended;          // blended surfaces after the opaque pass (BlendedPass.h)
};

std::vector<StageOption> clusteredOptionTable() {
    const ClusterGridOptions defaults;
    const AdaptiveClusterOptions adaptiveDefaults;
    return {
        StageOption::text(
            "grid",
            std::to_string(defaults.tilesX) + "x" + std::to_string(defaults.tilesY) + "x" +
                std::to_string(defaults.slices),
            "adaptive, or XxYxZ with each of X, Y, Z in 1.." +
                std::to_string(kMaxClusterDimension) + " and at most " +
                std::to_string(kMaxClusterCount) + " clusters",
            [](const std::string& value) -> std::optional<std::string> {
                if (value == "adaptive")
                    return value;
                int x = 0, y = 0, z = 0;
                if (!parseClusterGrid(value, x, y, z))
                    return std::nullopt;
                return std::to_string(x) + "x" + std::to_string(y) + "x" + std::to_string(z);
            },
            "tile columns x tile rows x depth slices; adaptive: cluster size from the lights' "
            "projected sizes each frame, each tile only the slices its samples span "
            "(culling/AdaptiveClusterGrid.h)"),
        StageOption::choice("slices", {"exp", "uniform"},
                            "slice boundaries between the G-buffer's nearest and farthest depth: "
                            "geometric or linear (fixed grid)"),
        StageOption::choice("assign", {"walk", "binary", "bvh"},
                            "per light, its cluster ranges by walking the planes or by binary "
                            "search; or per cluster, its lights from a light BVH (same lists; "
                            "fixed grid)"),
        StageOption::choice("test", {"aabb", "frustum"},
                            "cluster test: sphere vs AABB, or AABB and the four side planes "
                            "(fixed grid)"),
        StageOption::number("cells", adaptiveDefaults.cellsPerLight, 0.25f, 16.0f, false,
                            "grid=adaptive: clusters across a typical light's diameter per axis"),
        StageOption::integer("max_clusters", int(adaptiveDefaults.maxClusters), 1, 1 << 24,
                             "grid=adaptive: stored clusters at most (4 bytes each); the grid "
                             "coarsens to fit")};
}

const StageRegistrar kRegistrar(
    {.name = "clustered",
     .description = "implicit clusters: grid of screen tiles x depth slices (fixed, or adaptive to "
                    "the light density), lights assigned per cluster AABB",
     .kind = StageKind::Exact,
     .options = clusteredOptionTable(),
     .listOrder = 50,
     .msaaNote = "one grid per frame, over every fragment's depth; the complex pixels' other "
                 "fragments in one packed run, full packets by screen block (grid=adaptive: "
                 "one run per fragment layer, as with blended surfaces)"},
    [](const StageOptions& table) {
        ClusteredOptions options;
        options.adaptive = table.text("grid") == "adaptive";
        const std::vector<std::string> fixedOnly = {"slices", "assign", "test"};
        const std::vector<std::string> adaptiveOnly = {"cells", "max_clusters"};
        // An option of the other kind given with a value other than its default would be
        // ignored: refused. Its default given explicitly changes nothing and is accepted (every
        // option's default must parse on its own, tests/lighting/stage_options_test.cpp).
        std::map<std::string, std::string> defaults;
        for (const StageOption& option : clusteredOptionTable())
            defaults[option.key] = option.defaultText;
        for (const std::string& key : options.adaptive ? fixedOnly : adaptiveOnly)
            if (table.given(key) && table.resolved().at(key) != defaults.at(key))
                throw StageError("stage '" + table.stageName() + "': option " + key +
                                 (options.adaptive ? " applies to a fixed grid only"
                                                   : " applies to grid=adaptive only"));
        if (!options.adaptive)
            parseClusterGrid(table.text("grid"), options.fixed.tilesX, options.fixed.tilesY,
                             options.fixed.slices);
        options.fixed.spacing =
            table.text("slices") == "exp" ? SliceSpacing::Exponential : SliceSpacing::Uniform;
        const std::string assign = table.text("assign");
        options.fixed.assign = assign == "walk"     ? AssignMethod::Walk
                               : assign == "binary" ? AssignMethod::Binary
                                                    : AssignMethod::Bvh;
        options.fixed.test =
            table.text("test") == "aabb" ? ClusterTest::Aabb : ClusterTest::Frustum;
        options.adaptiveGrid.cellsPerLight = table.number("cells");
        options.adaptiveGrid.maxClusters = size_t(table.integer("max_clusters"));
        options.cellsText = table.resolved().at("cells");
        return std::make_unique<ClusteredStage>(options);
    });

} // namespace

} // namespace lighting
