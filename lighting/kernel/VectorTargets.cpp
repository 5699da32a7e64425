// The per-target translation unit of the kernel: hwy/foreach_target.h compiles this file once per
// instruction set Highway builds (VectorTargets.h lists them), each time with the target's code
// generation attributes, and the HWY_ONCE part below collects one VectorFunctions per target.
// Nothing here is included elsewhere: the per-target code lives in the *-inl.h files.
//
// Scalable-vector targets (SVE, RVV) are disabled: the kernel keeps a packet as an array of
// fixed-size vectors, which sizeless SVE types cannot form. x86 and NEON are unaffected.
#define HWY_DISABLED_TARGETS (HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)

#include "lighting/kernel/VectorTargets.h"

#include <stdexcept>
#include <string>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "lighting/kernel/VectorTargets.cpp"
#include <hwy/foreach_target.h> // must come before highway.h

#include <hwy/highway.h>

#include "lighting/kernel/LightKernel-inl.h"
#include "lighting/kernel/PacketDecode-inl.h"
#include "lighting/kernel/SplitLightKernel-inl.h"

HWY_BEFORE_NAMESPACE();
namespace lighting::kernel::HWY_NAMESPACE {

const VectorFunctions* vectorFunctions() {
    static const VectorFunctions functions{HWY_TARGET,           hwy::TargetName(HWY_TARGET),
                                           int(kLanesPerVector), &shadePacketVector,
                                           &decodePacketVector,  &powArrayVector,
                                           &shadeSplitVector,    &shadowVisibilityVector};
    return &functions;
}

} // namespace lighting::kernel::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace lighting::kernel {

HWY_EXPORT(vectorFunctions);

namespace {

// The entry of the HWY_EXPORT table for one target, found the way hwy::ChosenTarget::GetIndex
// finds the dispatched one (HWY_CHOSEN_TARGET_SHIFT maps a target bit to its slot), so no global
// Highway state is touched. Each entry reports its own target, which is checked.
const VectorFunctions* functionsOfTarget(int64_t target) {
    const size_t index =
        hwy::Num0BitsBelowLS1Bit_Nonzero64(uint64_t(HWY_CHOSEN_TARGET_SHIFT(target)));
    const auto entry = HWY_DISPATCH_TABLE(vectorFunctions)[index];
    const VectorFunctions* functions = entry ? entry() : nullptr;
    if (!functions || functions->target != target)
        throw std::logic_error(std::string("shading kernel: no table entry for Highway target ") +
                               hwy::TargetName(target));
    return functions;
}

} // namespace

const std::vector<const VectorFunctions*>& supportedVectorTargets() {
    static const std::vector<const VectorFunctions*> targets = [] {
        std::vector<const VectorFunctions*> list;
        // Highway's target bits are ordered best first; list narrowest first.
        for (int64_t target : hwy::SupportedAndGeneratedTargets())
            list.insert(list.begin(), functionsOfTarget(target));
        return list;
    }();
    return targets;
}

const VectorFunctions* dispatchedVectorTarget() {
    static const VectorFunctions* const dispatched = HWY_DYNAMIC_DISPATCH(vectorFunctions)();
    return dispatched;
}

} // namespace lighting::kernel
#endif // HWY_ONCE
