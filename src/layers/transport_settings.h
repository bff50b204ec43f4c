#pragma once
// How light is transported through a stack, shared by both of lamina's estimators, the
// goniophotometer (simulator/) and the per-query random walk (randomwalk/): how rough interfaces
// scatter, how a rough dielectric masks the light it refracts, and the safety cap on a path's
// events. compile_stack (layers/compiled_stack.h) reads it. Each setting is declared once, in
// `fields` (core/setting.h says how settings travel).

#include "core/setting.h"
#include "physics/transmission_masking.h"

#include <array>

namespace lamina {

/// How a rough interface treats the light its first facet does not let escape: `single`
/// (docs/physics.md §3: single-scattering microfacet theory, the energy is lost to the microsurface
/// and reported as lost_microsurface) or `multiple` (the microsurface random walk of Heitz et al.
/// 2016, physics/microsurface_walk.h: nothing is lost).
enum class Microsurface { Single, Multiple };
inline constexpr std::array<EnumName<Microsurface>, 2> enum_names(Microsurface) {
    return {{{Microsurface::Single, "single",
              "single scattering, the masked energy reported as lost_microsurface"},
             {Microsurface::Multiple, "multiple", "the random walk of Heitz et al. 2016"}}};
}
inline const char* enum_noun(Microsurface) {
    return "a microsurface model";
}

struct TransportSettings {
    Microsurface microsurface = Microsurface::Multiple;
    /// Facets a microsurface walk (Microsurface::Multiple) may meet before its particle is given up
    /// (reported as lost_microsurface); walks of a few facets are the rule, a hundred is never
    /// reached in practice. 1 keeps only the first order, the single-scattering interface (a test
    /// of the walk).
    int max_microsurface_order = 100;
    /// The refraction masking of the single-scattering rough dielectrics (physics/microfacet.h):
    /// the Smith microsurface's B(1 + Λi, 1 + Λo) or pbrt-v4's 1/(1 + Λi + Λo). The microsurface
    /// walk has its own, which is the Smith one.
    TransmissionMasking transmission_masking = TransmissionMasking::Smith;
    /// Safety cap on interface and scattering events per particle (or walk); flux still travelling
    /// then is reported as cut_off (docs/physics.md §5: must be ≈ 0).
    int max_events = 10'000;
    /// Follow the particles' polarization (docs/physics.md §8): every event applies its Mueller
    /// matrix to the particle's Stokes vector instead of the unpolarized Fresnel factors; the
    /// tables are those of unpolarized incident light, exact for it.
    bool polarization = true;

    // The cache key leaves out the 2019 reference's values (key_unsaid), so a bpb19 reference
    // keeps the key it had before the other values existed.
    template <typename Self, typename Visit>
    static void fields(Self& s, Visit&& visit) {
        using Key = SettingInfo::Key;
        visit({.name = "microsurface",
               .help = "Rough interfaces: single (single scattering, the masked energy reported as "
                       "lost_microsurface) or multiple (Heitz et al. 2016 random walk)",
               .key_unsaid = "single"},
              s.microsurface);
        visit({.name = "max_microsurface_order",
               .help = "Facets a microsurface walk may meet (microsurface multiple)",
               .min = 1,
               .max = 1e6,
               .key_unsaid = "100"},
              s.max_microsurface_order);
        // The cache key writes the masking in its fixed part, where it changes the table.
        visit(
            {.name = "transmission_masking",
             .help = "Masking of light refracted by a rough dielectric (single scattering): smith "
                     "(the Smith microsurface's B(1+Λi, 1+Λo)) or pbrt (1/(1+Λi+Λo), as pbrt-v4)",
             .key = Key::Fixed},
            s.transmission_masking);
        visit({.name = "max_events",
               .help = "Safety cap on events per particle",
               .min = 1,
               .max = 1e9,
               .key_unsaid = "10000"},
              s.max_events);
        visit(
            {.name = "polarization",
             .help = "Polarized light: Stokes vectors through Mueller matrices at every event (on) "
                     "or the unpolarized Fresnel factors (off)",
             .key_unsaid = "off"},
            s.polarization);
    }
};

/// The two references lamina names (docs/physics.md §8). `exact`, the defaults: polarized light
/// and rough interfaces that scatter on their whole microsurface, nothing rounded off. `bpb19`:
/// the reference of Bati, Pacanowski and Barla 2019 (unpolarized Fresnel factors at every event,
/// single scattering on the microsurfaces, the masked energy lost), to reproduce their study.
enum class ReferencePhysics { Exact, Bpb19 };
inline constexpr std::array<EnumName<ReferencePhysics>, 2> enum_names(ReferencePhysics) {
    return {{{ReferencePhysics::Exact, "exact",
              "polarized light, microsurface multiple scattering (the defaults)"},
             {ReferencePhysics::Bpb19, "bpb19",
              "the 2019 study's reference: polarization off, microsurface single"}}};
}
inline const char* enum_noun(ReferencePhysics) {
    return "a reference physics";
}

/// Sets the settings `physics` names (the others are left as they are).
inline void apply_physics(ReferencePhysics physics, TransportSettings& t) {
    const bool exact = physics == ReferencePhysics::Exact;
    t.polarization = exact;
    t.microsurface = exact ? Microsurface::Multiple : Microsurface::Single;
}

/// The named reference `t` is ("exact", "bpb19"), or "custom" for the two mixed.
inline const char* physics_name(const TransportSettings& t) {
    if (t.polarization && t.microsurface == Microsurface::Multiple) return "exact";
    if (!t.polarization && t.microsurface == Microsurface::Single) return "bpb19";
    return "custom";
}

}  // namespace lamina
