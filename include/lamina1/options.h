#pragma once
// lamina-1's inputs: the layers (one dielectric coat with an optional medium over a Lambertian,
// conductor or dielectric base) and the model's choices. Every approximation of lamina-1 is one
// of these choices; the defaults are the model (lamina's docs/models.md, "lamina-1", derives each
// and measures the others).

#include "lamina1/math.h"
#include "lamina1/physics.h"

namespace lamina1 {

/// The base under the coat.
enum class Base { Lambertian, Conductor, Dielectric };

/// The stack: ambient medium | dielectric coat (η0, α0) with an optional homogeneous medium |
/// base. Indices are relative (lamina's docs/physics.md §2): η0 = η_coat/η_ambient ≥ 1, the base's
/// η + iκ relative to the coat (a dielectric base, a slab's bottom: η_below/η_coat, the same in
/// the three channels). Roughnesses are GGX α (no remapping). Optical depths along the normal.
/// A rough coat or a rough conductor base may be anisotropic (lamina's docs/physics.md §3): α
/// along its tangent (alpha0, alpha1: α_x), α_y along its bitangent (alpha0_y, alpha1_y), the
/// tangent at tangent0, tangent1 radians from +x; each interface has its own tangent. A negative
/// α_y (the default) is an isotropic interface. docs/lamina1.md says which terms are anisotropic.
struct Layers {
    double eta0 = 1.5;
    double alpha0 = 0.0;
    double alpha0_y = -1.0;  ///< the coat's α along its bitangent (negative: alpha0, isotropic)
    double tangent0 = 0.0;   ///< the coat's tangent, radians from +x (anisotropic coat)
    Rgb tau_a{0.0};          ///< the coat medium's absorption optical depth
    Rgb tau_s{0.0};          ///< its scattering optical depth (Henyey–Greenstein)
    Rgb g{0.0};              ///< its Henyey–Greenstein asymmetry, (−1, 1)
    Base base = Base::Lambertian;
    Rgb base_eta{1.0};       ///< conductor or dielectric base: η relative to the coat
    Rgb base_k{0.0};         ///< conductor base: κ relative to the coat
    double alpha1 = 0.0;     ///< the base's roughness (conductor, dielectric)
    double alpha1_y = -1.0;  ///< a conductor base's α along its bitangent (negative: isotropic)
    double tangent1 = 0.0;   ///< the base's tangent, radians from +x (anisotropic base)
    Rgb albedo{0.0};         ///< Lambertian base: its albedo ρ
};

struct Options {
    /// Masking of the refracted rays in the coat's transmittance tables.
    Masking masking = Masking::Smith;
    /// The coat's transmittance: the rough interface's directional transmittance (true) or the
    /// smooth Fresnel transmittance 1 − F(μ) at the macro normal (false).
    bool directional_transmittance = true;
    /// Inter-reflections between base and coat bottom (the separable series term).
    bool inter_reflection = true;
    /// "auto": the separable series only where its uniform-radiance assumption can hold, where the
    /// returned light is spread again before it leaves: a Lambertian base, a base at least as
    /// rough as the coat (α1 ≥ α0), and, with the microsurfaces' orders ≥ 2 restored, every
    /// conductor (the rough coat spreads each return, and nothing is lost on the interfaces);
    /// reflected only (the slab's diffuse exit through the bottom only with "on"). With both
    /// interfaces smooth the exact delta series is summed either way.
    bool series_lambertian_only = true;
    /// The round trips as a lobe of their own (true) or in the separable series (false), where
    /// the series is summed over a conductor (its share round_trip_weight; the microsurfaces'
    /// orders ≥ 2 restored): the light the first order's exit leaves inside meets the coat's
    /// bottom, whose rough reflection sends it back to the base and out near the mirror direction,
    /// a lobe widened by that reflection (α_r² = α_e² + α1² + α0²) rather than uniform radiance. It
    /// carries what the returned light lets out, followed by its direction through the round trips
    /// (near the critical angle most of it stays trapped and the metal absorbs it), and the first
    /// order's light beyond its accounting is taken from that whole; false keeps the series'
    /// hemispherical-average escape.
    bool round_trip_lobe = true;
    /// The first order's balance: the series returns what the first order does not let out,
    /// counted as the light inside within the exit cone times its exit transmittance; the first
    /// order's lobe (its width, shape, masking and exit factors are approximations) carries a
    /// different energy. The difference is returned with the series (true), so the light that
    /// enters leaves in one or the other as it does in the stack; or not (false). A rough coat
    /// over a conductor or dielectric base, where the series is summed.
    bool first_order_balance = true;
    /// The slab's transmission lobe centred on the mean direction of the light the rough coat
    /// transmits (true) or on the macro refraction of wi (false).
    bool mean_shift = true;
    /// The 1/η² solid-angle compression of the base term (Hanrahan & Krueger 1993, Eq. 8).
    bool eta2_factor = true;
    /// The base lobe widened by the coat's refraction spread: with the angle-dependent deflection
    /// factor (Spread::Angular), its normal-incidence value 1 − 1/η (Normal), or not (Off).
    enum class Spread { Angular, Normal, Off } spread = Spread::Angular;
    /// The shape of that widened lobe (docs/models.md, lamina-1, item 4): its half-vector slope
    /// as the sum of the three independent GGX slopes of the base and the coat's two refractions
    /// (lamina1/table_lookups.h), the coat's tails carried through one facet's exact Snell
    /// deflection and transmission (Compressed); the same sum with the linear deflection (Sum);
    /// or one GGX lobe of the summed variance (Ggx, the earlier form).
    enum class FirstOrderLobe {
        Compressed,
        Sum,
        Ggx
    } first_order_lobe = FirstOrderLobe::Compressed;
    /// The rough interfaces' scattering orders ≥ 2 (lamina1/table_lookups.h). Multiple: restored
    /// (as lamina's default reference, --microsurface multiple, and a real rough surface): the
    /// coat's and the slab bottom's transmittances gain ΔT, the coat's inside reflectance and the
    /// base's albedo gain ΔR (ΔE F_ms for a conductor), and the coat's outer reflection and the
    /// base's lobe gain the separable energy-compensation lobes ΔR(μi) ΔR(μo)/(π ΔR̄)
    /// (docs/models.md); an anisotropic interface is then not represented (its loss depends on
    /// the azimuth, which these isotropic tables and separable lobes cannot follow: read at the
    /// root mean square roughness they return up to 23 % more light than arrives). Single: off
    /// (the energy the microsurfaces mask is lost, as the 2019 study's reference, --microsurface
    /// single). Auto (the default): Multiple where every interface is isotropic, else Single.
    enum class Microsurface { Auto, Single, Multiple } microsurface = Microsurface::Auto;
    /// The first order leaves a conductor or dielectric base through the coat with the coat's
    /// transmittance *from inside* along the base lobe's direction, T_in(μo'), where that lobe is
    /// narrower than the coat's refraction spread (true), or with the outside transmittance T(μo)
    /// (false), exact only for locally uniform radiance inside (a Lambertian base always uses it).
    bool inside_exit = true;
    /// The base lobe whose width follows wo through the coat's spread is divided by its excess
    /// energy over the fixed-width lobe, √N(μi') √N(μo') (reciprocal; docs/models.md).
    bool lobe_normalization = true;
    /// Scattering (Henyey–Greenstein) coat media (docs/models.md, lamina-1, "Scattering media"):
    /// the exact single scattering of the medium between the two refractions (first order in
    /// τs, closed form) ...
    bool medium_single = true;
    /// ... the once-scattered light that also meets a conductor or dielectric base (scattered
    /// then mirrored, mirrored then scattered; the base as a mirror of its directional albedo) ...
    bool medium_base_paths = true;
    /// ... and everything else the scattering sends back (orders ≥ 2, the scattered light's
    /// round trips between coat and base, the once-scattered light over a Lambertian base) as a
    /// separable lobe whose energy is the azimuth-averaged adding–doubling's (lamina1/adding.h).
    bool medium_orders = true;
    /// ... the part of that rest a slab transmits shaped like twice-scattered light (the
    /// once-scattered closed form with HG(g²): two HG scatterings have the mean cosine g²) and
    /// normalized to the adding's energy (true), or as uniform radiance below the bottom (false).
    bool medium_transmitted_twice = true;
    /// The slab's first-order transmission: the bottom interface's own Walter BTDF at the mean
    /// inside direction, widened by the coat's spread and carrying the light's exact first-order
    /// energy (true), or the mirrored GGX lobe q weighted by T_b,in at the exit (false).
    bool btdf_bottom_lobe = true;
    /// With btdf_bottom_lobe: the first order split between the bottom's BTDF, for the bottom's
    /// share of the spread's variance u = α1²/α_b², and the mirrored lobe (the coat's spread,
    /// made inside the coat and carried through the bottom's flat refraction), for 1 − u.
    bool btdf_lobe_shared = true;
    /// A slab's inter-reflections, both sides: the light inside carried in cosine bins with its
    /// azimuthal orders 0 and 1 (the forward moment), through both interfaces' transfer between
    /// bins, summed over every round trip and let out through each interface by reciprocity
    /// (true; lamina1/slab.h); or the uniform series and the first order's round trips of
    /// inter_reflection (false). Nothing with inter_reflection off.
    bool slab_bins = true;
    /// The Beer–Lambert factor of the light crossing a rough absorbing coat to and from an opaque
    /// base without a scattering medium: averaged over the directions the coat refracts it into
    /// (true; Bsdf::coat_attenuation), or along the macro refraction (false; with a scattering
    /// medium always: the adding balances the scattered light's energy along it).
    bool coat_path_spread = true;
    /// A slab's light polarized through its interfaces (true: as lamina's default reference,
    /// --polarization on): its reflection beyond the coat's own and its transmission scaled by
    /// the ratios of the slab's polarized series to the per-bounce average (lamina1/
    /// polarization.h), exact for smooth interfaces; or the unpolarized Fresnel factors at every
    /// event (false: as the 2019 study's reference, --polarization off). Only a slab's
    /// unscattered light changes (a Lambertian base and a scattering event depolarize, and a
    /// conductor under a coat changes by under 1 %).
    bool polarization = true;
};

}  // namespace lamina1
