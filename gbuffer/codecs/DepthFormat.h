// DepthFormat: how the G-buffer stores depth, and the two ways of getting view-space position
// back from it, as pure functions (the depth study measures them without a G-buffer).
//
// Conventions:
// - View depth d = -z_view, in metres, > 0 in front of the camera (view space looks down -Z).
// - NDC depth is "zero to one" (clip 0 <= z <= w). Standard Z: near -> 0, far -> 1. Reversed Z:
//   near -> 1, far -> 0. With an infinite far plane, d -> infinity maps to 1 (standard) or 0
//   (reversed); the formulas are below in DepthProjection.
// - The rasterizer always tests float NDC depth. A format is what the G-buffer keeps of it:
//     f32            float NDC depth, standard Z (the precision collapse this study shows)
//     f32-reversed   float NDC depth, reversed Z (the default: near-uniform relative precision)
//     unorm24        24-bit fixed point of standard NDC depth (D24S8 hardware depth)
//     unorm16        16-bit fixed point of standard NDC depth
//     f16-linear     IEEE half of the linear view depth in metres (S.T.A.L.K.E.R. Clear Sky)
//   Each may be suffixed ":infinite" for an infinite far plane, e.g. "f32-reversed:infinite".
// - A code is the format's bit pattern in the low bits of a uint32_t. The clear code (the far
//   plane's value) means "no surface"; a covered pixel never encodes to it (clamped one step
//   nearer), so quantisation cannot turn geometry into background.
// - Every function is pure and thread-safe; parse() throws std::invalid_argument listing the
//   valid names. Readers of a depth plane go through DepthDecoder (below), which composes them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gbuffer/visibility/CameraView.h"

namespace gbuffer {

enum class DepthFormatKind { F32, F32Reversed, Unorm24, Unorm16, F16Linear };

struct DepthFormatSpec {
    DepthFormatKind kind = DepthFormatKind::F32Reversed;
    bool infiniteFar = false;

    std::string text() const; // "NAME" or "NAME:infinite"; parse(text()) == *this
    static DepthFormatSpec parse(const std::string& text);
    int bits() const; // storage bits per pixel: 32, 32, 24, 16, 16
    // The working depth the rasterizer tests: reversed for f32-reversed and f16-linear (whose
    // stored value does not depend on it), standard for the others (reversed Z gains nothing in
    // fixed point, and hardware D24/D16 are standard).
    DepthConvention convention() const;
    friend bool operator==(const DepthFormatSpec&, const DepthFormatSpec&) = default;
};

const char* depthFormatName(DepthFormatKind kind);
std::vector<std::string> depthFormatNames();        // the CLI names, finite far plane
std::vector<DepthFormatSpec> allDepthFormatSpecs(); // every name, finite and infinite

// The projection's depth mapping (perspective, zero-to-one). Finite standard:
// z = f (d - n) / (d (f - n)); infinite standard: z = 1 - n / d; reversed: 1 - those.
struct DepthProjection {
    double nearMetres = 0.1;
    double farMetres = 100.0; // ignored when infiniteFar
    bool infiniteFar = false;
    bool reversed = true;

    static DepthProjection of(const CameraView& view);
    double ndcFromViewDepth(double viewDepthMetres) const;
    double viewDepthFromNdc(double depthNdc) const;
    // The same inverse evaluated in float, as a shader reconstructing linear depth would, in the
    // cancellation-free form n f / (n + w (f - n)), w = distance of z from the far plane's value:
    // within 8 float roundings of the double inverse for every z (tests/gbuffer/depth_format_test).
    float viewDepthFromNdcFloat(float depthNdc) const;
    float clearDepthNdc() const { return reversed ? 0.0f : 1.0f; }
};

// Code of NDC depth `depthNdc` (as the rasterizer computed it, in `projection`'s convention).
uint32_t encodeDepth(const DepthFormatSpec& format, const DepthProjection& projection,
                     float depthNdc);
uint32_t clearDepthCode(const DepthFormatSpec& format, const DepthProjection& projection);
// NDC depth the code stands for, in `projection`'s convention (what depth-reading code sees).
float decodeDepthNdc(const DepthFormatSpec& format, const DepthProjection& projection,
                     uint32_t code);
// Linear view depth (metres) the code stands for, evaluated in float as a shader would: direct
// for f16-linear, viewDepthFromNdcFloat of the NDC value otherwise.
float decodeViewDepth(const DepthFormatSpec& format, const DepthProjection& projection,
                      uint32_t code);

// The two reconstruction methods of the thesis (section 3.6).
enum class PositionMethod {
    InverseProjection, // (ndc.x, ndc.y, depthNdc, 1) times the inverse projection, divided by w
    ViewRay,           // linear view depth times the view ray through the pixel (z = -1)
};
const char* positionMethodName(PositionMethod method); // "inverse-projection", "view-ray"
PositionMethod parsePositionMethod(const std::string& text);

glm::vec3 positionByInverseProjection(const CameraView& view, glm::vec2 ndc, float depthNdc);
glm::vec3 positionByViewRay(const CameraView& view, glm::vec2 ndc, float viewDepthMetres);
// The view ray through `ndc` with z = -1 (also the ray `pixel-view` normals are built on).
glm::vec3 viewRayOfNdc(const CameraView& view, glm::vec2 ndc);

// DepthDecoder: a layout's depth as every reader sees it, and the one implementation of position
// from depth (GBuffer::decode, the tile and cluster bounds of the culling stages, forward
// shading's fragments). Built from a layout's depth format and position method
// (GBufferLayout::depthDecoder) and the frame's view.
// A depth plane holds the rasterizer's float NDC depth rounded through the format
// (storedDepthNdc: what GBuffer::quantiseDepth writes), so reading needs no decoding of codes;
// position comes from that value by the layout's method:
//   inverse-projection  positionByInverseProjection(view, ndc, depth)
//   view-ray            positionByViewRay(view, ndc, projection.viewDepthFromNdcFloat(depth))
// Forward stages keep no G-buffer: their depth is the rasterizer's own float depth, i.e. the
// lossless layout's (GBufferLayout::lossless), and they read it with that layout's decoder, so a
// fragment's position is bitwise what GBuffer::decode gives on the lossless layout.
// Cheap to copy (holds a copy of the view); const and thread-safe.
class DepthDecoder {
public:
    DepthDecoder(const DepthFormatSpec& format, PositionMethod method, const CameraView& view);

    const CameraView& view() const { return mView; }
    // True when the format keeps the rasterizer's float depth unchanged (f32, f32-reversed).
    bool lossless() const;

    // What the format keeps of the rasterizer's NDC depth `depthNdc` of a covered pixel: its code
    // decoded, one float step nearer than the clear value when the rounding would make it read as
    // background (e.g. f16-linear rounding past the far plane). The clear value itself is kept.
    float storedDepthNdc(float depthNdc) const;
    // View-space position of pixel (x, y) whose depth plane holds `storedDepthNdc` (covered), by
    // the layout's method.
    glm::vec3 positionView(int x, int y, float storedDepthNdc) const;
    // Positive view depth -positionView(x, y, storedDepthNdc).z, metres.
    float viewDepthMetres(int x, int y, float storedDepthNdc) const {
        return -positionView(x, y, storedDepthNdc).z;
    }

private:
    DepthFormatSpec mFormat;
    PositionMethod mMethod;
    CameraView mView;
    DepthProjection mProjection;
};

} // namespace gbuffer
