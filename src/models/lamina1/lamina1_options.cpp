// lamina-1's options (models/model_options.h), apart from the model so that the table's code leaves
// the compiler's inlining of the model's own code as it is.
#include "models/lamina1/lamina1.h"

namespace lamina {

namespace {

using L1 = Lamina1Choices;

// An option whose values set two flags.
ModelOption<L1>::Value two_flags(std::string text, bool L1::*a, bool a_value, bool L1::*b,
                                 bool b_value) {
    return {std::move(text),
            [=](L1& c) {
                c.*a = a_value;
                c.*b = b_value;
            },
            [=](const L1& c) { return c.*a == a_value && c.*b == b_value; }};
}

}  // namespace

const ModelOptionTable<Lamina1Choices>& lamina1_option_table() {
    using FirstOrderLobe = L1::FirstOrderLobe;
    using Spread = L1::Spread;
    static const ModelOptionTable<L1> table({
        member_option<L1, lamina1::Masking>(
            "refraction-masking", &L1::masking,
            {{"smith-beta", lamina1::Masking::Smith}, {"walter", lamina1::Masking::Walter}},
            "masking of refracted rays in the coat's transmittance: B(1+Li, 1+Lo) (Smith) or "
            "1/(1+Li+Lo) (Walter)"),
        member_option<L1, bool>(
            "coat-transmittance", &L1::directional_transmittance,
            {{"directional", true}, {"fresnel", false}},
            "the rough coat's directional transmittance (table) or 1 - F(mu) at the macro normal"),
        {"inter-reflection",
         {two_flags("auto", &L1::inter_reflection, true, &L1::series_lambertian_only, true),
          two_flags("on", &L1::inter_reflection, true, &L1::series_lambertian_only, false),
          {"off", [](L1& c) { c.inter_reflection = c.series_lambertian_only = false; },
           [](const L1& c) { return !c.inter_reflection; }}},
         "inter-reflections between base and coat bottom (geometric series as a separable lobe): "
         "auto: reflected under Lambertian bases, bases at least as rough as the coat and, with "
         "the orders >= 2 restored (microsurface), every conductor; on: "
         "always, transmitted too; off: never (smooth stacks: the exact delta series unless off); "
         "a slab's are slab-orders'"},
        member_option<L1, bool>(
            "round-trip", &L1::round_trip_lobe, {{"lobe", true}, {"series", false}},
            "the round trips (base, coat bottom, base) over a conductor (all of them up to the "
            "coat's roughness, a share up to 3 max(alpha0, 0.1)), "
            "where the series is summed: a lobe about the mirror direction widened by the coat "
            "bottom's reflection, carrying what the returned light lets out followed by its "
            "direction (lobe), or the uniform series with its average escape (series)"),
        on_off_member<L1>("first-order-balance", &L1::first_order_balance,
                          "the energy the first order's lobe does not carry out (against the "
                          "light inside the exit cone times its exit transmittance) returned "
                          "with the inter-reflection series, or not"),
        on_off_member<L1>("eta2", &L1::eta2_factor, "the 1/eta0^2 solid-angle compression"),
        member_option<L1, bool>(
            "transmitted-direction", &L1::mean_shift, {{"mean", true}, {"refracted", false}},
            "slab BTDF lobe centred on the rough coat's mean transmitted direction or on the macro "
            "refraction"),
        member_option<L1, Spread>(
            "spread", &L1::spread,
            {{"angular", Spread::Angular}, {"normal", Spread::Normal}, {"off", Spread::Off}},
            "base lobe widened by the coat's refraction spread: angle-dependent deflection, its "
            "normal-incidence value, or not widened"),
        member_option<L1, FirstOrderLobe>(
            "first-order-lobe", &L1::first_order_lobe,
            {{"compressed", FirstOrderLobe::Compressed},
             {"sum", FirstOrderLobe::Sum},
             {"ggx", FirstOrderLobe::Ggx}},
            "shape of the widened base lobe: the sum of the base's and the coat's two GGX slope "
            "spreads with the coat's tails through one facet's exact refraction (compressed), the "
            "same sum with the linear deflection (sum), or one GGX of the summed variance (ggx)"),
        member_option<L1, bool>(
            "exit-transmittance", &L1::inside_exit, {{"inside", true}, {"outside", false}},
            "the first order leaves a non-Lambertian base through the coat with the inside "
            "transmittance of its direction where the base lobe is narrower than the coat's "
            "spread, or always with the outside transmittance T(mu_o)"),
        on_off_member<L1>("lobe-normalization", &L1::lobe_normalization,
                          "the widened base lobe (width following wo) divided by its excess "
                          "energy sqrt(N(mu_i') N(mu_o')), or not"),
        on_off_member<L1>("medium-single", &L1::medium_single,
                          "scattering media: the exact single scattering of the medium between "
                          "the refractions (closed form; a slab's transmission too), or left to "
                          "the remainder lobe"),
        member_option<L1, bool>(
            "medium-base-paths", &L1::medium_base_paths, {{"mirror", true}, {"off", false}},
            "scattering media over a conductor or dielectric base: the once-scattered light that "
            "also meets the base, the base taken as a mirror of its albedo (closed form), or left "
            "to the remainder lobe"),
        member_option<L1, bool>(
            "medium-orders", &L1::medium_orders, {{"adding", true}, {"off", false}},
            "scattering media: the rest of the scattered light (orders >= 2, its round trips) as "
            "a separable lobe with the energy of an azimuth-averaged adding-doubling, or dropped"),
        member_option<L1, bool>(
            "medium-transmitted", &L1::medium_transmitted_twice,
            {{"twice", true}, {"diffuse", false}},
            "scattering slabs: the transmitted rest of the scattered light shaped like "
            "twice-scattered light (the once-scattered form with HG(g^2)), or as uniform radiance "
            "below the bottom"),
        {"btdf-lobe",
         {two_flags("shared", &L1::btdf_bottom_lobe, true, &L1::btdf_lobe_shared, true),
          two_flags("bottom", &L1::btdf_bottom_lobe, true, &L1::btdf_lobe_shared, false),
          {"mirrored", [](L1& c) { c.btdf_bottom_lobe = c.btdf_lobe_shared = false; },
           [](const L1& c) { return !c.btdf_bottom_lobe; }}},
         "slab BTDF first order: the bottom's own Walter BTDF at the mean inside direction with "
         "the first-order energy (bottom), the mirrored GGX lobe weighted by the bottom's "
         "transmittance at the exit (mirrored), or each for its share of the spread (shared)"},
        member_option<L1, bool>(
            "slab-orders", &L1::slab_bins, {{"bins", true}, {"series", false}},
            "slab later orders (reflection and transmission): the inside light in cosine bins "
            "with its forward moment, through both interfaces' transfer between bins, or the "
            "uniform series of inter-reflection"),
        member_option<L1, L1::Microsurface>(
            "microsurface", &L1::microsurface,
            {{"auto", L1::Microsurface::Auto},
             {"single", L1::Microsurface::Single},
             {"multiple", L1::Microsurface::Multiple}},
            "rough interfaces: with their orders >= 2 restored (multiple, as --microsurface "
            "multiple; isotropic interfaces only), single scattering (single: the masked energy "
            "lost, as --microsurface single), or multiple where every interface is isotropic "
            "(auto)"),
        member_option<L1, bool>(
            "coat-path", &L1::coat_path_spread, {{"spread", true}, {"refracted", false}},
            "Beer-Lambert through a rough absorbing coat (opaque base, no scattering medium): "
            "averaged over the directions the coat refracts the light into, or along the macro "
            "refraction"),
        on_off_member<L1>("polarization", &L1::polarization,
                          "a slab's light polarized through its interfaces, as the default "
                          "reference (--polarization on): its light beyond the coat's own "
                          "reflection scaled by the polarized series over the per-bounce "
                          "average, exact when smooth; or the unpolarized Fresnel factors at "
                          "every event (off, as --polarization off)"),
    });
    return table;
}

std::vector<OptionSpec> lamina1_options() {
    return lamina1_option_table().specs({});
}

}  // namespace lamina
