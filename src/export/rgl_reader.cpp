#include "export/rgl_reader.h"

#include "core/error.h"
#include "core/math.h"
#include "export/rgl_bsdf.h"
#include "export/rgl_parameterization.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

RglReader::RglReader(const TensorFile& file, const std::string& where) {
    check_rgl_bsdf(file, where);
    const TensorField& phi_i = file.at("phi_i");
    isotropic_ = phi_i.shape[0] <= 2;  // the readers' rule
    if (isotropic_) {
        phi_nodes_ = {0.0};
    } else {
        for (float p : phi_i.floats())
            phi_nodes_.push_back(double(p));
        for (std::size_t k = 1; k < phi_nodes_.size(); ++k)
            if (!(phi_nodes_[k] > phi_nodes_[k - 1]))
                throw InputError(where, "phi_i", "the azimuths must increase strictly");
        const double span = phi_nodes_.back() - phi_nodes_.front();
        reduction_ = int(std::lround(2 * kPi<double> / span));
        if (reduction_ != 1 && reduction_ != 2 && reduction_ != 4)
            throw InputError(where, "phi_i",
                             fmt::format("an anisotropic file's azimuths span 2π, π or π/2 "
                                         "(the readers' symmetries); these span {:.4g} rad",
                                         span));
    }
    for (float t : file.at("theta_i").floats())
        theta_nodes_.push_back(double(t));
    for (std::size_t k = 1; k < theta_nodes_.size(); ++k)
        if (!(theta_nodes_[k] > theta_nodes_[k - 1]))
            throw InputError(where, "theta_i", "the incidences must increase strictly");
    const TensorField &ndf = file.at("ndf"), &sigma = file.at("sigma"), &vndf = file.at("vndf"),
                      &spectra = file.at("spectra");
    ndf_ = ndf.floats();
    sigma_ = sigma.floats();
    ndf_ny_ = ndf.shape[0], ndf_nx_ = ndf.shape[1];
    sigma_ny_ = sigma.shape[0], sigma_nx_ = sigma.shape[1];
    s_ny_ = spectra.shape[3], s_nx_ = spectra.shape[4];
    const std::size_t plane = s_nx_ * s_ny_, n_slices = phi_nodes_.size() * theta_nodes_.size();
    if (file.count("rgb")) {
        rgb_ = file.at("rgb").floats();
    } else {
        // The colour as the spectra at 450, 550 and 650 nm: blue, green and red exactly in
        // lamina's upsampling (rgl_bsdf.h).
        const std::vector<float> wavelengths = file.at("wavelengths").floats(),
                                 v = spectra.floats();
        std::size_t at[3];
        const double want[3] = {650, 550, 450};
        for (int c = 0; c < 3; ++c) {
            const auto it = std::find(wavelengths.begin(), wavelengths.end(), float(want[c]));
            if (it == wavelengths.end())
                throw InputError(where, "wavelengths",
                                 "lamina reads a file's colour from its spectra at 450, 550 and "
                                 "650 nm (or from an rgb field): the file has neither");
            at[c] = std::size_t(it - wavelengths.begin());
        }
        const std::size_t nl = wavelengths.size();
        rgb_.resize(n_slices * 3 * plane);
        for (std::size_t k = 0; k < n_slices; ++k)
            for (int c = 0; c < 3; ++c)
                std::copy_n(v.begin() + std::ptrdiff_t((k * nl + at[c]) * plane), plane,
                            rgb_.begin() + std::ptrdiff_t((k * 3 + std::size_t(c)) * plane));
    }
    vndf_ny_ = vndf.shape[2], vndf_nx_ = vndf.shape[3];
    const std::vector<float> v = vndf.floats();
    const std::size_t slice = vndf_nx_ * vndf_ny_;
    for (std::size_t k = 0; k < n_slices; ++k) {
        std::vector<double> values(v.begin() + std::ptrdiff_t(k * slice),
                                   v.begin() + std::ptrdiff_t((k + 1) * slice));
        double total = 0;
        for (double& x : values) {
            if (!(x >= 0)) throw InputError(where, "vndf", "holds a negative value");
            total += x;
        }
        if (!(total > 0)) throw InputError(where, "vndf", "a slice holds only zeros");
        vndf_.emplace_back(std::move(values), int(vndf_nx_), int(vndf_ny_));
    }
}

