#include "layers/colorimetry.h"
#include "layers/spectrum.h"

#include "layers/data_files.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace lamina {

namespace {
constexpr double kFirstNm = 360, kStepNm = 5;
constexpr int kRows = kCie1931Rows;  // 360, 365, …, 830

/// Column `column` of a 5 nm table of data/cie.
std::vector<double> column_of(std::string_view path, std::size_t column) {
    std::vector<double> out;
    for (const auto& row : data_file_rows(path))
        out.push_back(std::stod(row.at(column)));
    return out;
}

struct Tables {
    std::array<std::vector<double>, 3> cmf;
    std::vector<double> d65;
    Tables() {
        for (std::size_t k = 0; k < 3; ++k)
            cmf[k] = column_of("cie/cie1931_xyz_5nm.csv", k + 1);
        d65 = column_of("cie/d65_5nm.csv", 1);
    }
};
const Tables& tables() {
    static const Tables t;
    return t;
}
}  // namespace

Rgbd d65_xyz_weights(double lambda_nm) {
    const double x = (lambda_nm - kFirstNm) / kStepNm;
    if (!(x >= 0) || x > kRows - 1) return Rgbd(0.0);
    const int i = std::min(int(x), kRows - 2);
    const double t = x - i;
    const Tables& tab = tables();
    const double s = tab.d65[std::size_t(i)] * (1 - t) + tab.d65[std::size_t(i + 1)] * t;
    Rgbd out;
    for (int k = 0; k < 3; ++k) {
        const auto& c = tab.cmf[std::size_t(k)];
        out[std::size_t(k)] = s * (c[std::size_t(i)] * (1 - t) + c[std::size_t(i + 1)] * t);
    }
    return out;
}

double d65_y_integral() {
    double norm_y = 0;
    constexpr int kCells = int((kSpectrumMaxNm - kSpectrumMinNm) * 10);
    for (int i = 0; i < kCells; ++i)
        norm_y += d65_xyz_weights(kSpectrumMinNm + (i + 0.5) * 0.1)[1] * 0.1;
    return norm_y;
}

Rgbd cie1931_cmf_row(int i) {
    const Tables& tab = tables();
    const auto row = std::size_t(std::clamp(i, 0, kRows - 1));
    return {tab.cmf[0][row], tab.cmf[1][row], tab.cmf[2][row]};
}

Rgbd xyz_to_linear_srgb(const Rgbd& xyz) {
    return {3.2406 * xyz[0] - 1.5372 * xyz[1] - 0.4986 * xyz[2],
            -0.9689 * xyz[0] + 1.8758 * xyz[1] + 0.0415 * xyz[2],
            0.0557 * xyz[0] - 0.2040 * xyz[1] + 1.0570 * xyz[2]};
}

}  // namespace lamina
