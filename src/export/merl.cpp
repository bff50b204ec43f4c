#include "export/merl.h"

#include "core/error.h"
#include "core/math.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace lamina {

namespace {
constexpr double kHalfPi = kPi<double> / 2;
constexpr std::size_t kCount = std::size_t(kMerlThetaH) * kMerlThetaD * kMerlPhiD;

std::size_t merl_index(double theta_h, double theta_d, double phi_d) {
    const int ih = std::clamp(int(std::sqrt(std::max(0.0, theta_h) / kHalfPi) * kMerlThetaH), 0,
                              kMerlThetaH - 1);
    const int id = std::clamp(int(theta_d / kHalfPi * kMerlThetaD), 0, kMerlThetaD - 1);
    const int ip = std::clamp(int(phi_d / kPi<double> * kMerlPhiD), 0, kMerlPhiD - 1);
    return (std::size_t(ih) * kMerlThetaD + id) * kMerlPhiD + ip;
}

Vec3d rotate_z(const Vec3d& v, double a) {
    const double c = std::cos(a), s = std::sin(a);
    return {c * v.x - s * v.y, s * v.x + c * v.y, v.z};
}
Vec3d rotate_y(const Vec3d& v, double a) {
    const double c = std::cos(a), s = std::sin(a);
    return {c * v.x + s * v.z, v.y, -s * v.x + c * v.z};
}
}  // namespace

std::array<double, 3> merl_half_diff(const Vec3d& wi, const Vec3d& wo) {
    const Vec3d h = normalize(wi + wo);
    const double theta_h = std::acos(std::clamp(h.z, -1.0, 1.0));
    const double phi_h = std::atan2(h.y, h.x);
    const Vec3d d = rotate_y(rotate_z(wi, -phi_h), -theta_h);
    const double theta_d = std::acos(std::clamp(d.z, -1.0, 1.0));
    double phi_d = std::atan2(d.y, d.x);
    if (phi_d < 0) phi_d += kPi<double>;
    return {theta_h, theta_d, phi_d};
}

std::array<Vec3d, 2> merl_directions(double theta_h, double theta_d, double phi_d) {
    const Vec3d d(std::sin(theta_d) * std::cos(phi_d), std::sin(theta_d) * std::sin(phi_d),
                  std::cos(theta_d));
    const Vec3d wi = rotate_y(d, theta_h);
    const Vec3d h(std::sin(theta_h), 0, std::cos(theta_h));
    const Vec3d wo = h * (2 * dot(wi, h)) - wi;
    return {wi, wo};
}

Rgbd MerlBrdf::eval(const Vec3d& wi, const Vec3d& wo) const {
    if (wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
    const auto [th, td, pd] = merl_half_diff(wi, wo);
    const std::size_t j = merl_index(th, td, pd);
    return {values[j], values[kCount + j], values[2 * kCount + j]};
}

std::string merl_binary(const BrdfSource& brdf) {
    if (!brdf.isotropic)
        throw InputError(brdf.name, "--format",
                         "a MERL .binary holds an isotropic BRDF (its half-vector coordinates "
                         "drop φh) and this stack is anisotropic: write a .bsdf or .npz");
    std::vector<double> planes(3 * kCount, 0.0);
#pragma omp parallel for schedule(dynamic, 1)
    for (int ih = 0; ih < kMerlThetaH; ++ih) {
        const double u = (ih + 0.5) / kMerlThetaH, theta_h = u * u * kHalfPi;
        for (int id = 0; id < kMerlThetaD; ++id) {
            const double theta_d = (id + 0.5) / kMerlThetaD * kHalfPi;
            for (int ip = 0; ip < kMerlPhiD; ++ip) {
                const double phi_d = (ip + 0.5) / kMerlPhiD * kPi<double>;
                const auto [wi, wo] = merl_directions(theta_h, theta_d, phi_d);
                if (wi.z <= 0 || wo.z <= 0) continue;
                const Rgbd f = brdf.f(normalize(wi), normalize(wo));
                const std::size_t j = (std::size_t(ih) * kMerlThetaD + id) * kMerlPhiD + ip;
                for (int c = 0; c < 3; ++c)
                    planes[c * kCount + j] = std::isfinite(f[c]) ? f[c] / kMerlScale[c] : 0.0;
            }
        }
    }
    std::string out(12 + planes.size() * 8, '\0');
    const std::int32_t dims[3] = {kMerlThetaH, kMerlThetaD, kMerlPhiD};
    std::memcpy(out.data(), dims, 12);
    std::memcpy(out.data() + 12, planes.data(), planes.size() * 8);
    return out;
}

MerlBrdf parse_merl(const std::string& bytes, const std::string& where) {
    if (bytes.size() < 12)
        throw InputError(where, "header",
                         "the file is shorter than its 12-byte header: truncated?");
    std::int32_t dims[3];
    std::memcpy(dims, bytes.data(), 12);
    if (dims[0] != kMerlThetaH || dims[1] != kMerlThetaD || dims[2] != kMerlPhiD)
        throw InputError(where, "header",
                         fmt::format("dimensions {} × {} × {}: a MERL file has 90 × 90 × 180",
                                     dims[0], dims[1], dims[2]));
    if (bytes.size() != 12 + 3 * kCount * 8)
        throw InputError(where, "data",
                         fmt::format("{} bytes: a MERL file has 12 + 3 × {} × 8 = {} (truncated?)",
                                     bytes.size(), kCount, 12 + 3 * kCount * 8));
    MerlBrdf out;
    out.values.resize(3 * kCount);
    std::memcpy(out.values.data(), bytes.data() + 12, out.values.size() * 8);
    for (std::size_t j = 0; j < out.values.size(); ++j) {
        if (!std::isfinite(out.values[j]))
            throw InputError(where, "data", fmt::format("value {} is not finite", j));
        out.values[j] *= kMerlScale[j / kCount];
    }
    return out;
}

}  // namespace lamina
