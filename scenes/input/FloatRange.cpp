// FloatRange.h: the double -> float range check and its message.
#include "scenes/input/FloatRange.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace scenes {

std::string numberText(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value);
    return text;
}

std::string floatRangeProblem(double value) {
    if (std::isnan(value))
        return "is NaN";
    if (std::isinf(value))
        return "is infinite";
    // Compared in double, never by converting: a double -> float conversion out of range is
    // undefined behaviour (UBSan's float-cast-overflow). The few values within half an ulp past
    // FLT_MAX that would round down to it are refused too.
    if (std::abs(value) > double(std::numeric_limits<float>::max()))
        return numberText(value) + " is beyond float's range (largest " +
               numberText(double(std::numeric_limits<float>::max())) + ")";
    return "";
}

} // namespace scenes
