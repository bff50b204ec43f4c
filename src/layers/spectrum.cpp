#include "layers/spectrum.h"

#include "core/check.h"
#include "layers/data_files.h"

#include <algorithm>
#include <cmath>

namespace lamina {

double Spectrum::at(double lambda_nm) const {
    switch (form) {
        case Form::Table: {
            if (lambda_nm <= wavelengths_nm.front()) return values.front();
            if (lambda_nm >= wavelengths_nm.back()) return values.back();
            const auto hi =
                std::upper_bound(wavelengths_nm.begin(), wavelengths_nm.end(), lambda_nm);
            const std::size_t j = std::size_t(hi - wavelengths_nm.begin());
            const double t =
                (lambda_nm - wavelengths_nm[j - 1]) / (wavelengths_nm[j] - wavelengths_nm[j - 1]);
            return values[j - 1] + t * (values[j] - values[j - 1]);
        }
        case Form::Sellmeier: {
            const double l2 = (lambda_nm * 1e-3) * (lambda_nm * 1e-3);
            double n2 = 1;
            for (std::size_t i = 0; i + 1 < coefficients.size(); i += 2)
                n2 += coefficients[i] * l2 / (l2 - coefficients[i + 1]);
            return std::sqrt(std::max(n2, 0.0));
        }
        case Form::Cauchy: {
            const double inv_l2 = 1.0 / ((lambda_nm * 1e-3) * (lambda_nm * 1e-3));
            double n = 0, power = 1;
            for (double c : coefficients) {
                n += c * power;
                power *= inv_l2;
            }
            return n;
        }
    }
    return 0;
}

std::vector<double> Spectrum::turning_points_nm(double lo_nm, double hi_nm) const {
    if (form != Form::Cauchy) return {};
    // n(x) = Σ c_k x^k with x = 1/λ² (µm⁻²); n'(x) = c1 + 2 c2 x + 3 c3 x², at most quadratic.
    const auto c = [&](std::size_t k) { return k < coefficients.size() ? coefficients[k] : 0.0; };
    const double a = 3 * c(3), b = 2 * c(2), d = c(1);
    std::vector<double> roots;
    if (a != 0) {
        const double disc = b * b - 4 * a * d;
        if (disc >= 0) {
            // The stable pair of roots: q = −(b + sign(b) √disc)/2, x = q/a and d/q.
            const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
            roots.push_back(q / a);
            if (q != 0) roots.push_back(d / q);
        }
    } else if (b != 0) {
        roots.push_back(-d / b);
    }
    std::vector<double> out;
    for (double x : roots) {
        if (!(x > 0) || !std::isfinite(x)) continue;
        const double lambda_nm = 1e3 / std::sqrt(x);
        if (lambda_nm >= lo_nm && lambda_nm <= hi_nm) out.push_back(lambda_nm);
    }
    return out;
}

Spectrum table_spectrum(std::vector<double> wavelengths_nm, std::vector<double> values) {
    LAMINA_CHECK(!wavelengths_nm.empty() && wavelengths_nm.size() == values.size());
    Spectrum s;
    s.form = Spectrum::Form::Table;
    s.wavelengths_nm = std::move(wavelengths_nm);
    s.values = std::move(values);
    return s;
}
Spectrum sellmeier_spectrum(std::vector<double> b_c) {
    Spectrum s;
    s.form = Spectrum::Form::Sellmeier;
    s.coefficients = std::move(b_c);
    return s;
}
Spectrum cauchy_spectrum(std::vector<double> coefficients) {
    Spectrum s;
    s.form = Spectrum::Form::Cauchy;
    s.coefficients = std::move(coefficients);
    return s;
}
Spectrum abbe_spectrum(double n_d, double v_d) {
    constexpr double kD = 0.58756, kF = 0.48613, kC = 0.65627;  // µm
    // n_F − n_C = B (1/λF² − 1/λC²) = (n_d − 1)/V_d; A from n_d.
    const double b = (n_d - 1) / (v_d * (1 / (kF * kF) - 1 / (kC * kC)));
    return cauchy_spectrum({n_d - b / (kD * kD), b});
}

namespace {
constexpr const char* kMetals[] = {"Ag", "Al", "Au", "Cr", "Cu", "Fe", "Ni", "Pt", "Ti"};

std::string joined(auto&& names) {
    std::string out;
    for (const auto& n : names)
        out += (out.empty() ? "\"" : ", \"") + std::string(n) + "\"";
    return out;
}

std::vector<std::string> glass_names() {
    std::vector<std::string> out;
    for (const auto& row : data_file_rows("glass/sellmeier.csv"))
        out.push_back(row.at(0));
    return out;
}

Spectrum metal_column(const std::string& name, std::size_t column) {
    const auto rows = data_file_rows("nk/" + name + ".csv");
    LAMINA_CHECK(!rows.empty());
    std::vector<double> wl, v;
    for (const auto& row : rows) {
        wl.push_back(std::stod(row.at(0)));
        v.push_back(std::stod(row.at(column)));
    }
    return table_spectrum(std::move(wl), std::move(v));
}
}  // namespace

bool is_conductor_material(const std::string& name) {
    return std::find(std::begin(kMetals), std::end(kMetals), name) != std::end(kMetals);
}
bool is_glass_material(const std::string& name) {
    const auto names = glass_names();
    return std::find(names.begin(), names.end(), name) != names.end();
}
std::string conductor_material_names() {
    return joined(kMetals);
}
std::string glass_material_names() {
    return joined(glass_names());
}
Spectrum conductor_material_eta(const std::string& name) {
    return metal_column(name, 1);
}
Spectrum conductor_material_k(const std::string& name) {
    return metal_column(name, 2);
}
Spectrum glass_material_eta(const std::string& name) {
    for (const auto& row : data_file_rows("glass/sellmeier.csv"))
        if (row.at(0) == name) {
            std::vector<double> b_c;
            for (std::size_t i = 1; i < row.size(); ++i)
                b_c.push_back(std::stod(row[i]));
            while (b_c.size() >= 2 && b_c[b_c.size() - 2] == 0 && b_c.back() == 0)
                b_c.resize(b_c.size() - 2);
            return sellmeier_spectrum(std::move(b_c));
        }
    LAMINA_CHECK(false);
    return {};
}

}  // namespace lamina
