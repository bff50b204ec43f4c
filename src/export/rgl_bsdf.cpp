#include "export/rgl_bsdf.h"

#include "core/error.h"
#include "core/incidences.h"
#include "core/math.h"
#include "core/spherical.h"
#include "export/bilinear_warp.h"
#include "export/rgl_parameterization.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {

using rgl::direction_at;
using rgl::solid_angle_jacobian;
using rgl::theta_to_u;
using rgl::u_to_theta;

// The writer's choices (docs/formats.md, "How lamina writes a .bsdf"), each found by measuring
// the figures of rgl_fidelity.h over the study's configurations.
/// P(ωm, ωm) is held at this fraction of its peak at least: it divides S.
constexpr double kRetroFloor = 1e-4;
/// ln D changes by at most this between two ndf nodes, so that the readers' linear interpolation
/// of D is within kMaxLogStep²/8 ≈ 0.8% of a smooth curve; a lobe narrower than that is left to
/// S, whose nodes gather there.
constexpr double kMaxLogStep = 0.25;
/// The warp's density along u_x: these shares uniform, where ln P(ωm, ωm) changes, and where
/// ln S changes (the rest).
constexpr double kUniformShare = 0.5, kRetroShare = 0.25;
/// Samples along u_x for P and for the changes of S, and azimuths of ωm for the latter.
constexpr int kFine = 4096, kMonitorSamples = 1024, kMonitorAzimuths = 8;
/// Where ωo falls below the horizon, S takes the value of the direction at this cos θo.
constexpr double kHorizonCos = 1e-3;
/// An anisotropic source's D: rows of u_y (absolute φm) over [−π, π], kNdfAzimuths + 1 of them,
/// 1.4° apart. S divides by D's interpolant, which must follow a brushed lobe across φm: with rows
/// 5.6° apart the values' p90 on brushed aluminium (α 0.05 × 0.35) under a coat was 6.8%, with
/// 2.8° 4.2%, here 4.1%, and finer rows change nothing more.
constexpr int kNdfAzimuths = 256;

void check_resolution(int n, const char* field, int max) {
    if (n < 2 || n > max)
        throw InputError("command line", field, fmt::format("{} is outside [2, {}]", n, max));
}

/// P(ωm, ωm) = Y(f(ωm, ωm)) cos²θm, the retro-reflection (for a microfacet BRDF F G D / 4), at
/// u_x = i/kFine, one row per azimuth φm (radians), floored at kRetroFloor of its peak over all.
std::vector<std::vector<double>> retro_reflection(const BrdfSource& brdf,
                                                  const std::vector<double>& phi_m) {
    std::vector<std::vector<double>> rows(phi_m.size(), std::vector<double>(kFine + 1));
    double peak = 0;
    for (std::size_t r = 0; r < phi_m.size(); ++r)
        for (int i = 0; i <= kFine; ++i) {
            const double theta =
                std::min(u_to_theta(double(i) / kFine), kPi<double> / 2 * (1 - 1e-6));
            const Vec3d m = direction_from_angles(theta, phi_m[r]);
            rows[r][std::size_t(i)] = std::max(0.0, luminance(brdf.f(m, m))) * sqr(std::cos(theta));
            peak = std::max(peak, rows[r][std::size_t(i)]);
        }
    if (!(peak > 0) || !std::isfinite(peak))
        throw InputError(brdf.name, "f", "the BRDF is zero or not finite at retro-reflection");
    for (std::vector<double>& p : rows)
        for (double& x : p)
            x = std::max(x, kRetroFloor * peak);
    return rows;
}

/// One row of D at nd nodes of u_x: P(ωm, ωm) with its log-slope limited to kMaxLogStep per node
/// (the largest function below P that obeys it).
std::vector<double> ndf_row(const std::vector<double>& retro, int nd) {
    std::vector<double> d(static_cast<std::size_t>(nd));
    for (int a = 0; a < nd; ++a)
        d[std::size_t(a)] = rgl::linear(retro.data(), retro.size(), double(a) / (nd - 1));
    const double step = std::exp(kMaxLogStep);
    for (std::size_t a = 1; a < d.size(); ++a)
        d[a] = std::min(d[a], d[a - 1] * step);
    for (std::size_t a = d.size() - 1; a-- > 0;)
        d[a] = std::min(d[a], d[a + 1] * step);
    return d;
}

