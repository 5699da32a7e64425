// MessageText.h: a strict UTF-8 decoder (no overlong forms, no surrogates, nothing past
// U+10FFFF) that copies what is printable and escapes the rest.
#include "scenes/input/MessageText.h"

#include <cstdint>
#include <cstdio>

namespace scenes {

namespace {

void appendByteEscape(std::string& out, unsigned char byte) {
    switch (byte) {
    case '\n':
        out += "\\n";
        return;
    case '\r':
        out += "\\r";
        return;
    case '\t':
        out += "\\t";
        return;
    default:
        char text[8];
        std::snprintf(text, sizeof text, "\\x%02x", unsigned(byte));
        out += text;
    }
}

// The length of the valid UTF-8 sequence at text[i] and its code point, or 0 when the bytes there
// do not start one.
size_t decodeUtf8(std::string_view text, size_t i, uint32_t* codePoint) {
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char lead = byte(i);
    size_t length;
    uint32_t value, minimum;
    if (lead >= 0xC2 && lead <= 0xDF) {
        length = 2, value = lead & 0x1Fu, minimum = 0x80;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
        length = 3, value = lead & 0x0Fu, minimum = 0x800;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
        length = 4, value = lead & 0x07u, minimum = 0x10000;
    } else {
        return 0; // ASCII is handled by the caller; 0x80..0xC1 and 0xF5..0xFF never lead
    }
    if (i + length > text.size())
        return 0;
    for (size_t k = 1; k < length; ++k) {
        if ((byte(i + k) & 0xC0u) != 0x80u)
            return 0;
        value = (value << 6) | (byte(i + k) & 0x3Fu);
    }
    if (value < minimum || value > 0x10FFFF || (value >= 0xD800 && value <= 0xDFFF))
        return 0;
    *codePoint = value;
    return length;
}

bool isInvisibleControl(uint32_t codePoint) {
    return (codePoint >= 0x80 && codePoint <= 0x9F) ||
           (codePoint >= 0x202A && codePoint <= 0x202E) ||
           (codePoint >= 0x2066 && codePoint <= 0x2069);
}

} // namespace

std::string escapeControlCharacters(std::string_view text, LineBreaks lineBreaks) {
    std::string out;
    out.reserve(text.size());
    size_t i = 0;
    while (i < text.size()) {
        const auto byte = static_cast<unsigned char>(text[i]);
        if (byte < 0x80) {
            const bool keep =
                lineBreaks == LineBreaks::Keep && (byte == '\n' || byte == '\r' || byte == '\t');
            if ((byte < 0x20 || byte == 0x7F) && !keep)
                appendByteEscape(out, byte);
            else
                out += char(byte);
            ++i;
            continue;
        }
        uint32_t codePoint = 0;
        const size_t length = decodeUtf8(text, i, &codePoint);
        if (length == 0) {
            appendByteEscape(out, byte);
            ++i;
        } else if (isInvisibleControl(codePoint)) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(codePoint));
            out += escaped;
            i += length;
        } else {
            out.append(text.substr(i, length));
            i += length;
        }
    }
    return out;
}

} // namespace scenes