std::vector<double> RglReader::theta_i_deg() const {
    std::vector<double> out;
    for (double t : theta_nodes_)
        out.push_back(rad_to_deg(t));
    return out;
}

Rgbd RglReader::eval(const Vec3d& wi_in, const Vec3d& wo_in) const {
    Vec3d wi = wi_in, wo = wo_in;
    if (!(wi.z > 0) || !(wo.z > 0)) return Rgbd(0.0);
    if (reduction_ >= 2) {
        // Into the slices' range: ωi.y ≤ 0 (and ωi.x ≤ 0 for a quarter), ωo mirrored with it.
        if (wi.y >= 0) wi.y = -wi.y, wo.y = -wo.y;
        if (reduction_ == 4 && wi.x >= 0) wi.x = -wi.x, wo.x = -wo.x;
    }
    const Vec3d sum = wi + wo;
    if (!(dot(sum, sum) > 0)) return Rgbd(0.0);
    const Vec3d wm = normalize(sum);
    const double theta_i = std::acos(std::min(1.0, wi.z)), phi_i = std::atan2(wi.y, wi.x);
    const double theta_m = std::acos(std::min(1.0, wm.z)), phi_m = std::atan2(wm.y, wm.x);
    const double ux = rgl::theta_to_u(theta_m);
    double uy = rgl::phi_to_u(isotropic_ ? phi_m - phi_i : phi_m);
    uy -= std::floor(uy);

    // The slices around (φi, θi) and their weights: the readers interpolate the warps' masses
    // and S multilinearly in the parameters.
    const auto [k, w] = rgl::incidence_weight(theta_nodes_, theta_i);
    const auto [p, v] =
        isotropic_ ? rgl::IncidenceWeight{0, 0.0} : rgl::incidence_weight(phi_nodes_, phi_i);
    const std::size_t n_inc = theta_nodes_.size(), n_phi = phi_nodes_.size();
    struct Corner {
        std::size_t slice;
        double weight;
    };
    std::vector<Corner> corners;
    for (std::size_t b = 0; b < 2 && p + b < n_phi; ++b)
        for (std::size_t e = 0; e < 2 && k + e < n_inc; ++e) {
            const double weight = (b == 0 ? 1 - v : v) * (e == 0 ? 1 - w : w);
            if (weight != 0) corners.push_back({(p + b) * n_inc + k + e, weight});
        }

    // s: the blended warps' masses at u(ωm), then S at s.
    double left = 0, row = 0, below = 0;
    for (const Corner& c : corners) {
        const BilinearWarp::Masses m = vndf_[c.slice].masses({ux, uy});
        left += c.weight * m.left, row += c.weight * m.row, below += c.weight * m.below;
    }
    const double sx = row > 0 ? std::clamp(left / row, 0.0, 1.0) : 0.0,
                 sy = std::clamp(below, 0.0, 1.0);
    const std::size_t plane = s_nx_ * s_ny_;
    Rgbd s(0.0);
    for (const Corner& c : corners)
        for (int ch = 0; ch < 3; ++ch)
            s[ch] += c.weight * rgl::bilinear(rgb_.data() + (c.slice * 3 + std::size_t(ch)) * plane,
                                              s_nx_, s_ny_, sx, sy);
    for (int c = 0; c < 3; ++c)
        s[c] = std::max(0.0, s[c]);  // pbrt-v4 clamps the interpolated value
    const double d = rgl::bilinear(ndf_.data(), ndf_nx_, ndf_ny_, ux, uy);
    const double sigma = rgl::bilinear(sigma_.data(), sigma_nx_, sigma_ny_,
                                       rgl::theta_to_u(theta_i), rgl::phi_to_u(phi_i));
    if (!(sigma > 0)) return Rgbd(0.0);
    return s * (d / (4 * sigma * wo.z));
}

}  // namespace lamina
