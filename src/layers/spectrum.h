#pragma once
// A quantity of a stack as a function of the vacuum wavelength (docs/physics.md §10,
// docs/stack-format.md "Spectra"): a measured table, a Sellmeier or Cauchy dispersion formula, or
// a glass named by its Abbe number. The stack file's form of it is kept (`given`), so that a
// stack writes back what it read.

#include <string>
#include <vector>

namespace lamina {

/// The range of wavelengths, in nm, over which spectra are checked and traced: the visible range
/// of the CIE 1931 observer.
inline constexpr double kSpectrumMinNm = 360, kSpectrumMaxNm = 830;

struct Spectrum {
    enum class Form { Table, Sellmeier, Cauchy };
    Form form = Form::Table;
    /// Table: the samples (λ in nm, strictly increasing; value), linearly interpolated, constant
    /// beyond the ends.
    std::vector<double> wavelengths_nm, values;
    /// Sellmeier: B1, C1, B2, C2, … (C in µm²): n² = 1 + Σ Bᵢ λ²/(λ² − Cᵢ), λ in µm.
    /// Cauchy: A, B, C, … : n = A + B/λ² + C/λ⁴ + …, λ in µm.
    std::vector<double> coefficients;
    /// The stack file's JSON text of the value (what stack_to_json writes back).
    std::string given;

    /// The value at the vacuum wavelength lambda_nm.
    double at(double lambda_nm) const;
    /// The wavelengths in [lo_nm, hi_nm] where a Cauchy formula turns (its polynomial in 1/λ² has
    /// a zero derivative there): with the range's ends, where it takes its extreme values over
    /// the range. Empty for the other forms (a table is linear between its samples; a Sellmeier
    /// formula is checked for resonances where it is read).
    std::vector<double> turning_points_nm(double lo_nm, double hi_nm) const;
    bool operator==(const Spectrum&) const = default;
};

Spectrum table_spectrum(std::vector<double> wavelengths_nm, std::vector<double> values);
Spectrum sellmeier_spectrum(std::vector<double> b_c);
Spectrum cauchy_spectrum(std::vector<double> coefficients);
/// The two-term Cauchy formula n = A + B/λ² through the refractive index n_d at the helium d line
/// (587.56 nm) with the Abbe number V_d = (n_d − 1)/(n_F − n_C), F and C the hydrogen lines at
/// 486.13 and 656.27 nm (the definition of the Abbe number: ISO 7944).
Spectrum abbe_spectrum(double n_d, double v_d);

/// The named measured materials (data/nk: a conductor's n and k; data/glass: a dielectric's n).
/// "" when lamina ships none by that name; `names` lists them for messages.
bool is_conductor_material(const std::string& name);
bool is_glass_material(const std::string& name);
std::string conductor_material_names();
std::string glass_material_names();
/// A conductor's n (eta) and k of a named metal; a glass's n (Sellmeier). Precondition: the name
/// is one lamina ships.
Spectrum conductor_material_eta(const std::string& name);
Spectrum conductor_material_k(const std::string& name);
Spectrum glass_material_eta(const std::string& name);

}  // namespace lamina