/// The rows of D (nd nodes each, the rows evenly over u_y), normalized together to
/// ∫ D cos θm dωm = 1: a row's integral over u_x by the midpoint rule (D is linear between nodes),
/// the rows' by the trapezoid rule (D is linear between rows).
std::vector<float> ndf_nodes(const std::vector<std::vector<double>>& rows, std::size_t nd) {
    constexpr int kQ = 16384;
    std::vector<double> integrals;
    for (const std::vector<double>& d : rows) {
        double integral = 0;
        for (int q = 0; q < kQ; ++q) {
            const double ux = (q + 0.5) / kQ;
            integral += rgl::linear(d.data(), d.size(), ux) * std::cos(u_to_theta(ux)) *
                        solid_angle_jacobian(ux);
        }
        integrals.push_back(integral);
    }
    double total = 0;
    for (std::size_t r = 0; r + 1 < rows.size(); ++r)
        total += (integrals[r] + integrals[r + 1]) / 2;
    total /= double(rows.size() - 1);
    std::vector<float> ndf;
    for (const std::vector<double>& d : rows)
        for (std::size_t a = 0; a < nd; ++a)
            ndf.push_back(float(d[a] / (total / kQ)));
    return ndf;
}

/// |Δ ln S| between neighbouring samples of u_x at incidence wi, averaged over azimuths of ωm
/// (S ∝ Y(f) cos θo / D; samples whose ωo is below the horizon are skipped): kMonitorAzimuths of
/// them over (−π, 0) relative to φi for an isotropic file (the other half mirrors them), twice
/// that over the whole circle for an anisotropic one (ndf with n_rows rows over absolute φm).
std::vector<double> s_changes(const BrdfSource& brdf, const Vec3d& wi,
                              const std::vector<float>& ndf, std::size_t nd, std::size_t n_rows) {
    std::vector<double> out(kMonitorSamples, 0.0);
    const int azimuths = brdf.isotropic ? kMonitorAzimuths : 2 * kMonitorAzimuths;
    for (int r = 0; r < azimuths; ++r) {
        const double uy = (r + 0.5) / (2 * kMonitorAzimuths);
        double previous = 0;
        bool have_previous = false;
        for (int i = 0; i <= kMonitorSamples; ++i) {
            const double ux = double(i) / kMonitorSamples;
            const Vec3d m = direction_at(ux, uy);
            const double cos_im = dot(wi, m);
            const Vec3d wo = m * (2 * cos_im) - wi;
            double ln_s = 0;
            bool ok = cos_im > 0 && wo.z > kHorizonCos;
            if (ok) {
                const double s =
                    luminance(brdf.f(wi, wo)) * wo.z /
                    rgl::bilinear(ndf.data(), nd, n_rows, ux, brdf.isotropic ? 0.0 : uy);
                ok = s > 0 && std::isfinite(s);
                if (ok) ln_s = std::log(s);
            }
            if (ok && have_previous) out[std::size_t(i - 1)] += std::abs(ln_s - previous);
            have_previous = ok;
            previous = ln_s;
        }
    }
    return out;
}

