// NormalCodec: the G-buffer normal encodings of the literature as pure functions, so that
// experiments can compare them by their angular error at equal storage (bits per pixel).
//
// Conventions:
// - Input and output are view-space unit normals (right-handed, camera looking down -Z, so a
//   surface facing the camera's axis has normalView.z > 0). Nothing here depends on the view
//   except `xy-z`, which assumes z >= 0 and is kept to measure what that assumption costs (under
//   perspective, visible normals can have z < 0 off-centre), and `pixel-view`, which reads the
//   pixel's view ray (see below).
// - A codec is named "NAME:BITS" where BITS is the TOTAL number of bits of the code (pbrt-style
//   registry: parse() ends in an error listing every valid name and bit count).
// - Signed components are quantised as SNORM (D3D / Cigolle et al. 2014): b bits hold
//   q in [-(2^(b-1)-1), 2^(b-1)-1], value q / (2^(b-1)-1), stored offset by 2^(b-1)-1. Unlike the
//   thesis' "v*0.5+0.5" UNORM this represents 0 and +-1 exactly (so +Z, the axes and the
//   octahedral folds are exact); the code 2^b-1 is never written and decodes as +1.
// - Component i of a code lives in bits [i*b, (i+1)*b) of NormalCode::low (x first).
// - Robustness contract: encode accepts ANY input. A non-finite input (NaN or Inf component) or a
//   zero vector encodes kFallbackNormalView (+Z). Non-unit lengths (huge, subnormal, 1+-1e-3) are
//   normalised in double first. decode accepts ANY code (also codes no encoder writes) and returns
//   a finite unit vector (to float rounding, |n| = 1 +- 1e-6), never NaN/Inf.
// - All functions are pure, allocation-free (except the name/registry helpers, parse and
//   best-fit's one-time table) and thread-safe. Encode/decode cost tens of nanoseconds;
//   `best-fit` encode looks up a 512 KiB table of best lengths, built once by the first best-fit
//   encode (TBB-parallel; that call blocks ~0.5 s, concurrent first callers wait for the same
//   build), and `octahedral-precise` decodes up to 4 candidates.
// - `pixel-view` (the thesis' "per-pixel view space", Ishmukhametov 2013, section "Compact normal
//   storage") expresses the normal in a frame built from the pixel's view ray r: z =
//   -normalize(r), x = normalize(z.z, 0, -z.x), y = cross(z, x) (at the image centre this is the
//   view frame, so the codec equals `xy-z` there). It stores local x, y as SNORM and reconstructs
//   local z = +sqrt(max(0, 1 - x^2 - y^2)). A pinhole camera never sees a normal with local z < 0
//   (it faces away from the ray), so such inputs are clamped to the silhouette: the nearest local-z
//   = 0 direction (local (x, y) normalised; exactly -z goes to local +x). Degenerate rays (zero,
//   NaN/Inf, or parallel to the view Y axis, where x is undefined) fall back to kCentralViewRay, in
//   encode and decode alike, so a pair given the same ray always agrees.
// - normalErrorBoundRadians() gives each codec's derived worst-case angular error, valid inside
//   inNormalErrorBoundRegion() (the comment in NormalCodec.cpp derives every bound).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace gbuffer {

enum class NormalCodecKind {
    Float32,             // "float32": xyz float32, the reference (96 bits)
    Xyz,                 // "xyz": three SNORM components, the naive baseline
    XyReconstructZ,      // "xy-z": X, Y stored, Z = +sqrt(1-x^2-y^2) (wrong for z < 0)
    Spherical,           // "spherical": azimuth and polar angle
    Spheremap,           // "spheremap": Lambert azimuthal equal-area (Pranckevicius method #4)
    Stereographic,       // "stereographic": projection from -Z, plane square [-1,1]^2
    StereographicScaled, // "stereographic-scaled": the same with the thesis' scale 1.7777
    PixelView,           // "pixel-view": X, Y in the per-pixel view frame, Z reconstructed
    BestFit,             // "best-fit": Kaplanyan 2010 best-fit normals in RGB8
    Octahedral,          // "octahedral": Meyer / Cigolle octahedral map, plain rounding
    OctahedralPrecise,   // "octahedral-precise": the best of the 4 floor/ceil neighbours
};

// The code of one normal. Up to 64 bits live in `low`; only float32 (96 bits) uses `high`
// (its z component), which is why this is not a bare uint64_t.
struct NormalCode {
    std::uint64_t low = 0;
    std::uint32_t high = 0;
    friend bool operator==(const NormalCode&, const NormalCode&) = default;
};

