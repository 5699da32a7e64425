// Limits: the one place where every input that sizes memory or recursion has its cap. Each
// reader checks its input against these numbers, with an estimate of the memory it would need,
// before it allocates anything for it; an input over a cap is one error naming the file, the
// field, the figure and the cap (never a std::bad_alloc, a crash or minutes of swapping).
// README.md ("Limits") lists them for users; change a cap here and there together.
//
// Why these figures: the development machine (and CI) has 24 GiB and 2 cores. Each cap admits
// every real input we know of with a wide margin (the largest shared glTF model has ~0.3 M
// triangles; the built-in atrium 0.35 M; published light-culling studies use <= 10^6 lights)
// while keeping the worst admitted input under a few GiB.
// This header lives in scenes/ because scenes is the bottom library that every other one (and
// the testbed CLI) links; it has no dependencies.
#pragma once

#include <cstddef>
#include <cstdint>

namespace scenes::limits {

// Nesting of JSON arrays/objects and TOML tables/arrays, in any input file (glTF, GLB JSON chunk,
// JSON scene, sweep file). tinygltf converts JSON values recursively (a few hundred bytes of
// stack per level, more under AddressSanitizer), so 10^5 levels overflow an 8 MiB stack; real
// files nest about 10 levels. 256 is also toml++'s own bound for arrays and inline tables.
inline constexpr int kMaxNestingDepth = 256;

// One file read whole into memory by a loader: a .gltf/.glb, an external .bin buffer, an image.
// stb_image and tinygltf take sizes as int / unsigned, so 2 GiB - 1 is also what they can take.
inline constexpr uint64_t kMaxFileBytes = (uint64_t(1) << 31) - 1;

// Vertices stored over all meshes of a scene (each at 48 bytes: position, normal, tangent, uv):
// 2^26 vertices = 3 GiB. Also the per-mesh bound of the procedural MeshBuilder.
inline constexpr uint64_t kMaxVertices = uint64_t(1) << 26;
inline constexpr uint64_t kBytesPerVertex = 48;

// Triangles drawn per frame, counted over instances (a mesh placed n times counts n times): the
// rasterizer transforms, clips and bins every drawn triangle. Estimated at 12 bytes of indices
// per stored triangle plus ~64 bytes of per-frame rasterizer data per drawn triangle: 2^26
// triangles = 4 GiB.
inline constexpr uint64_t kMaxTriangles = uint64_t(1) << 26;
inline constexpr uint64_t kBytesPerDrawnTriangle = 64;

// One texture image, as declared in its header (read before decoding): sides up to 16384 and at
// most 2^26 pixels (8192 x 8192: 256 MiB as RGBA8, up to 512 MiB while stb decodes 16-bit RGBA).
// Over the cap the image is not decoded: a warning, and materials fall back to their factors.
inline constexpr int kMaxTextureSide = 16384;
inline constexpr uint64_t kMaxTexturePixels = uint64_t(1) << 26;
// Decoded texture memory over a whole scene (RGBA8, 4 bytes per pixel): 4 GiB. Images past it get
// the same warning and fallback.
inline constexpr uint64_t kMaxTextureBytes = uint64_t(1) << 32;

// Lights in a scene, whatever makes them (--lights, lightGenerator.count, explicit lights, glTF
// KHR_lights_punctual): a Light is 56 bytes, and culling structures grow with the count (stages
// keep a few index lists per tile or cluster); 10^6 lights stay under 1 GiB in every stage.
inline constexpr int kMaxLights = 1'000'000;

// Rendered image size: every side 1..16384 and at most 8192 x 8192 pixels in all (a G-buffer of
// up to 40 bytes per pixel plus float RGB image, light counts and reference: ~6 GiB at the cap).
inline constexpr int kMaxImageSide = 16384;
inline constexpr uint64_t kMaxPixels = uint64_t(8192) * 8192;

// An image that `testbed diff` reads: its header is read first and must be within the image
// limits above, with at most 64 channels and 2^30 channel values in all (4 GiB as float; a
// 1280x720 render.exr has 21 channels, 19 M values). The diff holds both inputs as float plus a
// few planes of its own.
inline constexpr int kMaxImageChannels = 64;
inline constexpr uint64_t kMaxImageValues = uint64_t(1) << 30;

// Magnitudes of a scene's numbers, checked in float (the precision the renderer computes in) after
// every transform is composed (scenes::validate, issue 32 class 1). A world coordinate, a light's
// range and a camera's far plane are at most 1e15 m: lighting squares distances (|d|^2 of two
// points up to 1e15 m apart per axis is at most 1.2e31) and the projection multiplies them by up
// to ~1e5 more, all far below float's 3.4e38. 1e15 m is ~6700 astronomical units: no real scene
// comes near it. A value finite in double but over float's range is refused wherever it is read.
inline constexpr double kMaxCoordinateMetres = 1e15;
// A light's radiance (colour x intensity, per channel) and a material's emitted radiance
// (emissive factor x strength): at most 1e30, so that 10^6 lights (kMaxLights) summed at a pixel
// and weighted by a BRDF's peak (~1e2 for Blinn-Phong's largest exponent) stay below float's
// 3.4e38 instead of summing to infinity.
inline constexpr double kMaxRadiance = 1e30;

// Jobs of one sweep (after crossing axes and cases). Each job's settings are kept in memory
// while the sweep runs (about 1 KiB per job), so 10^6 jobs are ~1 GiB.
inline constexpr uint64_t kMaxSweepJobs = 1'000'000;

} // namespace scenes::limits
