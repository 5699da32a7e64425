// libFuzzer target: the sweep-file reader (experiments::readSweepText, JSON and TOML) and the
// expansion into jobs (which validates every job's options). The first byte picks the format:
// odd is TOML. Only SweepError may leave them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "experiments/sweep/SweepFile.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0)
        return 0;
    const bool toml = data[0] & 1;
    const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
    try {
        const experiments::SweepSpec spec = experiments::readSweepText(text, "fuzz", toml);
        (void)experiments::expandSweep(spec);
        if (spec.source.contains("quick"))
            (void)experiments::expandSweep(experiments::applyQuick(spec));
    } catch (const experiments::SweepError&) {
    }
    return 0;
}
