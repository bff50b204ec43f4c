// Explicit instantiations: every physics template compiles in float and double.
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"
#include "physics/microfacet.h"
#include "physics/phase.h"
#include "physics/sampling.h"

namespace lamina {
template struct GGX<float>;
template struct GGX<double>;
template struct DielectricInterface<float>;
template struct DielectricInterface<double>;
template struct ConductorInterface<float>;
template struct ConductorInterface<double>;
template struct LambertianInterface<float>;
template struct LambertianInterface<double>;
}  // namespace lamina
