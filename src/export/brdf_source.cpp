#include "export/brdf_source.h"

#include "core/error.h"
#include "core/math.h"
#include "core/spherical.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

BrdfSource model_brdf(std::shared_ptr<const Model> model, const Stack& stack,
                      const std::string& where) {
    const Support s = model->support();
    if (!s.brdf) throw InputError(where, "model", "the BRDF is not supported: " + s.reason);
    for (double t = 0; t < 90; t += 5)
        if (!model->delta_lobes(incident_direction(deg_to_rad(t))).empty())
            throw InputError(where, "model",
                             fmt::format("{} has a delta lobe here (a smooth interface): a table "
                                         "cannot hold a Dirac; give the interface some roughness",
                                         model->name()));
    BrdfSource out;
    out.name = model->name();
    out.isotropic = !stack.is_anisotropic();
    out.f = [model](const Vec3d& wi, const Vec3d& wo) { return model->eval(wi, wo); };
    return out;
}

BrdfSource table_brdf(const BinnedTable& table, const std::string& name, const std::string& where) {
    if (!table.has_reflection || table.theta_i_deg.empty())
        throw InputError(where, "side", "the table has no reflection (R) rows to export");
    if (table.grid.is_unfolded())
        throw InputError(where, "phi_lo",
                         "an unfolded table (φ over [0°, 360°): an anisotropic stack or light "
                         "from φi ≠ 0) holds the BRDF at one φi; a .bsdf or MERL file needs it "
                         "at every φi: export the model (--model, --stack) instead, or write the "
                         "table as .npz");
    BrdfSource out;
    out.name = name;
    out.theta_i_deg = table.theta_i_deg;
    const auto t = std::make_shared<BinnedTable>(table);
    out.f = [t](const Vec3d& wi, const Vec3d& wo) {
        const std::vector<double>& inc = t->theta_i_deg;
        const double theta_i = rad_to_deg(theta_of(wi));
        std::size_t k = 0;
        for (std::size_t i = 1; i < inc.size(); ++i)
            if (std::abs(inc[i] - theta_i) < std::abs(inc[k] - theta_i)) k = i;
        const HemisphereGrid& g = t->grid;
        const BinnedLobe& lobe = t->lobe(k, Side::Reflection);
        // Bin-centre coordinates: θ index x = θ/Δθ − ½, folded φ of wo relative to wi's azimuth.
        const double phi_i = std::atan2(wi.y, wi.x);
        double phi = std::abs(std::remainder(std::atan2(wo.y, wo.x) - phi_i, 2 * kPi<double>));
        const double x = std::clamp(theta_of(wo) / (kPi<double> / 2) * g.n_theta() - 0.5, 0.0,
                                    g.n_theta() - 1.0);
        const double y = std::clamp(phi / kPi<double> * g.n_phi() - 0.5, 0.0, g.n_phi() - 1.0);
        const int i0 = std::min(int(x), std::max(0, g.n_theta() - 2));
        const int j0 = std::min(int(y), std::max(0, g.n_phi() - 2));
        const int i1 = std::min(i0 + 1, g.n_theta() - 1), j1 = std::min(j0 + 1, g.n_phi() - 1);
        const double s = x - i0, u = y - j0;
        auto at = [&](int i, int j) { return lobe.f[std::size_t(i) * g.n_phi() + j]; };
        const Rgbd f = (at(i0, j0) * (1 - u) + at(i0, j1) * u) * (1 - s) +
                       (at(i1, j0) * (1 - u) + at(i1, j1) * u) * s;
        // A spectral run's linear sRGB may be negative in a bin (docs/formats.md); a BRDF file
        // holds none.
        return Rgbd(std::max(f[0], 0.0), std::max(f[1], 0.0), std::max(f[2], 0.0));
    };
    return out;
}

}  // namespace lamina
