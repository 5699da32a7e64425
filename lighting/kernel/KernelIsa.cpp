#include "lighting/kernel/KernelIsa.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "lighting/kernel/VectorTargets.h"

namespace lighting::kernel {

namespace {

std::string lowerCase(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return text;
}

} // namespace

KernelIsa KernelIsa::best() {
    return KernelIsa(dispatchedVectorTarget());
}

std::vector<KernelIsa> KernelIsa::available() {
    std::vector<KernelIsa> isas{scalar()};
    for (const VectorFunctions* target : supportedVectorTargets())
        isas.push_back(KernelIsa(target));
    return isas;
}

KernelIsa KernelIsa::byName(const std::string& name) {
    const std::string wanted = lowerCase(name);
    if (wanted == "auto")
        return best();
    std::string valid = "auto";
    for (const KernelIsa& isa : available()) {
        if (isa.name() == wanted)
            return isa;
        valid += ", " + isa.name();
    }
    throw std::invalid_argument("unknown instruction set '" + name +
                                "' for the shading kernel; "
                                "valid on this machine: " +
                                valid);
}

std::string KernelIsa::name() const {
    return mVector ? lowerCase(mVector->name) : "scalar";
}

int KernelIsa::vectorLanes() const {
    return mVector ? mVector->vectorLanes : 1;
}

} // namespace lighting::kernel
