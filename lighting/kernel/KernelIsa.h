// KernelIsa: which implementation of the shading kernel runs, chosen at run time. "scalar" is the
// per-pixel path (lighting/brdf/Brdf.h's evaluateLight lane by lane, GBuffer::decode's arithmetic
// pixel by pixel): the tests' oracle and the baseline a speed-up is measured against in the same
// build. The vector paths are the Highway targets compiled into the binary (VectorTargets.h) that
// this CPU supports; "auto" is the one Highway's dynamic dispatch picks, the widest (AVX3 =
// AVX-512 on the development machine).
//
// A KernelIsa is a small value (a pointer to constant tables); pass it to shadePacket and
// PacketDecoder::decode. There is no global "current ISA": a runner that offers `--isa` resolves
// the name once with byName and hands the value to the stages. Thread-safe.
#pragma once

#include <string>
#include <vector>

namespace lighting::kernel {

struct VectorFunctions; // VectorTargets.h

class KernelIsa {
public:
    static KernelIsa scalar() { return KernelIsa(nullptr); }
    // The widest supported target (Highway's dynamic-dispatch choice).
    static KernelIsa best();
    // "scalar", "auto", or a target name of available() ("ssse3", "sse4", "avx2", "avx3"),
    // case-insensitive. Throws std::invalid_argument naming the valid choices on this machine.
    static KernelIsa byName(const std::string& name);
    // Scalar first, then every compiled target this CPU supports, narrowest to widest.
    static std::vector<KernelIsa> available();

    bool isScalar() const { return mVector == nullptr; }
    // Lower-case name: "scalar", "sse4", "avx2", "avx3", ...
    std::string name() const;
    // Floats per hardware vector: 1 for scalar, 4 (SSE4), 8 (AVX2), 16 (AVX-512).
    int vectorLanes() const;
    const VectorFunctions* vector() const { return mVector; }

    friend bool operator==(const KernelIsa& a, const KernelIsa& b) {
        return a.mVector == b.mVector;
    }

private:
    explicit KernelIsa(const VectorFunctions* vector) : mVector(vector) {}
    const VectorFunctions* mVector;
};

} // namespace lighting::kernel
