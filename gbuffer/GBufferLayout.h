// GBufferLayout: what the G-buffer stores, as data (Falcor-style channel table): one row per
// channel with its encoding and planes (structure of arrays), and the reason it is there.
// Consumers declare the channels they need; only those are allocated.
//
// This first version knows the reference layout (float32 everything). Encodings and derived
// layouts extend the table; readers always go through GBuffer::decode, never the raw planes.
#pragma once

#include <string>
#include <vector>

namespace gbuffer {

enum class Channel { Depth, Normal, Albedo, Specular };

const char* channelName(Channel channel);

struct PlaneDesc {
    std::string name;    // EXR-style channel name, e.g. "N.X"
    std::string format;  // storage format, e.g. "f32"
    int bits = 32;
};

struct ChannelDesc {
    Channel channel;
    std::string encoding;  // e.g. "float32", later "octahedral:24"
    std::vector<PlaneDesc> planes;
    std::string reason;  // why the plane is there (printed by --explain-layout)
};

struct GBufferLayout {
    std::string name;
    std::vector<ChannelDesc> channels;

    bool has(Channel channel) const;
    const ChannelDesc& channel(Channel channel) const;  // throws std::out_of_range naming it
    double bytesPerPixel() const;

    // float32 reversed-Z depth (NDC z), float32 view-space normal, float32 albedo RGB, float32 specular
    // (intensity, power): lossless with respect to what the rasterizer computes.
    static GBufferLayout reference();
};

}  // namespace gbuffer
