#include "models/production/ggx_albedo.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {

/// G2(wi, wo)/G1(wi) = (1 + Λi)/(1 + Λi + Λo): the weight visible-normal sampling leaves.
double masking_weight(const GGX<double>& ggx, const Vec3d& wi, const Vec3d& wo) {
    const double lambda_i = ggx.lambda(wi);
    return (1 + lambda_i) / (1 + lambda_i + ggx.lambda(wo));
}

}  // namespace

double correlated_ggx_albedo_white(double mu, double alpha, int n_r, int n_phi) {
    if (alpha <= 0) return 1;
    return reflection_over_visible_normals(
        mu, alpha,
        [](const GGX<double>& ggx, const Vec3d& wi, const Vec3d& wo, double) {
            return masking_weight(ggx, wi, wo);
        },
        n_r, n_phi);
}

SchlickSplit correlated_ggx_schlick_split(double mu, double alpha, int n_r, int n_phi) {
    auto weight = [](double c) {
        const double m = clamp(1 - c, 0.0, 1.0), m2 = m * m;
        return m2 * m2 * m;
    };
    SchlickSplit split;
    if (alpha <= 0) {
        split.bias = weight(clamp(mu, 0.0, 1.0));
        split.scale = 1 - split.bias;
        return split;
    }
    split.bias = reflection_over_visible_normals(
        mu, alpha,
        [&](const GGX<double>& ggx, const Vec3d& wi, const Vec3d& wo, double cos_h) {
            return weight(cos_h) * masking_weight(ggx, wi, wo);
        },
        n_r, n_phi);
    split.scale = reflection_over_visible_normals(
        mu, alpha,
        [&](const GGX<double>& ggx, const Vec3d& wi, const Vec3d& wo, double cos_h) {
            return (1 - weight(cos_h)) * masking_weight(ggx, wi, wo);
        },
        n_r, n_phi);
    return split;
}

double cycles_fresnel_factor(double mu, double alpha, double eta, int n_r, int n_phi) {
    const double f0 = fresnel_dielectric_normal(eta);
    auto position = [&](double c) {
        return clamp((fresnel_dielectric(c, eta) - f0) / (1 - f0), 0.0, 1.0);
    };
    if (alpha <= 0) return position(clamp(mu, 0.0, 1.0));
    return reflection_over_visible_normals(
        mu, alpha,
        [&](const GGX<double>&, const Vec3d&, const Vec3d&, double cos_h) {
            return position(cos_h);
        },
        n_r, n_phi);
}

}  // namespace lamina
