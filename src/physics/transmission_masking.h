#pragma once
// How a rough dielectric masks the light it refracts: a setting of the reference
// (layers/transport_settings.h) and an option of the models that tabulate a coat's transmittance;
// physics/microfacet.h and physics/dielectric.h apply it.

#include "core/enum_names.h"

#include <array>

namespace lamina {

/// How a rough dielectric masks and shadows the light it *refracts* (its reflection lobe always
/// has the height-correlated 1/(1 + Λi + Λo) of Heitz 2014, Eq. 99).
enum class TransmissionMasking {
    /// The Smith microsurface's own height-correlated form for a pair on opposite sides,
    /// B(1 + Λi, 1 + Λo) (smith_refraction_escape): the default.
    Smith,
    /// 1/(1 + Λi + Λo) as for reflection: Walter et al. 2007 with the height-correlated G2, as
    /// pbrt-v4 uses it; kept for comparisons with those renderers.
    Pbrt,
};
inline constexpr std::array<EnumName<TransmissionMasking>, 2> enum_names(TransmissionMasking) {
    return {{{TransmissionMasking::Smith, "smith", "the Smith microsurface's B(1 + Λi, 1 + Λo)"},
             {TransmissionMasking::Pbrt, "pbrt", "1/(1 + Λi + Λo), as pbrt-v4"}}};
}
inline const char* enum_noun(TransmissionMasking) {
    return "a transmission masking";
}

}  // namespace lamina
