// FloatRange: the one check for a number read as a double (JSON and glTF parsers read doubles)
// that is stored or used as a float (issue 32, class 1). 1e39 is finite as a double and +Inf as
// a float; stored unchecked it turned into an all-black image, a "scene has no geometry" error or
// a texture silently dropped. Every double -> float store of the loaders goes through
// floatRangeProblem (through each loader's checked narrowing, which adds the field's path to the
// message); derived quantities (composed transforms, bounds, radiance, view matrices) are checked
// in float afterwards by scenes::validate (Scene.h).
//
// Problems are returned as text without the field ("1e+39 is beyond float's range (largest
// 3.40282e+38)"): each reader puts them into its own error with the file and the field.
// Pure functions, thread-safe. Includes nothing of the project.
#pragma once

#include <string>

namespace scenes {

// "" when value is finite and rounds to a finite float; else why not (NaN, infinite, or beyond
// float's largest value 3.40282e+38 in magnitude). Values below float's smallest magnitude
// round to 0 or a denormal, as a float store does: that loses no order of magnitude that
// matters to a renderer and is not refused here (a range or plane that must be positive is
// checked after narrowing).
std::string floatRangeProblem(double value);

// The shortest text of a number for messages: 1e+39, 0.5, -3.40282e+38.
std::string numberText(double value);

} // namespace scenes
