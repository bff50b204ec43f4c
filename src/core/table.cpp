#include "core/table.h"

#include "core/error.h"
#include "core/incidences.h"
#include "core/setting.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <sstream>

namespace lamina {

BinnedTable BinnedTable::zeros(const HemisphereGrid& grid, const std::vector<double>& theta_i_deg,
                               bool reflection, bool transmission) {
    BinnedTable t{grid, theta_i_deg, reflection, transmission, {}};
    t.lobes.resize(theta_i_deg.size());
    for (auto& pair : t.lobes) {
        if (reflection) pair[0] = {std::vector<Rgbd>(grid.size()), std::vector<Rgbd>(grid.size())};
        if (transmission)
            pair[1] = {std::vector<Rgbd>(grid.size()), std::vector<Rgbd>(grid.size())};
    }
    return t;
}

Rgbd BinnedTable::albedo(std::size_t incidence, Side side) const {
    const BinnedLobe& l = lobe(incidence, side);
    Rgbd sum(0.0);
    for (std::size_t j = 0; j < l.f.size(); ++j)
        sum += l.f[j] * grid.projected_solid_angle(j);
    return sum;
}

std::string BinnedTable::to_csv() const {
    std::string out = std::string(kBrdfCsvHeader) + "\n";
    for (std::size_t i = 0; i < theta_i_deg.size(); ++i) {
        for (const Side side : {Side::Reflection, Side::Transmission}) {
            if (side == Side::Reflection ? !has_reflection : !has_transmission) continue;
            const BinnedLobe& l = lobe(i, side);
            for (int t = 0; t < grid.n_theta(); ++t) {
                for (int p = 0; p < grid.n_phi(); ++p) {
                    const std::size_t j = std::size_t(t) * grid.n_phi() + p;
                    fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},{},{},{},{},{},{}\n",
                                   theta_i_deg[i], side == Side::Reflection ? 'R' : 'T',
                                   grid.theta_lo_deg(t), grid.theta_hi_deg(t), grid.phi_lo_deg(p),
                                   grid.phi_hi_deg(p), l.f[j][0], l.f[j][1], l.f[j][2], l.se[j][0],
                                   l.se[j][1], l.se[j][2]);
                }
            }
        }
    }
    return out;
}

