#include "models/production/threejs_dfg.h"

#include "core/check.h"
#include "core/math.h"
#include "layers/data_files.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace lamina {

namespace {

/// three.js's texture (data/production/threejs_dfg.csv): E = scale + bias of each texel, row
/// by row (μ), the roughness parameter fastest, as its half floats hold them.
struct ShippedTexture {
    std::array<double, ThreeJsDfgTexture::kSize * ThreeJsDfgTexture::kSize> albedo{};
    ShippedTexture() {
        const auto rows = data_file_rows("production/threejs_dfg.csv");
        LAMINA_CHECK(rows.size() == albedo.size());
        for (const auto& row : rows)
            albedo.at(std::size_t(std::stoi(row.at(0)) * ThreeJsDfgTexture::kSize +
                                  std::stoi(row.at(1)))) =
                std::stod(row.at(2)) + std::stod(row.at(3));
    }
};
const ShippedTexture& shipped() {
    static const ShippedTexture texture;
    return texture;
}

/// The GL reading of a coordinate on an axis of n texels with clamped edges: the texel below
/// the sample point (x n − ½), the weight of the next; both indices clamped to [0, n − 1].
struct Bracket {
    int i0, i1;
    double t;
};
Bracket texel_bracket(double x, int n) {
    const double u = x * n - 0.5, lower = std::floor(u);
    const int i = int(lower);
    return {std::clamp(i, 0, n - 1), std::clamp(i + 1, 0, n - 1), u - lower};
}

}  // namespace

ThreeJsDfgTexture::ThreeJsDfgTexture(double roughness) {
    const Bracket b = texel_bracket(roughness, kSize);
    t_ = b.t;
    const int columns[2] = {b.i0, b.i1};
    for (int c = 0; c < 2; ++c)
        for (int y = 0; y < kSize; ++y)
            albedo_[c * kSize + y] = shipped().albedo[std::size_t(y * kSize + columns[c])];
}

double ThreeJsDfgTexture::albedo(double mu_o) const {
    const Bracket b = texel_bracket(mu_o, kSize);
    auto at = [&](int c) { return mix(albedo_[c * kSize + b.i0], albedo_[c * kSize + b.i1], b.t); };
    return mix(at(0), at(1), t_);
}

}  // namespace lamina
