#pragma once
// The axes of a table f(c, α, η) that steps at the critical cosine of total internal reflection
// (a rough interface's transmittance, the fraction of a lobe of light that leaves through an
// interface), and its interpolation: lamina-1's header library holds them
// (include/lamina1/table_lookups.h, CriticalCosineAxes, which documents the axes, the control
// variate and the layout), and lamina's tables use the same code.

#include "lamina1/table_lookups.h"

namespace lamina {

using lamina1::critical_cosine;
using lamina1::CriticalCosineAxes;

}  // namespace lamina