BinnedTable BinnedTable::from_csv(const std::string& text, const std::string& where) {
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line) || line != kBrdfCsvHeader)
        throw InputError(where, "line 1", fmt::format("expected the header '{}'", kBrdfCsvHeader));
    struct Row {
        double theta_i;
        char side;
        int t, p;
        Rgbd f, se;
    };
    std::vector<Row> rows;
    int max_t = -1, max_p = -1, n_theta_guess = 0, n_phi_guess = 0;
    std::size_t line_no = 1;
    while (std::getline(in, line)) {
        ++line_no;
        if (line.empty()) continue;
        std::vector<std::string> cells;
        std::stringstream ls(line);
        for (std::string cell; std::getline(ls, cell, ',');)
            cells.push_back(cell);
        if (cells.size() != 12)
            throw InputError(where, fmt::format("line {}", line_no),
                             fmt::format("expected 12 columns, found {}", cells.size()));
        // A decimal number as every number lamina reads (setting_detail::parse_real): no hex
        // floats, and subnormals are numbers (std::stod refused them as out of range).
        auto num = [&](int c) {
            double v = 0;
            if (!setting_detail::parse_real(cells[c], v))
                throw InputError(where, fmt::format("line {}, column {}", line_no, c + 1),
                                 fmt::format("'{}' is not a finite decimal number", cells[c]));
            return v;
        };
        if (cells[1] != "R" && cells[1] != "T")
            throw InputError(where, fmt::format("line {}, column 2", line_no),
                             fmt::format("side '{}' must be R or T", cells[1]));
        const double theta_lo = num(2), theta_hi = num(3), phi_lo = num(4), phi_hi = num(5);
        if (!(theta_lo >= 0 && theta_hi > theta_lo && theta_hi <= 90 && phi_lo >= 0 &&
              phi_hi > phi_lo && phi_hi <= 360))
            throw InputError(where, fmt::format("line {}", line_no),
                             "a bin must have 0 ≤ theta_lo < theta_hi ≤ 90 and 0 ≤ phi_lo < "
                             "phi_hi ≤ 360 (degrees; beyond 180 on the unfolded grid only)");
        const int n_theta = int(std::lround(90.0 / (theta_hi - theta_lo)));
        const int n_phi = int(std::lround(180.0 / (phi_hi - phi_lo)));
        if (n_theta > 3600 || n_phi > 3600 ||
            (n_theta_guess != 0 && (n_theta != n_theta_guess || n_phi != n_phi_guess)))
            throw InputError(where, fmt::format("line {}", line_no),
                             "the bins do not form one regular grid (at most 3600 bins a side)");
        n_theta_guess = n_theta;
        n_phi_guess = n_phi;
        Row r{num(0),
              cells[1][0],
              int(std::lround(theta_lo / 90.0 * n_theta)),
              int(std::lround(phi_lo / 180.0 * n_phi)),
              Rgbd(num(6), num(7), num(8)),
              Rgbd(num(9), num(10), num(11))};
        // A bin average of a BSDF is below 10¹² /sr: all of the energy in the smallest bin of
        // the finest grid read (3600 × 3600, Ω⊥ ≈ 1.7·10⁻¹⁰ sr) is ≈ 6·10⁹. A larger value is a
        // broken table, and its square would overflow the metrics. Values may be negative: a
        // spectral run's linear sRGB is (docs/formats.md); standard errors may not.
        for (int c = 0; c < 6; ++c) {
            const double v = c < 3 ? r.f[c] : r.se[c - 3];
            const double lo = c < 3 ? -kMaxBinValue : 0.0;
            if (!(v >= lo && v <= kMaxBinValue))
                throw InputError(
                    where, fmt::format("line {}, column {}", line_no, 7 + c),
                    fmt::format("{} {} is outside [{:g}, {:g}] (1/sr)",
                                c < 3 ? "the value" : "the standard error", v, lo, kMaxBinValue));
        }
        if (!incidence_in_range(r.theta_i))
            throw InputError(where, fmt::format("line {}, column 1", line_no),
                             fmt::format("theta_i {} is outside [0, 90) degrees", r.theta_i));
        // The edges must be the grid's (to rounding): a bin of another layout is refused.
        if (std::abs(theta_lo - 90.0 * r.t / n_theta) > 1e-6 ||
            std::abs(theta_hi - 90.0 * (r.t + 1) / n_theta) > 1e-6 ||
            std::abs(phi_lo - 180.0 * r.p / n_phi) > 1e-6 ||
            std::abs(phi_hi - 180.0 * (r.p + 1) / n_phi) > 1e-6)
            throw InputError(where, fmt::format("line {}", line_no),
                             "the bin's edges are not those of a uniform NTHETAxNPHI grid over "
                             "θ ∈ [0°, 90°], φ ∈ [0°, 180°] (or [0°, 360°) unfolded)");
        max_t = std::max(max_t, r.t);
        max_p = std::max(max_p, r.p);
        rows.push_back(r);
    }
    if (rows.empty()) throw InputError(where, "", "the table has no rows");
    // Bins beyond φ = 180° make the grid the unfolded one (core/grid.h).
    const HemisphereGrid folded(n_theta_guess, n_phi_guess);
    const HemisphereGrid grid = max_p >= n_phi_guess ? folded.unfolded() : folded;
    if (max_t + 1 != grid.n_theta() || max_p + 1 != grid.n_phi())
        throw InputError(where, "", "the bins do not form a regular grid");
    std::vector<double> incidences;
    bool has_r = false, has_t = false;
    for (const Row& r : rows) {
        if (incidences.empty() || incidences.back() != r.theta_i) {
            if (std::find(incidences.begin(), incidences.end(), r.theta_i) == incidences.end())
                incidences.push_back(r.theta_i);
        }
        (r.side == 'R' ? has_r : has_t) = true;
    }
    BinnedTable table = zeros(grid, incidences, has_r, has_t);
    std::size_t expected = incidences.size() * grid.size() * (has_r + has_t);
    if (rows.size() != expected)
        throw InputError(where, "",
                         fmt::format("expected {} rows for {} incidences on a {} grid, found {}",
                                     expected, incidences.size(), grid.to_string(), rows.size()));
    std::vector<char> seen(expected, 0);
    for (const Row& r : rows) {
        const std::size_t i =
            std::find(incidences.begin(), incidences.end(), r.theta_i) - incidences.begin();
        BinnedLobe& l = table.lobe(i, r.side == 'R' ? Side::Reflection : Side::Transmission);
        const std::size_t j = std::size_t(r.t) * grid.n_phi() + r.p;
        const std::size_t key =
            (i * (has_r + has_t) + (r.side == 'R' || !has_r ? 0 : 1)) * grid.size() + j;
        if (seen[key]++)
            throw InputError(
                where, "",
                fmt::format("the bin θ ∈ [{}°, {}°], φ ∈ [{}°, {}°] of θi = {}°, side "
                            "{} appears twice",
                            90.0 * r.t / grid.n_theta(), 90.0 * (r.t + 1) / grid.n_theta(),
                            180.0 * r.p / grid.n_phi(), 180.0 * (r.p + 1) / grid.n_phi(), r.theta_i,
                            r.side));
        l.f[j] = r.f;
        l.se[j] = r.se;
    }
    return table;
}

}  // namespace lamina
