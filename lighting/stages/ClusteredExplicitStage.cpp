// `clustered-explicit`: explicit (unique) clustered deferred shading (Olsson, Billeter and
// Assarsson, "Clustered Deferred and Forward Shading", HPG 2012). Instead of a fixed grid, each
// covered sample gets a cluster key from its screen tile, its exponential depth slice and
// optionally its quantised normal; the unique keys of each tile are its clusters, each bounded
// by a tight view-space AABB and a normal cone from its own decoded samples, and lights are
// assigned per cluster by sphere vs AABB plus, by default, back-face culling with the cone
// (lighting/culling/ExplicitClusters.h). Every covered pixel then shades with its cluster's
// ascending list through accumulateLights (LightAccumulation.h), 4x4 packets whose lanes are
// grouped by cluster: the same image as `brute`.
//
// Options (defaults first):
//   tile=32          screen tile size in pixels (4..256; the paper's 32x32)
//   normals=0        normal clustering: 0 off, n = n x n cells per cube face (1..8; paper: 3)
//   backface=1       back-face culling of lights with each cluster's normal cone
// Passes: "clusters" (keys, unique clusters, bounds), "assign" (light lists), "shading"; "blend"
// when the scene has blended surfaces. Parameters: unique_clusters, mean_lights_per_cluster,
// cluster_light_pairs, cluster_bytes (per-pixel cluster indices, clusters, lists),
// backface_rejected ((cluster, light) pairs the cone test removed).
// Blended surfaces (no sample of the G-buffer, so no explicit cluster): the near-to-opaque tile
// lists of the tiled stages (BlendedTileLists.h) on this stage's tiles, as Forward+ culls a second
// list set for transparent geometry. MSAA: run per fragment layer (MultisampleShading.h); an
// upper layer's clusters come from its complex pixels' samples only.
// Conventions: view space right-handed, -Z forward; a pixel's cluster is the one its decoded
// sample (bitwise the shaded one) was keyed into, so it lies in its cluster's box exactly.
#include <stdexcept>
#include <string>

#include "lighting/StageRegistry.h"
#include "lighting/culling/ExplicitClusters.h"
#include "lighting/culling/LightBounds.h"
#include "lighting/passes/BlendedPass.h"
#include "lighting/passes/LightAccumulation.h"
#include "lighting/passes/PassNames.h"

namespace lighting {

namespace {

// A packet's lanes grouped by their pixels' clusters, each with its cluster's ascending list
// (a packet across clusters gets their union with per-light lane masks, addByKeyMerged), so each
// lane walks exactly its own cluster's list.
class ExplicitClusterListSource final : public PacketListSource {
public:
    explicit ExplicitClusterListSource(const ExplicitClusters& clusters) : mClusters(clusters) {}
    void listsOf(const kernel::ShadingPacket& packet, PacketLightLists& lists) const override {
        lists.addByKeyMerged(
            packet,
            [&](int lane) {
                return mClusters.clusterOfPixel(packet.x0 + kernel::laneX(lane),
                                                packet.y0 + kernel::laneY(lane));
            },
            [&](uint32_t cluster) {
                // A shaded lane is a covered pixel, which find() always keyed (GBuffer::covered
                // is the decoder's rule too); anything else is a bug, never a silent empty list.
                if (cluster == kNoCluster)
                    throw std::logic_error("clustered-explicit: a shaded pixel has no cluster");
                return mClusters.lightsOf(cluster);
            });
    }

private:
    const ExplicitClusters& mClusters;
};

class ClusteredExplicitStage final : public ShadingStage {
public:
    explicit ClusteredExplicitStage(const ExplicitClusterOptions& options) : mOptions(options) {}
    std::string name() const override { return "clustered-explicit"; }
    StageRequirements requirements() const override { return StageRequirements::wholeSurface(); }

    void shade(const StageInputs& inputs, StageResult& result) override {
        const gbuffer::GBuffer& gb = *inputs.gbuffer;
        result.resize(gb.width(), gb.height(), false);

        PassTimer findPass(result, pass::kClusters);
        mClusters.find(gb, mOptions);
        findPass.stop();

        PassTimer assignPass(result, pass::kAssign);
        const uint64_t backfaceRejected = mClusters.assignLights(
            gb.view(), boundingSpheresView(*inputs.lights), mOptions.backface);
        assignPass.stop();

        PassTimer shadingPass(result, pass::kShading);
        accumulateLights(inputs, ExplicitClusterListSource(mClusters), {}, result);
        shadingPass.stop();

        if (mBlended.prepare(inputs))
            mBlended.shadeWithTileLists(gb.depth(), mOptions.tileSizePixels, true, result);

        const size_t clusterCount = mClusters.clusterCount();
        result.parameters["tile"] = std::to_string(mOptions.tileSizePixels);
        result.parameters["normals"] = std::to_string(mOptions.normalDivisions);
        result.parameters["backface"] = mOptions.backface ? "1" : "0";
        result.parameters["unique_clusters"] = std::to_string(clusterCount);
        result.parameters["cluster_light_pairs"] = std::to_string(mClusters.pairCount());
        result.parameters["mean_lights_per_cluster"] = std::to_string(
            clusterCount == 0 ? 0.0 : double(mClusters.pairCount()) / double(clusterCount));
        result.parameters["cluster_bytes"] = std::to_string(mClusters.bytes());
        result.parameters["backface_rejected"] = std::to_string(backfaceRejected);
    }

private:
    ExplicitClusterOptions mOptions;
    ExplicitClusters mClusters; // kept across frames for its storage
    BlendedPass mBlended;       // blended surfaces after the opaque pass (BlendedPass.h)
};

const StageRegistrar kRegistrar(
    {.name = "clustered-explicit",
     .description = "explicit (unique) clusters from the samples' tile, depth slice and "
                    "optionally normal; tight boxes and normal cones, lights per cluster",
     .kind = StageKind::Exact,
     .options = {StageOption::integer("tile", 32, 4, 256, "screen tile size in pixels"),
                 StageOption::integer("normals", 0, 0, kMaxNormalDivisions,
                                      "normal clustering: 0 off, n = n x n cells per cube face"),
                 StageOption::boolean("backface", true,
                                      "back-face culling of lights with the clusters' normal "
                                      "cones")},
     .listOrder = 55,
     .msaaRefusal = {},
     .msaaNote = "clusters per fragment layer: an upper layer's clusters hold only its complex "
                 "pixels' samples"},
    [](const StageOptions& table) {
        ExplicitClusterOptions options;
        options.tileSizePixels = table.integer("tile");
        options.normalDivisions = table.integer("normals");
        options.backface = table.boolean("backface");
        return std::make_unique<ClusteredExplicitStage>(options);
    });

} // namespace

} // namespace lighting