/// The warp's density at nv nodes of u_x: kUniformShare uniform, kRetroShare by |Δ ln P(ωm, ωm)|
/// (the cores and edges of narrow lobes; the mean over the first n_rows rows of azimuth), the rest
/// by |Δ ln S|
/// summed over the incidences (in their order: the same for any thread count). Each share is a
/// density over [0, 1]; a node gets the mean of the share's density over its half cells.
std::vector<double> warp_nodes(const std::vector<std::vector<double>>& retro, std::size_t n_rows,
                               const std::vector<double>& s_change, int nv) {
    std::vector<double> retro_change(kFine);
    for (int f = 0; f < kFine; ++f) {
        double change = 0;
        for (std::size_t r = 0; r < n_rows; ++r)
            change += std::abs(std::log(retro[r][std::size_t(f) + 1] / retro[r][std::size_t(f)]));
        retro_change[std::size_t(f)] = change / double(n_rows);
    }
    auto mean_density = [](const std::vector<double>& change, double lo, double hi) {
        const std::size_t n = change.size();
        double total = 0, mass = 0;
        for (double c : change)
            total += c;
        if (!(total > 0)) return 1.0;
        for (std::size_t f = std::size_t(lo * double(n));
             f < std::min(n, std::size_t(std::ceil(hi * double(n)))); ++f)
            mass += change[f];
        return mass / total / (hi - lo);
    };
    std::vector<double> a(static_cast<std::size_t>(nv));
    for (int i = 0; i < nv; ++i) {
        const double lo = std::max(0.0, (i - 0.5) / (nv - 1)),
                     hi = std::min(1.0, (i + 0.5) / (nv - 1));
        a[std::size_t(i)] = kUniformShare + kRetroShare * mean_density(retro_change, lo, hi) +
                            (1 - kUniformShare - kRetroShare) * mean_density(s_change, lo, hi);
    }
    return a;
}

}  // namespace

std::vector<double> rgl_default_incidences() {
    // Every kStep degrees while that is at most kShare of the distance to the horizon, then steps
    // of kShare of it (S and the readers' interpolation between incidences change faster there),
    // and kLast last (past it the readers hold the last incidence).
    constexpr double kStep = 4, kShare = 0.25, kLast = 88;
    std::vector<double> out;
    for (double t = 0; t < kLast - 0.5; t += std::min(kStep, kShare * (90 - t)))
        out.push_back(std::round(t * 100) / 100);
    out.push_back(kLast);
    return out;
}

const std::vector<double>& rgl_wavelengths() {
    static const std::vector<double> w = {400, 450, 500, 550, 600, 650, 700};
    return w;
}

Rgbd rgl_spectral_weights(std::size_t k) {
    // (r, g, b) weights: a partition of unity over the wavelengths above.
    static const Rgbd weights[7] = {{0, 0, 1},     {0, 0, 1}, {0, 0.5, 0.5}, {0, 1, 0},
                                    {0.5, 0.5, 0}, {1, 0, 0}, {1, 0, 0}};
    return weights[k];
}

