#include "models/belcour_barla/belcour_barla.h"

#include "core/math.h"
#include "layers/compiled_stack.h"
#include "models/production/film_fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <optional>
#include <string>

namespace lamina {

std::vector<OptionSpec> belcour_barla_options() {
    return {{"kappa3",
             {"attenuation-index", "extinction"},
             "attenuation-index",
             "how the conductor's index eta + i k reaches the shader's base eta3 (1 + i kappa3): "
             "attenuation-index passes kappa3 = k/eta, the same metal; extinction passes kappa3 = "
             "k (relative to the ambient), what a user reading kappa3 as the extinction "
             "coefficient gets: the metal eta + i eta k"},
            {"primaries",
             {"cie-rgb", "srgb"},
             "cie-rgb",
             "the colour the Fresnel term returns: cie-rgb, the shader's (CIE 1931 RGB, "
             "equal-energy white); srgb, the same spectrum's linear sRGB over the white a flat "
             "spectrum gives"}};
}

namespace {

class BelcourBarla final : public Model {
  public:
    BelcourBarla(const Stack& stack, const ModelOptions& options) {
        support_ = {true, false, "a conductor reflects only: no BTDF"};
        // The conductor under the ambient: alone, or under a smooth clear interface of the
        // ambient's own index (no interface at all; the shape the coats take for a bare metal).
        const auto index_matched = [&](const Layer& l) {
            return l.interface.type == InterfaceType::Dielectric && !l.interface.is_spectral() &&
                   l.interface.eta == stack.ambient_eta && l.interface.alpha == 0 &&
                   !l.interface.has_film && !l.has_medium;
        };
        const std::size_t n = stack.layers.size();
        if (!(n == 1 || (n == 2 && index_matched(stack.layers[0]))) ||
            stack.base().type != InterfaceType::Conductor) {
            support_ = {false, false,
                        "bb17 represents one conductor interface under the ambient, with or "
                        "without a thin film (Belcour & Barla's shader has no coat)"};
            return;
        }
        const InterfaceSpec& metal = stack.base();
        const double eta0 = stack.ambient_eta;
        alpha_ = metal.alpha;
        const bool extinction = option_value(options, "kappa3") == "extinction";
        primaries_ = option_value(options, "primaries") == "srgb" ? BelcourBarlaPrimaries::Srgb
                                                                  : BelcourBarlaPrimaries::CieRgb;
        for (int c = 0; c < 3; ++c) {
            base_eta_[c] = model_relative_eta(metal.eta_rgb[c] / eta0);
            base_kappa_[c] =
                model_relative_k(extinction ? metal.k[c] / eta0 : metal.k[c] / metal.eta_rgb[c]);
        }
        if (metal.has_film && !read_film(stack_film_optics(stack, n - 1), eta0)) return;
        // A base without extinction is the shader's dielectric (its fresnelConductor hands κ3 = 0
        // to fresnelDielectric), whose total reflection below the film's index (or the ambient's)
        // leaves the reflectance unset, as for a film below the ambient.
        for (int c = 0; c < 3; ++c)
            if (base_kappa_[c] == 0 && base_eta_[c] < film_ior_) {
                support_ = {false, false,
                            fmt::format("bb17's base without extinction (k = 0) must not be of "
                                        "lower index than what lies above it ({} < {} relative "
                                        "to the ambient): the shader leaves the reflectance of "
                                        "its total reflection unset",
                                        base_eta_[c], film_ior_)};
                return;
            }
    }

    std::string name() const override { return "bb17"; }
    Support support() const override { return support_; }
    bool integrates_spectrum() const override { return true; }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || !(wi.z > 0) || !(wo.z > 0) || !(alpha_ > 0)) return Rgbd(0.0);
        const Vec3d h = normalize(wi + wo);
        const GGX<double> ggx{alpha_};
        return fresnel(dot(h, wi)) * (ggx.D(h) * ggx.G2_uncorrelated(wi, wo) / (4 * wi.z * wo.z));
    }

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        if (!support_.brdf || alpha_ > 0 || !(wi.z > 0)) return {};
        return {{mirror_direction(wi), fresnel(wi.z)}};
    }

  private:
    /// Reads the film into film_ior_ and the Dinc range, or says why it is not represented.
    bool read_film(const FilmOptics& film, double eta0) {
        if (film.eta_film.imag() > 0) {
            support_ = {false, false,
                        fmt::format("bb17's thin film is transparent (no extinction k); this "
                                    "film's k is {}",
                                    film.eta_film.imag())};
            return false;
        }
        if (film.eta_film.real() < eta0) {
            support_ = {false, false,
                        fmt::format("bb17's thin film must not be of lower index than the medium "
                                    "above it ({} < {}): the shader leaves the reflectance of its "
                                    "total reflection unset",
                                    film.eta_film.real(), eta0)};
            return false;
        }
        film_ior_ = film.eta_film.real() / eta0;
        // Dinc, the film's optical path at normal incidence 2 η_f d, in µm.
        dinc_min_um_ = 2 * film.eta_film.real() * film.thickness_min_nm / 1000;
        dinc_max_um_ = 2 * film.eta_film.real() * film.thickness_max_nm / 1000;
        return true;
    }

    /// The shader's Fresnel term at the facet cosine, averaged over the film's range.
    Rgbd fresnel(double cos_theta) const {
        return belcour_barla_fresnel_range(film_ior_, dinc_min_um_, dinc_max_um_, base_eta_,
                                           base_kappa_, cos_theta, primaries_);
    }

    Support support_;
    double alpha_ = 0;
    double film_ior_ = 1, dinc_min_um_ = 0, dinc_max_um_ = 0;  ///< no film: Dinc 0
    Rgbd base_eta_{1.0}, base_kappa_{0.0};
    BelcourBarlaPrimaries primaries_ = BelcourBarlaPrimaries::CieRgb;
};

}  // namespace

std::unique_ptr<Model> make_belcour_barla(const Stack& stack, const ModelOptions& options) {
    return std::make_unique<BelcourBarla>(stack, options);
}

}  // namespace lamina
