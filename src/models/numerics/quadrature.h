#pragma once
// Gauss–Legendre rules and hemispherical integrals split at a critical cosine: lamina-1's header
// library holds them (include/lamina1/quadrature.h, where their sources are cited), and lamina's
// models and tables use the same functions.

#include "lamina1/quadrature.h"

namespace lamina {

using lamina1::gauss_legendre;
using lamina1::integrate_split01;
using lamina1::QuadratureRule;

}  // namespace lamina
