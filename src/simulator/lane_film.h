// A thin film's reflection on SIMD lanes (docs/physics.md §9; simulator/scalar_particle.h
// film_event): the functor that the conductor event and walk (physics/conductor.h,
// microsurface_walk.h) call at a facet's cosine in place of the bare conductor's Fresnel terms
// (simulator/lane_conductor.h), each lane with its own film and thickness. The SIMD kernel
// (simulator/lane_events.h FilmConductorEvent) and the lane tests use it. A per-target header
// (core/lane_hwy.h); physics/thin_film.h must already be included as an ordinary header.

#include "core/lane_complex.h"
#include "core/lane_hwy.h"
#include "physics/polarization.h"
#include "physics/thin_film_airy.h"

#include <algorithm>
#include <bit>
#include <complex>
#include <cstdint>

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_SIMULATOR_LANE_FILM_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_SIMULATOR_LANE_FILM_H
#undef LAMINA_SIMULATOR_LANE_FILM_H
#else
#define LAMINA_SIMULATOR_LANE_FILM_H
#endif

LAMINA_LANE_BEGIN

// The film's reflection at each lane's facet cosine and film thickness: what FilmOptics::
// reflection_from_above (physics/thin_film.h, in double, what the scalar kernel's film_event
// evaluates) gives, here the lane templates of physics/thin_film_airy.h on vectors of doubles
// (half a float vector at a time: a film's phase and its near-cancelling sums want double). The
// lanes within twice reflection_from_above's band of the film's critical angle, and those whose
// sums are not finite (grazing on an index-matched boundary, an exit's normal wave number 0), are
// evaluated by reflection_from_above itself, which sorts them out. It
// stands where the bare conductor's ConductorFresnel and ConductorMueller stand in the conductor
// event and walk.
struct FilmReflection {
    const FilmOptics* const* film;  // per lane: the layer's, or a spectral lane's stack's
    const double* thickness_nm;     // per lane
    // The Mueller matrices (a, b, c, d) per channel into e[c][k] on the lanes of `active`; the
    // others keep what e holds.
    HWY_NOINLINE void Evaluate(VF cos_theta, MF active, float (*e)[4][kMaxLanes]) const {
        const DF df;
        const DD dd;
        const hn::Rebind<float, DD> dfh;  // the floats of half a vector
        const std::size_t n_lanes = hn::Lanes(df), n_half = hn::Lanes(dd);
        HWY_ALIGN float cos_l[kMaxLanes];
        HWY_ALIGN double mu[kMaxLanes], above[kMaxLanes], eta_film[2][kMaxLanes],
            eta_below[3][2][kMaxLanes], thickness[kMaxLanes], lambda[3][kMaxLanes];
        HWY_ALIGN float out[3][4][kMaxLanes];
        hn::Store(cos_theta, df, cos_l);
        const std::uint64_t active_bits = MaskBits(active);
        for (std::size_t l = 0; l < n_lanes; ++l) {
            const FilmOptics& f = *film[l];
            mu[l] = std::min(std::max(double(cos_l[l]), 0.0), 1.0);
            above[l] = f.eta_above;
            thickness[l] = thickness_nm[l];
            eta_film[0][l] = f.eta_film.real();
            eta_film[1][l] = f.eta_film.imag();
            for (int c = 0; c < 3; ++c) {
                eta_below[c][0][l] = f.eta_below[c].real();
                eta_below[c][1][l] = f.eta_below[c].imag();
                lambda[c][l] = f.wavelength_nm[c];
            }
        }
        std::uint64_t scalar_bits = 0;
        const std::uint64_t half_bits = n_half >= 64 ? ~0ull : (1ull << n_half) - 1;
        for (std::size_t base = 0; base < n_lanes; base += n_half) {
            if ((active_bits >> base & half_bits) == 0) continue;
            // The indices relative to the medium above and the thickness in waves, as
            // FilmOptics::reflection_from_above forms them.
            const VD m = hn::Load(dd, mu + base);
            const VD sin2 = hn::NegMulAdd(m, m, hn::Set(dd, 1.0));
            const VD eta_above = hn::Load(dd, above + base);
            const LaneComplex<VD> ef{hn::Div(hn::Load(dd, eta_film[0] + base), eta_above),
                                     hn::Div(hn::Load(dd, eta_film[1] + base), eta_above)};
            // Twice thin_film.h's band: the lanes near its edge are left to it.
            MD special = near_film_critical<VD, VecLaneD>(ef, sin2, 2 * kFilmNearCritical);
            const VD thickness_above = hn::Mul(hn::Load(dd, thickness + base), eta_above);
            const LaneFilmTop<VD> top = film_top<VD, VecLaneD>(m, sin2, ef);
            for (int c = 0; c < 3; ++c) {
                const LaneComplex<VD> ex{hn::Div(hn::Load(dd, eta_below[c][0] + base), eta_above),
                                         hn::Div(hn::Load(dd, eta_below[c][1] + base), eta_above)};
                const VD waves = hn::Div(thickness_above, hn::Load(dd, lambda[c] + base));
                const InterfaceMueller<VD> r =
                    film_reflection_mueller<VD, VecLaneD>(top, ef, sin2, ex, waves);
                const VD sum = hn::Add(hn::Add(r.a, r.b), hn::Add(r.c, r.d));
                special = hn::Or(special, hn::Not(hn::IsFinite(sum)));
                hn::Store(hn::DemoteTo(dfh, r.a), dfh, out[c][0] + base);
                hn::Store(hn::DemoteTo(dfh, r.b), dfh, out[c][1] + base);
                hn::Store(hn::DemoteTo(dfh, r.c), dfh, out[c][2] + base);
                hn::Store(hn::DemoteTo(dfh, r.d), dfh, out[c][3] + base);
            }
            std::uint8_t bytes[8] = {};
            hn::StoreMaskBits(dd, special, bytes);
            std::uint64_t bits = 0;
            for (std::size_t i = 0; i < (n_half + 7) / 8; ++i)
                bits |= std::uint64_t(bytes[i]) << (8 * i);
            scalar_bits |= bits << base;
        }
        for (std::uint64_t bits = active_bits; bits != 0; bits &= bits - 1) {
            const std::size_t l = std::size_t(std::countr_zero(bits));
            if ((scalar_bits >> l & 1) != 0) {
                const auto md = film[l]->reflection_from_above(double(cos_l[l]), thickness_nm[l]);
                for (int c = 0; c < 3; ++c) {
                    e[c][0][l] = float(md[std::size_t(c)].a);
                    e[c][1][l] = float(md[std::size_t(c)].b);
                    e[c][2][l] = float(md[std::size_t(c)].c);
                    e[c][3][l] = float(md[std::size_t(c)].d);
                }
                continue;
            }
            for (int c = 0; c < 3; ++c)
                for (int k = 0; k < 4; ++k)
                    e[c][k][l] = out[c][k][l];
        }
    }
    // The reflectance per channel (unpolarized), as film_event's `reflectance`, on the lanes of
    // `active` (reflection_on_lanes: the others, whose values no event uses, are 1).
    HWY_NOINLINE void operator()(VF cos_theta, VF* factors, MF active) const {
        const DF df;
        HWY_ALIGN float e[3][4][kMaxLanes];
        for (int c = 0; c < 3; ++c)
            std::fill(e[c][0], e[c][0] + hn::Lanes(df), 1.f);
        Evaluate(cos_theta, active, e);
        for (int c = 0; c < 3; ++c)
            factors[c] = hn::Load(df, e[c][0]);
    }
    // The reflection Mueller matrices per channel (polarized), as film_event's `mueller`, on the
    // lanes of `active` (the others get the identity).
    HWY_NOINLINE void operator()(VF cos_theta, InterfaceMueller<VF>* m, MF active) const {
        const DF df;
        HWY_ALIGN float e[3][4][kMaxLanes];
        for (int c = 0; c < 3; ++c) {
            std::fill(e[c][0], e[c][0] + hn::Lanes(df), 1.f);
            std::fill(e[c][1], e[c][1] + hn::Lanes(df), 0.f);
            std::fill(e[c][2], e[c][2] + hn::Lanes(df), 1.f);
            std::fill(e[c][3], e[c][3] + hn::Lanes(df), 0.f);
        }
        Evaluate(cos_theta, active, e);
        for (int c = 0; c < 3; ++c)
            m[c] = {hn::Load(df, e[c][0]), hn::Load(df, e[c][1]), hn::Load(df, e[c][2]),
                    hn::Load(df, e[c][3])};
    }
};

LAMINA_LANE_END

#endif  // LAMINA_SIMULATOR_LANE_FILM_H
