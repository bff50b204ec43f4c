#include "export/rgl_bsdf.h"

#include "core/error.h"
#include "core/incidences.h"
#include "core/math.h"
#include "core/spherical.h"
#include "export/bilinear_warp.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {

constexpr double kPiD = kPi<double>;

double u_to_theta(double u) {
    return u * u * (kPiD / 2);
}
double u_to_phi(double u) {
    return (2 * u - 1) * kPiD;
}
double theta_to_u(double theta) {
    return std::sqrt(std::max(0.0, theta) / (kPiD / 2));
}

Vec3d from_u(double ux, double uy) {
    return direction_from_angles(u_to_theta(ux), u_to_phi(uy));
}

/// A float32 table on an nx × ny node grid over [0, 1]², evaluated as the readers do (bilinear).
struct NodeTable {
    int nx, ny;
    std::vector<float> v;
    double eval(double x, double y) const {
        const double gx = std::clamp(x, 0.0, 1.0) * (nx - 1),
                     gy = std::clamp(y, 0.0, 1.0) * (ny - 1);
        const int i = std::min(int(gx), nx - 2), j = std::min(int(gy), ny - 2);
        const double s = gx - i, t = gy - j;
        auto at = [&](int a, int b) { return double(v[std::size_t(b) * nx + a]); };
        return (1 - t) * ((1 - s) * at(i, j) + s * at(i + 1, j)) +
               t * ((1 - s) * at(i, j + 1) + s * at(i + 1, j + 1));
    }
};

void check_resolution(int n, const char* field) {
    if (n < 2 || n > 512)
        throw InputError("command line", field, fmt::format("{} is outside [2, 512]", n));
}

}  // namespace

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
    check_resolution(o.resolution, "--resolution");
    check_resolution(o.vndf_resolution, "--vndf-resolution");
    check_resolution(o.ndf_resolution, "--ndf-resolution");
    std::vector<double> thetas = !o.theta_i_deg.empty() ? o.theta_i_deg : brdf.theta_i_deg;
    if (thetas.empty())
        for (int k = 0; k <= 22; ++k)
            thetas.push_back(4.0 * k);
    for (std::size_t k = 0; k < thetas.size(); ++k)
        if (!incidence_in_range(thetas[k]) || (k > 0 && !(thetas[k] > thetas[k - 1])))
            throw InputError("command line", "--theta-i",
                             "incidences must increase strictly within [0, 90) degrees");
    const int nd = o.ndf_resolution, nv = o.vndf_resolution, ns = o.resolution;
    const std::size_t n_inc = thetas.size();

    // 1. D from the retro-reflection, D ∝ Y(f(ωm, ωm)) cos²θm, floored (it divides S), then
    //    normalized to ∫ D cos θm dωm = 1 (by the interpolant the reader has).
    std::vector<double> d_theta(nd);
    double d_max = 0;
    for (int a = 0; a < nd; ++a) {
        const double theta = std::min(u_to_theta(double(a) / (nd - 1)), kPiD / 2 * (1 - 1e-6));
        const Vec3d m = direction_from_angles(theta, 0.0);
        d_theta[a] = std::max(0.0, luminance(brdf.f(m, m))) * sqr(std::cos(theta));
        d_max = std::max(d_max, d_theta[a]);
    }
    if (!(d_max > 0) || !std::isfinite(d_max))
        throw InputError(brdf.name, "f", "the BRDF is zero or not finite at retro-reflection");
    for (double& d : d_theta)
        d = std::max(d, 2e-2 * d_max);  // D divides S: keep it away from 0
    NodeTable ndf{nd, nd, std::vector<float>(std::size_t(nd) * nd)};
    auto fill_ndf = [&](double scale) {
        for (int b = 0; b < nd; ++b)
            for (int a = 0; a < nd; ++a)
                ndf.v[std::size_t(b) * nd + a] = float(d_theta[a] * scale);
    };
    fill_ndf(1.0);
    // ∫ D cos θ dω in u: dω = 2π² u sin θ du_x du_y (θ = u²π/2, φ = (2u − 1)π); midpoint rule.
    constexpr int kQ = 512;
    auto projected = [&](const Vec3d& w) {
        double sum = 0;
        for (int a = 0; a < kQ; ++a) {
            const double ux = (a + 0.5) / kQ, theta = u_to_theta(ux);
            const double jac = 2 * kPiD * kPiD * ux * std::sin(theta);
            for (int b = 0; b < kQ / 2; ++b) {
                const double uy = (b + 0.5) / (kQ / 2);
                const Vec3d m = from_u(ux, uy);
                sum += ndf.eval(ux, uy) * std::max(0.0, dot(w, m)) * jac;
            }
        }
        return sum / (double(kQ) * (kQ / 2));
    };
    fill_ndf(1.0 / projected(Vec3d(0, 0, 1)));

    // 2. σ(ωi) on the u grid of ωi (isotropic: each row the same).
    NodeTable sigma{nd, nd, std::vector<float>(std::size_t(nd) * nd)};
    std::vector<double> sigma_theta(nd);