TensorFile rgl_bsdf(const BrdfSource& brdf, const RglOptions& o) {
    check_resolution(o.resolution, "--resolution", 512);
    check_resolution(o.vndf_resolution, "--vndf-resolution", 8192);
    check_resolution(o.ndf_resolution, "--ndf-resolution", 8192);
    std::vector<double> thetas = !o.theta_i_deg.empty() ? o.theta_i_deg : brdf.theta_i_deg;
    if (thetas.empty()) thetas = rgl_default_incidences();
    for (std::size_t k = 0; k < thetas.size(); ++k)
        if (!incidence_in_range(thetas[k]) || (k > 0 && !(thetas[k] > thetas[k - 1])))
            throw InputError("command line", "--theta-i",
                             "incidences must increase strictly within [0, 90) degrees");
    check_resolution(o.azimuths, "--azimuths", 360);
    const std::size_t nd = std::size_t(o.ndf_resolution), nv = std::size_t(o.vndf_resolution),
                      ns = std::size_t(o.resolution), n_inc = thetas.size(), plane = ns * ns;

    // The φi slices (one for an isotropic source, at φi = 0) and D's rows of azimuth: for an
    // isotropic source φm relative to φi, one row of P on two equal rows of u_y; for an
    // anisotropic one absolute φm, a row of P per row of u_y over [−π, π].
    std::vector<double> phi_slices = {0.0}, phi_rows = {0.0};
    if (!brdf.isotropic) {
        phi_slices.clear(), phi_rows.clear();
        for (int p = 0; p <= o.azimuths; ++p)
            phi_slices.push_back(rgl::u_to_phi(double(p) / o.azimuths));
        for (int r = 0; r <= kNdfAzimuths; ++r)
            phi_rows.push_back(rgl::u_to_phi(double(r) / kNdfAzimuths));
    }
    const std::size_t n_phi = phi_slices.size(), n_slices = n_phi * n_inc;
    auto incidence = [&](std::size_t q) {  // slice q = (φi index) n_inc + (θi index)
        const double theta_i = deg_to_rad(thetas[q % n_inc]);
        return brdf.isotropic ? incident_direction(theta_i)
                              : direction_from_angles(theta_i, phi_slices[q / n_inc]);
    };

    // 1. D from the retro-reflection.
    const std::vector<std::vector<double>> retro = retro_reflection(brdf, phi_rows);
    std::vector<std::vector<double>> d_rows;
    for (const std::vector<double>& row : retro)
        d_rows.push_back(ndf_row(row, int(nd)));
    if (brdf.isotropic) d_rows.push_back(d_rows[0]);
    const std::size_t n_rows = d_rows.size();
    const std::vector<float> ndf = ndf_nodes(d_rows, nd);

    // 2. σ(θi) = cos θi, held past the last incidence (the readers hold S there too, so that f
    //    stays bounded as θi → 90°).
    const double theta_last = deg_to_rad(thetas.back());
    std::vector<float> sigma(2 * nd);
    for (std::size_t a = 0; a < nd; ++a)
        sigma[a] = sigma[nd + a] =
            float(std::cos(std::min(u_to_theta(double(a) / double(nd - 1)), theta_last)));

    // 3. The warp, a density of u_x alone and the same at every incidence, so that s_x ↔ u_x is
    //    one map: S's features in θm line up across rows of s and across incidences.
    //    An anisotropic source's last slice, and last row of P, repeat its first and are not
    //    counted twice.
    const std::size_t n_distinct = brdf.isotropic ? n_slices : n_slices - n_inc;
    std::vector<std::vector<double>> changes(n_distinct);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t q = 0; q < n_distinct; ++q)
        changes[q] = s_changes(brdf, incidence(q), ndf, nd, n_rows);
    std::vector<double> s_change(kMonitorSamples, 0.0);
    for (const std::vector<double>& c : changes)
        for (std::size_t f = 0; f < c.size(); ++f)
            s_change[f] += c[f];
    const std::vector<double> a =
        warp_nodes(retro, brdf.isotropic ? retro.size() : retro.size() - 1, s_change, int(nv));
    std::vector<float> vndf_slice(2 * nv);
    for (std::size_t i = 0; i < nv; ++i)
        vndf_slice[i] = vndf_slice[nv + i] = float(a[i]);
    const BilinearWarp warp(std::vector<double>(vndf_slice.begin(), vndf_slice.end()), int(nv), 2);

    // 4. Per slice: S at the s nodes, S = 4 f cos θo σ(θi) / D(ωm) (at the nodes a reader gives
    //    f back to float32 precision), and the density to sample s from.
    const std::size_t nl = rgl_wavelengths().size();
    std::vector<float> vndf(n_slices * vndf_slice.size()), lum(n_slices * plane),
        spectra(n_slices * nl * plane);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t q = 0; q < n_slices; ++q) {
        const double theta_i = deg_to_rad(thetas[q % n_inc]);
        const Vec3d wi = incidence(q);
        const double sigma_i = rgl::bilinear(sigma.data(), nd, 2, theta_to_u(theta_i), 0.5);
        std::copy(vndf_slice.begin(), vndf_slice.end(),
                  vndf.begin() + std::ptrdiff_t(q * vndf_slice.size()));
        std::vector<Rgbd> s_values(plane);
        std::vector<double> weights(plane);
        double weight_max = 0;
        for (std::size_t j = 0; j < plane; ++j) {
            const auto u =
                warp.sample({double(j % ns) / double(ns - 1), double(j / ns) / double(ns - 1)});
            const Vec3d m = direction_at(u[0], u[1]);
            const double cos_im = dot(wi, m);
            const Vec3d wo = m * (2 * cos_im) - wi;
            // Nodes whose ωo is below the horizon are never evaluated by a reader, but their
            // neighbours interpolate with them: S of the direction just above the horizon at the
            // same azimuth (f cos θo → 0 there), the continuous extension.
            Vec3d out = wo;
            const double xy = std::hypot(wo.x, wo.y);
            if (wo.z < kHorizonCos && xy > 0) {
                const double r = std::sqrt(1 - kHorizonCos * kHorizonCos) / xy;
                out = Vec3d(wo.x * r, wo.y * r, kHorizonCos);
            }
            const double d_m = rgl::bilinear(ndf.data(), nd, n_rows, u[0], u[1]);
            Rgbd s = brdf.f(wi, out) * (out.z * 4 * sigma_i / d_m);
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(s[c]) || s[c] < 0) s[c] = 0;
            s_values[j] = s;
            // Sampling s ∝ Y(f) cos θo / (warp density of ωo) = Y(S) D (ωi·ωm) J / (4σ p) makes
            // the readers' Sample_f follow f cos θo (the constant 4σ drops out).
            const double p = warp.eval(u);
            const double w = wo.z > 0 && cos_im > 0 && p > 0
                                 ? luminance(s) * d_m * cos_im * solid_angle_jacobian(u[0]) / p
                                 : 0;
            weights[j] = std::isfinite(w) ? w : 0;
            weight_max = std::max(weight_max, weights[j]);
        }
        for (std::size_t j = 0; j < plane; ++j) {
            // Never 0, so that a renderer can sample every direction it evaluates.
            lum[q * plane + j] = float(std::max(weights[j], 1e-4 * weight_max + 1e-12));
            for (std::size_t l = 0; l < nl; ++l) {
                const Rgbd w = rgl_spectral_weights(l);
                const Rgbd& sj = s_values[j];
                spectra[(q * nl + l) * plane + j] =
                    float(w[0] * sj[0] + w[1] * sj[1] + w[2] * sj[2]);
            }
        }
    }

    // 5. The file.
    std::vector<float> theta_rad, phi_rad, wavelengths;
    for (double t : thetas)
        theta_rad.push_back(float(deg_to_rad(t)));
    for (double p : phi_slices)
        phi_rad.push_back(float(p));
    for (double l : rgl_wavelengths())
        wavelengths.push_back(float(l));
    const std::uint64_t n = n_inc, np = n_phi;
    const std::string description =
        o.description.empty() ? fmt::format("lamina: {}", brdf.name) : o.description;
    TensorFile file;
    file["description"] = tensor_uint8(description, {description.size()});
    file["jacobian"] = tensor_uint8(std::string(1, '\1'), {1});
    file["theta_i"] = tensor_float32(theta_rad, {n});
    file["phi_i"] = tensor_float32(phi_rad, {np});
    file["ndf"] = tensor_float32(ndf, {n_rows, nd});
    file["sigma"] = tensor_float32(sigma, {2, nd});
    file["vndf"] = tensor_float32(vndf, {np, n, 2, nv});
    file["luminance"] = tensor_float32(lum, {np, n, ns, ns});
    file["spectra"] = tensor_float32(spectra, {np, n, nl, ns, ns});
    file["wavelengths"] = tensor_float32(wavelengths, {nl});
    return file;
}

