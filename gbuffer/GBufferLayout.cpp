#include "gbuffer/GBufferLayout.h"

#include <stdexcept>

namespace gbuffer {

const char* channelName(Channel channel) {
    switch (channel) {
    case Channel::Depth: return "depth";
    case Channel::Normal: return "normal";
    case Channel::Albedo: return "albedo";
    case Channel::Specular: return "specular";
    }
    return "?";
}

bool GBufferLayout::has(Channel channel) const {
    for (const ChannelDesc& c : channels)
        if (c.channel == channel) return true;
    return false;
}

const ChannelDesc& GBufferLayout::channel(Channel channel) const {
    for (const ChannelDesc& c : channels)
        if (c.channel == channel) return c;
    throw std::out_of_range("G-buffer layout '" + name + "' has no " + channelName(channel) +
                            " channel");
}

double GBufferLayout::bytesPerPixel() const {
    int bits = 0;
    for (const ChannelDesc& c : channels)
        for (const PlaneDesc& p : c.planes) bits += p.bits;
    return bits / 8.0;
}

GBufferLayout GBufferLayout::reference() {
    GBufferLayout layout;
    layout.name = "reference";
    layout.channels = {
        {Channel::Depth, "f32-reversed", {{"Z", "f32", 32}}, "position is reconstructed from depth"},
        {Channel::Normal,
         "float32",
         {{"N.X", "f32", 32}, {"N.Y", "f32", 32}, {"N.Z", "f32", 32}},
         "view-space normal for diffuse and specular terms"},
        {Channel::Albedo,
         "float32",
         {{"albedo.R", "f32", 32}, {"albedo.G", "f32", 32}, {"albedo.B", "f32", 32}},
         "diffuse colour"},
        {Channel::Specular,
         "float32",
         {{"specular.intensity", "f32", 32}, {"specular.power", "f32", 32}},
         "Blinn-Phong specular intensity and exponent"},
    };
    return layout;
}

}  // namespace gbuffer
