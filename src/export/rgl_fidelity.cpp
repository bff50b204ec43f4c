#include "export/rgl_fidelity.h"

#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "export/rgl_parameterization.h"
#include "models/numerics/quadrature.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

double RglFidelity::worst_albedo_error() const {
    double worst = 0;
    for (const RglAlbedoRow& r : albedo)
        worst = std::max(worst, r.error);
    return worst;
}

double RglFidelity::value_error(double q) const {
    if (value_errors.empty()) return 0;
    const double at = std::clamp(q, 0.0, 1.0) * double(value_errors.size() - 1);
    return value_errors[std::size_t(std::ceil(at))];
}

bool RglFidelity::meets_goals() const {
    return worst_albedo_error() <= RglFidelityGoals::kAlbedo &&
           value_error(RglFidelityGoals::kValueQuantile) <= RglFidelityGoals::kValue;
}

Rgbd directional_albedo(const std::function<Rgbd(const Vec3d&, const Vec3d&)>& f, const Vec3d& wi) {
    constexpr int kCells = 48, kGauss = 6;
    static const QuadratureRule q = gauss_legendre(kGauss);
    const double phi_i = std::atan2(wi.y, wi.x);
    Rgbd sum(0.0);
    for (int a = 0; a < kCells; ++a)
        for (int ga = 0; ga < kGauss; ++ga) {
            const double t = (a + q.x[ga]) / kCells, ux = t * t;
            const double theta_m = rgl::u_to_theta(ux);
            Rgbd row(0.0);
            for (int b = 0; b < kCells; ++b)
                for (int gb = 0; gb < kGauss; ++gb) {
                    const double uy = (b + q.x[gb]) / kCells;
                    const Vec3d wm = direction_from_angles(theta_m, rgl::u_to_phi(uy) + phi_i);
                    const double cos_im = dot(wi, wm);
                    if (!(cos_im > 0)) continue;
                    const Vec3d wo = wm * (2 * cos_im) - wi;
                    if (!(wo.z > 0)) continue;
                    row += f(wi, wo) * (wo.z * 4 * cos_im * q.w[gb]);
                }
            sum += row * (rgl::solid_angle_jacobian(ux) * 2 * t * q.w[ga]);
        }
    return sum / double(kCells * kCells);
}

RglFidelity rgl_fidelity(const RglReader& file, const BrdfSource& source,
                         const RglFidelityOptions& o, const std::string& where) {
    // The incidences: the source's own, or a regular step.
    std::vector<double> thetas;
    if (!source.theta_i_deg.empty()) {
        for (double t : source.theta_i_deg)
            if (t <= o.max_theta_deg) thetas.push_back(t);
    } else {
        for (int k = 0; k * o.albedo_step_deg <= o.max_theta_deg + 1e-9; ++k)
            thetas.push_back(k * o.albedo_step_deg);
    }
    if (thetas.empty())
        throw InputError(
            where, "theta_i",
            fmt::format("the source has no incidence within {}° of the normal", o.max_theta_deg));
    const std::vector<double> azimuths =
        source.isotropic ? std::vector<double>{0} : std::vector<double>{0, 45, 90, 135};
    RglFidelity out;
    out.albedo.resize(thetas.size() * azimuths.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t k = 0; k < out.albedo.size(); ++k) {
        RglAlbedoRow& r = out.albedo[k];
        r.theta_i_deg = thetas[k / azimuths.size()];
        r.phi_i_deg = azimuths[k % azimuths.size()];
        const Vec3d wi = source.isotropic ? incident_direction(deg_to_rad(r.theta_i_deg))
                                          : direction_from_angles(deg_to_rad(r.theta_i_deg),
                                                                  deg_to_rad(r.phi_i_deg));
        r.source = directional_albedo(source.f, wi);
        r.file = directional_albedo(
            [&file](const Vec3d& i, const Vec3d& o) { return file.eval(i, o); }, wi);
        r.error = 0;
        for (int c = 0; c < 3; ++c)
            if (r.source[c] > 0) r.error = std::max(r.error, std::abs(r.file[c] / r.source[c] - 1));
    }

    // Pairs uniform in solid angle over the cap θ ≤ max: cos θ uniform in [cos max, 1]. A source
    // known at some incidences only gets them in turn as θi (its azimuth kept random).
    const double cos_max = std::cos(deg_to_rad(o.max_theta_deg));
    std::vector<double> errors(std::size_t(std::max(0, o.pairs)), -1.0);
#pragma omp parallel for schedule(static)
    for (int p = 0; p < o.pairs; ++p) {
        ParticleRng rng(o.seed, 0, std::uint64_t(p));
        auto direction = [&] {
            const double cos_theta = 1 - (1 - cos_max) * rng.uniform_double();
            const double phi = 2 * kPi<double> * rng.uniform_double();
            return direction_from_angles(std::acos(cos_theta), phi);
        };
        Vec3d wi = direction();
        if (!source.theta_i_deg.empty())
            wi = direction_from_angles(deg_to_rad(thetas[std::size_t(p) % thetas.size()]),
                                       std::atan2(wi.y, wi.x));
        const Vec3d wo = direction();
        const double want = luminance(source.f(wi, wo));
        if (!(want > 0)) continue;
        const double e = std::abs(luminance(file.eval(wi, wo)) / want - 1);
        errors[std::size_t(p)] = std::isfinite(e) ? e : HUGE_VAL;
    }
    for (double e : errors)
        if (e >= 0)
            out.value_errors.push_back(e);
        else
            ++out.pairs_skipped;
    std::sort(out.value_errors.begin(), out.value_errors.end());
    return out;
}

}  // namespace lamina