#pragma omp parallel for schedule(dynamic, 1)
    for (int a = 0; a < nd; ++a)
        sigma_theta[a] = projected(direction_from_angles(u_to_theta(double(a) / (nd - 1)), 0.0));
    for (int b = 0; b < nd; ++b)
        for (int a = 0; a < nd; ++a)
            sigma.v[std::size_t(b) * nd + a] = float(sigma_theta[a]);

    // 3. Per incidence: the VNDF warp and the values S at the s nodes.
    const std::size_t nl = rgl_wavelengths().size();
    std::vector<float> vndf(n_inc * nv * nv), lum(n_inc * ns * ns), rgb(n_inc * 3 * ns * ns),
        spectra(n_inc * nl * ns * ns);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t k = 0; k < n_inc; ++k) {
        const double theta_i = deg_to_rad(thetas[k]);
        const Vec3d wi = incident_direction(theta_i);
        const double sigma_i = sigma.eval(theta_to_u(theta_i), 0.5);
        std::vector<double> density(std::size_t(nv) * nv);
        for (int b = 0; b < nv; ++b)
            for (int a = 0; a < nv; ++a) {
                const double ux = double(a) / (nv - 1), uy = double(b) / (nv - 1);
                const Vec3d m = from_u(ux, uy);
                const double jac = 2 * kPiD * kPiD * ux * std::sin(u_to_theta(ux));
                density[std::size_t(b) * nv + a] =
                    ndf.eval(ux, uy) * std::max(0.0, dot(wi, m)) * jac;
                vndf[(k * nv + b) * nv + a] = float(density[std::size_t(b) * nv + a]);
            }
        const BilinearWarp warp(density, nv, nv);
        std::vector<Rgbd> s_values(std::size_t(ns) * ns);
        double y_max = 0;
        for (int b = 0; b < ns; ++b)
            for (int a = 0; a < ns; ++a) {
                const auto u = warp.sample({double(a) / (ns - 1), double(b) / (ns - 1)});
                const Vec3d m = from_u(u[0], u[1]);
                const Vec3d wo = m * (2 * dot(wi, m)) - wi;
                // Nodes whose ωo falls below the horizon are never evaluated by a reader, but
                // their neighbours interpolate with them: give them S of the direction just above
                // the horizon at the same azimuth (f|cos θo| stays finite there for a glossy
                // lobe), the continuous extension, rather than a jump to 0.
                Vec3d out = wo;
                const double xy = std::hypot(wo.x, wo.y);
                if (wo.z < 1e-3 && xy > 0) {
                    constexpr double kZ = 1e-3;
                    const double r = std::sqrt(1 - kZ * kZ) / xy;
                    out = Vec3d(wo.x * r, wo.y * r, kZ);
                }
                const double d = ndf.eval(u[0], u[1]);
                Rgbd s = brdf.f(wi, out) * (out.z * 4 * sigma_i / d);
                for (int c = 0; c < 3; ++c)
                    if (!std::isfinite(s[c]) || s[c] < 0) s[c] = 0;
                s_values[std::size_t(b) * ns + a] = s;
                y_max = std::max(y_max, luminance(s));
            }
        for (std::size_t j = 0; j < s_values.size(); ++j) {
            const Rgbd& s = s_values[j];
            lum[k * ns * ns + j] = float(std::max(luminance(s), 1e-4 * y_max + 1e-12));
            for (int c = 0; c < 3; ++c)
                rgb[(k * 3 + c) * ns * ns + j] = float(s[c]);
            for (std::size_t l = 0; l < nl; ++l) {
                const Rgbd w = rgl_spectral_weights(l);
                spectra[(k * nl + l) * ns * ns + j] =
                    float(w[0] * s[0] + w[1] * s[1] + w[2] * s[2]);
            }
        }
    }

    // 4. Two equal φi slices (isotropic), then the file.
    auto twice = [](const std::vector<float>& v) {
        std::vector<float> out(v);
        out.insert(out.end(), v.begin(), v.end());
        return out;
    };
    std::vector<float> theta_rad, wavelengths;
    for (double t : thetas)
        theta_rad.push_back(float(deg_to_rad(t)));
    for (double l : rgl_wavelengths())
        wavelengths.push_back(float(l));
    const std::uint64_t n = n_inc;
    const std::string description =
        o.description.empty() ? fmt::format("lamina: {}", brdf.name) : o.description;
    TensorFile file;
    file["description"] = tensor_uint8(description, {description.size()});
    file["jacobian"] = tensor_uint8(std::string(1, '\1'), {1});
    file["theta_i"] = tensor_float32(theta_rad, {n});
    file["phi_i"] = tensor_float32({float(-kPiD), float(kPiD)}, {2});
    file["ndf"] = tensor_float32(ndf.v, {std::uint64_t(nd), std::uint64_t(nd)});
    file["sigma"] = tensor_float32(sigma.v, {std::uint64_t(nd), std::uint64_t(nd)});
    file["vndf"] = tensor_float32(twice(vndf), {2, n, std::uint64_t(nv), std::uint64_t(nv)});
    file["luminance"] = tensor_float32(twice(lum), {2, n, std::uint64_t(ns), std::uint64_t(ns)});
    file["rgb"] = tensor_float32(twice(rgb), {2, n, 3, std::uint64_t(ns), std::uint64_t(ns)});
    file["spectra"] =
        tensor_float32(twice(spectra), {2, n, nl, std::uint64_t(ns), std::uint64_t(ns)});
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
    for (const char* name : {"theta_i", "phi_i", "ndf", "sigma", "vndf", "luminance", "spectra"})
        for (float v : file.at(name).floats())
            if (!std::isfinite(v))
                throw InputError(where, name, "holds a value that is not finite");
}

}  // namespace lamina
