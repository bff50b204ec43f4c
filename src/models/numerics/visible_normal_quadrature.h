#pragma once
// Quadrature over the normals visible from a direction (Heitz 2018, "Sampling the GGX distribution
// of visible normals", JCGT 7(4)) for integrands that step where the facet's outgoing direction
// crosses a cosine (total internal reflection, the edge of a coat's exit cone): the radius of
// Heitz's sampling disk is split at the steps per φ node (Chandrupatla's bracketed root), each
// piece integrated by Gauss–Legendre in u = √(1 − r). The rule is lamina-1's header library's
// (include/lamina1/quadrature.h, which documents it); it takes any GGX type with a
// visible_normal_frame, so lamina's tables (GGX of physics/microfacet.h) and lamina-1 share it.

#include "lamina1/quadrature.h"

namespace lamina {

using lamina1::bracketed_root;
using lamina1::Crossing;
using lamina1::integrate_visible_split;

}  // namespace lamina