// What invalid inputs (NaN/Inf, zero vector) encode to and what invalid float32 codes decode to:
// facing the camera, the least surprising direction for shading.
inline constexpr glm::vec3 kFallbackNormalView{0.0f, 0.0f, 1.0f};
// The ray through the image centre: what `pixel-view` assumes when no pixel is given.
inline constexpr glm::vec3 kCentralViewRay{0.0f, 0.0f, -1.0f};

struct NormalCodecSpec {
    NormalCodecKind kind = NormalCodecKind::Octahedral;
    int bits = 24; // total bits of the code

    std::string text() const; // "NAME:BITS", parse(text()) == *this
    // Parses "NAME:BITS", or a bare NAME for a codec with one bit count (float32); throws
    // std::invalid_argument naming the input, suggesting the closest name and listing every valid
    // NAME with its BITS. Called once per configuration, not per pixel.
    static NormalCodecSpec parse(const std::string& text);
    friend bool operator==(const NormalCodecSpec&, const NormalCodecSpec&) = default;
};

const char* normalCodecName(NormalCodecKind kind);
std::vector<std::string> normalCodecNames(); // registry order, the CLI names
// Total bit counts a codec supports: 2-component codecs (pixel-view included) 16, 20, 24, 32
// (8/10/12/16 per component); xyz 24, 30, 48; best-fit 24; float32 96.
std::vector<int> supportedBits(NormalCodecKind kind);
std::vector<NormalCodecSpec> allNormalCodecSpecs(); // every name x every supported bits

// Encodes a view-space normal; see the robustness contract above. Throws std::invalid_argument
// only for a spec with unsupported bits (a programming error: parse() never makes one).
// `viewRayView` is the direction from the camera through the pixel (view space, any length, z < 0);
// only `pixel-view` reads it. The default is the central ray, for studies without a camera (and
// there `pixel-view` gives the same codes as `xy-z`).
NormalCode encodeNormal(const NormalCodecSpec& spec, glm::vec3 unitNormalView,
                        glm::vec3 viewRayView = kCentralViewRay);
// Decodes to a unit vector; bits of `code` above spec.bits are ignored. `viewRayView` must be the
// ray given to encodeNormal (only `pixel-view` reads it).
glm::vec3 decodeNormal(const NormalCodecSpec& spec, NormalCode code,
                       glm::vec3 viewRayView = kCentralViewRay);

// The oracle for `best-fit:24`'s table encoder (tests and studies only): the exact per-direction
// search over all 127 major-axis lengths plus naive rounding, a superset of the table encoder's
// two candidates, so never farther from the input (in double). Same robustness contract and code
// layout as encodeNormal({BestFit, 24}, ...); costs 128 candidates, ~7x the table encoder.
NormalCode encodeBestFitBySearch(glm::vec3 unitNormalView);

// Angle between two directions in radians, computed in double as atan2(|a x b|, a . b), which
// stays accurate for tiny angles (acos of a dot product loses ~1e-4 rad near 0). Lengths do not
// matter. This is the metric `octahedral-precise` minimises, so tests must use it as well.
double normalAngleRadians(glm::vec3 a, glm::vec3 b);

// Slack for the final float cast of a decoded direction: each component is rounded with relative
// error 2^-24, which tilts a unit vector by at most ~1e-7 rad; 4e-7 rad leaves a factor of 4.
inline constexpr double kNormalFloatSlackRadians = 4e-7;

// The derived worst-case angle between an input and its decoded direction (quantisation only;
// add kNormalFloatSlackRadians for the float output), for inputs inside
// inNormalErrorBoundRegion(). Pure formula, cheap; throws like encodeNormal for bad bits.
double normalErrorBoundRadians(const NormalCodecSpec& spec);
// Where normalErrorBoundRadians holds: everywhere, except z >= 0 for `xy-z` and `stereographic`,
// z >= (1 - S^2) / (1 + S^2) = -0.519 for `stereographic-scaled` (S = 1.7777) and local z >= 0
// (dot(n, viewRay) <= 0, facing the camera) for `pixel-view`. Outside it a codec clamps by
// design. `unitNormalView` must be finite and non-zero (any length).
bool inNormalErrorBoundRegion(const NormalCodecSpec& spec, glm::vec3 unitNormalView,
                              glm::vec3 viewRayView = kCentralViewRay);

} // namespace gbuffer
