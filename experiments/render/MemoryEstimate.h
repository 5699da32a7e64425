// MemoryEstimate: a render's peak resident memory, estimated before anything large is allocated
// (issue 32, class 9: 8192x8192 took 6.3 GB, a 10^6-node glTF 1.1 GB, 256 shadowed point lights
// at 1024^2 texels 6.5 GB, with nothing to stop them but the out-of-memory killer). One estimator
// for `testbed render`, --explain-layout, stats.json and every sweep job; a render whose estimate
// exceeds its limit (--max-memory, a sweep's max-memory key; default kDefaultMaxMemoryFraction of
// the machine's memory) is refused with the estimate, its largest terms and the limit.
//
// Two checks, both before the allocation they bound:
//   - before the scene is loaded: the process baseline plus the parse of a scene file
//     (sceneLoadBytes: the glTF / JSON document tree, ~16 bytes per byte of JSON text, measured);
//   - after the plan (scene loaded, layout derived), before the G-buffer pass (runRender): the
//     sum of the terms below.
// Terms (bytes; "pixels" = width x height; constants measured on this machine with getrusage's
// ru_maxrss against renders of spheres and atrium, 64^2 .. 4096^2, 1x .. 8x MSAA; see
// experiments/README.md "Memory" for the figures and the factor the estimate is within):
//   process        binary, libraries, thread pools, fonts: kProcessBaselineBytes
//   scene          the loaded scene's arrays (meshes, textures, instances, lights), exactly
//   geometry       per drawn vertex (over instances) its world-space copy, per drawn triangle
//                  its indices and the rasterizer's set-up data
//   gbuffer        pixels x the layout's allocated bytes per pixel x (MSAA: one layer per sample
//                  at most)
//   msaa           per-sample depth and visibility (12 bytes a sample) and per-layer shading
//                  scratch, MSAA only
//   frame          per pixel: the stage's result (RGB, light counts), rasterizer buffers, the
//                  stage's scratch and the output images (decoded layers, EXR rows, PNG canvases)
//   exact_surface  the exact surface, when the stage reads it
//   reference      with --compare-reference: the double-precision reference, its frame and the
//                  error and FLIP planes (more for a supersampled reference)
//   post_aa        the filter's edge plane and scratch
//   shadow_maps    an upper bound: the casting lights the budget allows, most bytes first
//                  (point 6 or dual-paraboloid 2, directional `cascades`, spot 1) x the
//                  light's own or the global mapSize^2 floats, twice when the
//                  maps are rendered more than once (a repetition's maps are built before the
//                  previous ones are freed)
//   rays           Embree's BVH (~90 bytes a drawn triangle) for ray-traced shadows or the
//                  visibility oracle
//   lights         per light, its view-space copy and its share of culling lists
//   scene_file_parse  the parse of the scene file (sceneLoadBytes) peaks before the render and is
//                  freed after it: only its excess over the render's own terms counts
// Cost: O(meshes + instances + lights); loads nothing.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "experiments/render/RenderOptions.h"
#include "gbuffer/GBufferLayout.h"
#include "lighting/ShadingStage.h"
#include "scenes/Scene.h"

namespace experiments {

// The default limit: this fraction of the machine's memory (physicalMemoryBytes), leaving the
// rest to the OS, the page cache and other users of a shared machine.
inline constexpr double kDefaultMaxMemoryFraction = 0.75;
// What the process holds before it renders anything (measured: 136-142 MiB for a 16x16 render).
inline constexpr uint64_t kProcessBaselineBytes = uint64_t(140) << 20;
// Peak bytes of loading a scene file per byte of JSON text (glTF JSON, JSON scenes, a GLB's JSON
// chunk): the document tree of nlohmann/tinygltf. Measured: 15.2 and 15.4 on glTF files of 10^5
// and 10^6 nodes (6 MB and 64 MB of text). A GLB's binary chunk and external buffers count 3
// bytes per byte (the file, the buffer, the decoded arrays).
inline constexpr double kSceneLoadBytesPerJsonByte = 16.0;
inline constexpr double kSceneLoadBytesPerBinaryByte = 3.0;

struct MemoryTerm {
    std::string name; // "gbuffer", "frame", ... (see the top of the file)
    double bytes = 0.0;
    std::string basis; // how it was counted, e.g. "1048576 pixels x 17 bytes"
};

struct MemoryEstimate {
    std::vector<MemoryTerm> terms;
    uint64_t limitBytes = 0; // the limit it is checked against

    double totalBytes() const;
    // The lines --explain-layout prints: the total, the limit, every term with its basis.
    std::string explain() const;
    // stats.json's "memory" block: estimate_bytes, limit_bytes, terms {name: bytes}.
    nlohmann::json toJson() const;
};

// The machine's memory: the smaller of the physical memory (sysconf) and the cgroup v2 limit of
// this process (/sys/fs/cgroup/memory.max), when there is one.
uint64_t physicalMemoryBytes();
// options.maxMemoryBytes, or kDefaultMaxMemoryFraction of physicalMemoryBytes() when it is 0.
uint64_t memoryLimitBytes(const RenderOptions& options);

// "1073741824", "512M", "1.5G", "8GiB", "64k": bytes with an optional binary suffix (K, M, G, T;
// an optional "B" or "iB"). Throws UsageError naming `option` for anything else, 0, or more
// than 2^60 bytes.
uint64_t parseByteSize(const std::string& text, const std::string& option);
// Bytes for people: "6.27 GiB", "512 MiB", "900 bytes".
std::string formatBytes(double bytes);

// Peak bytes of loading the options' scene file (0 for a built-in scene): see
// kSceneLoadBytesPerJsonByte. Reads at most the 20-byte GLB header.
double sceneLoadBytes(const std::string& scene);
// Throws UsageError when kProcessBaselineBytes + sceneLoadBytes exceed the limit: called before
// the scene is loaded.
void checkSceneLoadMemory(const RenderOptions& options);

// The estimate of a planned render (terms above), with memoryLimitBytes(options) as its limit.
MemoryEstimate estimateRenderMemory(const RenderOptions& options, const scenes::Scene& scene,
                                    const gbuffer::GBufferLayout& layout,
                                    const lighting::StageRequirements& requirements);

// Throws UsageError("... needs an estimated X at its peak (largest: ...), over the memory limit
// Y (--max-memory ...)") when the estimate exceeds its limit.
void checkMemoryEstimate(const MemoryEstimate& estimate);

// The process's peak resident set size so far (getrusage ru_maxrss), bytes: since the process
// started, or since the last resetPeakResident().
uint64_t peakResidentBytes();
// Lowers the peak to the current resident set (Linux: writes 5 to /proc/self/clear_refs), so
// that a sweep job measures its render without the reference it rendered before; false when the
// kernel refuses (the peak then stays the process's).
bool resetPeakResident();

} // namespace experiments