void check_rgl_bsdf(const TensorFile& file, const std::string& where) {
    auto field = [&](const char* name, TensorType type, std::size_t ndim) -> const TensorField& {
        const auto it = file.find(name);
        if (it == file.end()) throw InputError(where, name, "the field is missing");
        if (it->second.type != type || it->second.shape.size() != ndim)
            throw InputError(where, name,
                             fmt::format("expected a {}-dimensional {} array", ndim,
                                         type == TensorType::UInt8 ? "uint8" : "float32"));
        return it->second;
    };
    field("description", TensorType::UInt8, 1);
    const auto& jac = field("jacobian", TensorType::UInt8, 1);
    const auto& ti = field("theta_i", TensorType::Float32, 1);
    const auto& pi = field("phi_i", TensorType::Float32, 1);
    const auto& wl = field("wavelengths", TensorType::Float32, 1);
    const auto& ndf = field("ndf", TensorType::Float32, 2);
    const auto& sigma = field("sigma", TensorType::Float32, 2);
    const auto& vndf = field("vndf", TensorType::Float32, 4);
    const auto& lum = field("luminance", TensorType::Float32, 4);
    const auto& spec = field("spectra", TensorType::Float32, 5);
    auto require = [&](bool ok, const char* name, const char* what) {
        if (!ok) throw InputError(where, name, what);
    };
    require(jac.shape[0] == 1, "jacobian", "expected one byte");
    require(ti.shape[0] >= 1 && pi.shape[0] >= 1, "theta_i", "expected at least one incidence");
    require(ndf.shape[0] >= 2 && ndf.shape[1] >= 2 && sigma.shape[0] >= 2 && sigma.shape[1] >= 2,
            "ndf", "ndf and sigma need at least 2 × 2 nodes");
    require(vndf.shape[0] == pi.shape[0] && vndf.shape[1] == ti.shape[0] && vndf.shape[2] >= 2 &&
                vndf.shape[3] >= 2,
            "vndf", "expected [phi_i, theta_i, ≥ 2, ≥ 2]");
    require(lum.shape[0] == pi.shape[0] && lum.shape[1] == ti.shape[0] &&
                lum.shape[2] == lum.shape[3] && lum.shape[2] >= 2,
            "luminance", "expected [phi_i, theta_i, n, n] with n ≥ 2");
    require(spec.shape[0] == pi.shape[0] && spec.shape[1] == ti.shape[0] &&
                spec.shape[2] == wl.shape[0] && spec.shape[3] == lum.shape[2] &&
                spec.shape[4] == lum.shape[3],
            "spectra", "expected [phi_i, theta_i, wavelengths, n, n] matching luminance");
    if (file.count("rgb")) {
        const auto& rgb = field("rgb", TensorType::Float32, 5);
        require(rgb.shape[0] == pi.shape[0] && rgb.shape[1] == ti.shape[0] && rgb.shape[2] == 3 &&
                    rgb.shape[3] == lum.shape[2] && rgb.shape[4] == lum.shape[3],
                "rgb", "expected [phi_i, theta_i, 3, n, n] matching luminance");
    }
    for (const char* name :
         {"theta_i", "phi_i", "wavelengths", "ndf", "sigma", "vndf", "luminance", "spectra"})
        for (float v : file.at(name).floats())
            if (!std::isfinite(v))
                throw InputError(where, name, "holds a value that is not finite");
    if (file.count("rgb"))
        for (float v : file.at("rgb").floats())
            if (!std::isfinite(v))
                throw InputError(where, "rgb", "holds a value that is not finite");
    // The BRDF's values per wavelength and their luminance, which a reader samples by (its
    // marginal distributions): never negative. The rgb field is linear sRGB, negative outside the
    // gamut.
    for (const char* name : {"luminance", "spectra"}) {
        const std::vector<float> values = file.at(name).floats();
        if (std::any_of(values.begin(), values.end(), [](float v) { return v < 0; }))
            throw InputError(where, name,
                             "holds a negative value (a BRDF value is never negative, and a "
                             "reader samples by the luminance)");
    }
    // The microfacets' distribution and projected area: densities, so never negative, and not
    // zero everywhere (a reader normalizes by them).
    for (const char* name : {"ndf", "sigma"}) {
        const std::vector<float> values = file.at(name).floats();
        if (std::any_of(values.begin(), values.end(), [](float v) { return v < 0; }))
            throw InputError(where, name, "holds a negative value (a density is never negative)");
        if (std::none_of(values.begin(), values.end(), [](float v) { return v > 0; }))
            throw InputError(where, name, "is zero everywhere (a reader normalizes by it)");
    }
    // The incidences are polar angles of the upper hemisphere (radians), the wavelengths the
    // nodes a renderer interpolates the spectra between.
    for (float v : ti.floats())
        if (!(v >= 0 && v <= float(kPi<double> / 2)))
            throw InputError(
                where, "theta_i",
                fmt::format("{} rad is outside [0, π/2] (an incidence's polar angle)", v));
    const std::vector<float> wavelengths = wl.floats();
    for (std::size_t k = 0; k < wavelengths.size(); ++k)
        if (!(wavelengths[k] > 0) || (k > 0 && !(wavelengths[k] > wavelengths[k - 1])))
            throw InputError(where, "wavelengths",
                             "the wavelengths must be positive and increase strictly");
}

}  // namespace lamina
