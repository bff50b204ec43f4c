#pragma once
// A thin film on a dielectric base's specular layer, as OpenPBR Surface 1.1 and Blender Cycles'
// Principled BSDF put it (docs/models.md, "A film on a dielectric base"). The stack is a filmed
// plastic: ambient | film | rough dielectric interface (η0, α0) | Lambertian ρ, nothing between the
// interface and the Lambertian. Its counterpart in both engines is their dielectric base without a
// coat (base_color ρ, specular IOR η0, specular roughness √α0, the film on the base): a GGX
// reflection lobe whose Fresnel factor is the film's, over the diffuse lobe weighted by what the
// specular layer is taken to leave,
//
//     f(wi, wo) = F_film(wi·h) D(h) G2(wi, wo) / (4 μi μo) · c(μo) + C/π · L(μo),
//
// G2 the height-correlated Smith term (Heitz 2014, JCGT 3(2), Eq. 99). Per engine:
//
//   OpenPBR 1.1 ("Glossy-diffuse": the non-reciprocal albedo scaling, f_dielectric + (1 −
//   E_dielectric(ωo)) f_diffuse with ρ = base_color; "Thin-film iridescence": the film enters the
//   Fresnel factor of the dielectric base's specular lobe and only redistributes reflection and
//   transmission). The cases the specification leaves to the implementation are taken exactly, as
//   for its film on a metal: F_film the film's Airy reflectance (physics/thin_film.h, at the
//   stack's channel wavelengths, averaged over the thickness range), c = 1, and L = 1 − E_film(μo)
//   with E_film the directional albedo of the filmed lobe itself (F_film(μo) for a smooth one).
//   Its colour C is the base colour the specification asks for, the Lambertian's ρ darkened by the
//   filmed interface's internal reflections (GlossyDiffuseFilmRecipe::darkened_base_color):
//   without a film the model is then `openpbr`'s coat over the diffuse base.
//
//   Cycles (kernel/svm/closure.h, the Principled BSDF's specular and diffuse components;
//   kernel/closure/bsdf_microfacet.h), C = ρ: F_film its Fourier-space film sum over the
//   dielectric (film_fresnel.h, cycles_dielectric_film; the film's index and thickness relative
//   to the ambient's index, which Cycles takes as 1); c its multiple-scattering compensation 1 +
//   F_ms (1 − E)/E (microfacet_ggx_preserve_energy, E from its white-lobe tables at μo, F_ms from
//   the bare dielectric's average Fresnel fit: the film does not enter it); L = clamp(1 − max_c w
//   F_film,c(μo), 0, 1) (closure_layering_weight), w = E + F_ms (1 − E) the lobe's weight after
//   compensation (1 without it) and F_film(μo) its albedo estimate, the film at the view's cosine
//   (Cycles keeps no table for films).
//
// Not represented, with the reason in support(): other shapes, an absorbing or scattering medium
// between the interface and the Lambertian, an absorbing film (k > 0; neither engine's film
// absorbs), an anisotropic interface, a base index at or below the ambient's, and for Cycles a
// thickness range (its layering weight is not linear in the film: a range has no one value).

#include "models/model.h"
#include "models/production/ggx_albedo.h"

#include <algorithm>
#include <memory>
#include <string>

namespace lamina {

struct GlossyDiffuseFilmRecipe {
    std::string name;
    enum class Film {
        Exact,   ///< the film's exact Airy reflectance (film_reflectance_exact)
        Cycles,  ///< Cycles' film sum over the dielectric (cycles_dielectric_film)
    } film = Film::Exact;
    /// Cycles' compensation of the specular lobe for multiple scattering (its multi-GGX default).
    bool cycles_compensation = false;
    enum class Layering {
        LobeAlbedo,      ///< L = 1 − E_film(μo), the filmed lobe's own albedo (OpenPBR)
        CyclesEstimate,  ///< L = clamp(1 − max_c w F_film,c(μo), 0, 1) (Cycles)
    } layering = Layering::LobeAlbedo;
    /// The diffuse's colour is the Lambertian's ρ darkened as OpenPBR darkens a diffuse base under
    /// a coat of the interface's index (openpbr_coat_darkening, K_r of the specification's E_F fit
    /// plus the film's change of the interface's average reflectance, per channel): OpenPBR 1.1
    /// defines base_color as the fraction of the light let into the dielectric that comes back
    /// out ("Glossy-diffuse"), which a Lambertian ρ under the interface gives by its internal
    /// reflections. Otherwise the colour is ρ (Cycles' base colour).
    bool darkened_base_color = false;
};

/// The stack is a filmed plastic (two interfaces: a dielectric carrying a film over a Lambertian).
bool is_filmed_plastic(const Stack& stack);

/// Builds the model for a filmed plastic; never fails (an unsupported stack says why in
/// support()).
std::unique_ptr<Model> make_glossy_diffuse_film(const Stack& stack,
                                                const GlossyDiffuseFilmRecipe& recipe);

/// E_film(μ): the directional albedo ∫ F_film(wi·h) D G2/(4 μi μo) μo dωo of the film's GGX lobe
/// of roughness alpha for light at the cosine mu, per channel, by quadrature over the visible
/// normals (48 Gauss–Legendre nodes per piece of the radius × 64 in φ); `film_at(cos)` gives the
/// film's reflectance at a facet cosine. alpha = 0 gives film_at(mu).
template <typename FilmAt>
Rgbd filmed_lobe_albedo(double mu, double alpha, FilmAt&& film_at);

template <typename FilmAt>
Rgbd filmed_lobe_albedo(double mu, double alpha, FilmAt&& film_at) {
    if (alpha <= 0) return film_at(std::max(mu, kAlbedoMuMin));
    return reflection_over_visible_normals<Rgbd>(
        mu, alpha,
        [&](const GGX<double>& ggx, const Vec3d& wi, const Vec3d& wo, double cos_h) {
            // G2/G1(wi) = (1 + Λi)/(1 + Λi + Λo): the weight visible-normal sampling leaves.
            const double lambda_i = ggx.lambda(wi);
            return film_at(cos_h) * ((1 + lambda_i) / (1 + lambda_i + ggx.lambda(wo)));
        },
        48, 64);
}

}  // namespace lamina
