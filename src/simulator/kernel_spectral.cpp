#include "simulator/kernel_spectral.h"

#include "layers/colorimetry.h"
#include "simulator/scalar_particle.h"

#include <cmath>

namespace lamina {

namespace {

// The SIMD kernel's view of a spectral run (SpectralTracing::layer_lanes, structure,
// lanes_uniform): the values that differ between the stacks gathered per layer, and whether one
// stack's branches serve all of them.
void spectral_lanes(SpectralTracing& tr) {
    const std::size_t n = tr.stacks.size();
    const CompiledStack<float>& first = tr.stacks.front();
    tr.structure = first;
    tr.lanes_uniform = true;
    tr.layer_lanes.assign(first.layers.size(), {});
    for (std::size_t i = 0; i < first.layers.size(); ++i) {
        SpectralLayerLanes& lanes = tr.layer_lanes[i];
        CompiledLayer<float>& shared = tr.structure.layers[i];
        const CompiledLayer<float>& a = first.layers[i];
        for (std::size_t at = 0; at < n; ++at) {
            const CompiledStack<float>& stack = tr.stacks[at];
            const CompiledLayer<float>& l = stack.layers[i];
            // The branches the kernel takes per layer: the same in every stack, or no lanes.
            const bool same = l.type == a.type && l.delta == a.delta && l.multiple == a.multiple &&
                              l.has_film == a.has_film &&
                              l.dielectric.is_index_matched() == a.dielectric.is_index_matched();
            if (!same || (l.has_film && l.type == InterfaceType::Dielectric))
                tr.lanes_uniform = false;
            // A lane whose medium neither absorbs nor scatters at its wavelengths is traced
            // through it by the flags of the others: Beer–Lambert with τa = 0 transmits 1, and
            // free flights at its own extinction (MIS-weighted, or unweighted with one
            // extinction) estimate its transmittance without bias.
            shared.medium.absorbs = shared.medium.absorbs || l.medium.absorbs;
            shared.medium.scatters = shared.medium.scatters || l.medium.scatters;
            shared.medium.uniform_tau_t = shared.medium.uniform_tau_t && l.medium.uniform_tau_t;
            shared.medium.uniform_g = shared.medium.uniform_g && l.medium.uniform_g;
            tr.structure.polarization_channels =
                std::max(tr.structure.polarization_channels, stack.polarization_channels);
            lanes.eta.push_back(l.dielectric.eta);
            lanes.inv_eta.push_back(l.dielectric.inv_eta());
            for (int c = 0; c < 3; ++c) {
                lanes.conductor_eta[std::size_t(c)].push_back(l.conductor.eta[c]);
                lanes.conductor_k[std::size_t(c)].push_back(l.conductor.k[c]);
                lanes.albedo[std::size_t(c)].push_back(l.lambertian.albedo[c]);
                lanes.tau_a[std::size_t(c)].push_back(l.medium.tau_a[c]);
                lanes.tau_s[std::size_t(c)].push_back(l.medium.tau_s[c]);
                lanes.tau_t[std::size_t(c)].push_back(l.medium.tau_t[c]);
                lanes.g[std::size_t(c)].push_back(l.medium.g[c]);
                lanes.single_scattering_albedo[std::size_t(c)].push_back(
                    l.medium.single_scattering_albedo[c]);
            }
            lanes.dispersive.push_back(tr.dispersive[at][i] != 0 ? 1 : 0);
        }
    }
}

}  // namespace

void trace_block_spectral(const BlockJob& job, Tally& tally, BlockBudget& block) {
    const SpectralTracing& tr = *job.spectral;
    const int groups = tr.bins / 3;
    for (std::uint64_t p = job.first; p < job.first + job.count; ++p) {
        ParticleRng rng(job.seed, job.stream, p);
        const int group = int(p % std::uint64_t(groups));
        constexpr int kPoints = 3 * kSpectralLattice;  // a group's lattice points, all channels
        const int point = std::min(kPoints - 1, int(rng.uniform_float() * float(kPoints)));
        const int hero = point / kSpectralLattice;
        const int t = group * kSpectralLattice + point % kSpectralLattice;
        const std::size_t at = std::size_t(t) * 3 + std::size_t(hero);
        const CompiledStack<float>& stack = tr.stacks[at];
        SpectralParticle sp = spectral_particle(job, at, group);
        // The instance of trace_particle for the stack: polarized or not, anisotropic, filmed.
        const auto trace = [&]<bool kPolarized, bool kAnisotropic, bool kFilm>() {
            trace_particle<kPolarized, kAnisotropic, kFilm, true>(stack, *job.grid, job, rng, tally,
                                                                  block, &sp);
        };
        const bool pol = stack.polarization;
        if (stack.has_film)
            pol ? trace.template operator()<true, false, true>()
                : trace.template operator()<false, false, true>();
        else if (stack.anisotropic)
            pol ? trace.template operator()<true, true, false>()
                : trace.template operator()<false, true, false>();
        else
            pol ? trace.template operator()<true, false, false>()
                : trace.template operator()<false, false, false>();
    }
}

// A spectral run's stacks and colour weights (tally.h; docs/physics.md §10).
SpectralTracing spectral_tracing(const Stack& stack, const SimulationSettings& settings) {
    SpectralTracing tr;
    tr.bins = settings.spectral_bins;
    tr.lattice = tr.bins * kSpectralLattice;
    const int third = tr.lattice / 3;
    const double lo = settings.spectral_min_nm, hi = settings.spectral_max_nm;
    const double cell = (hi - lo) / tr.lattice;
    auto lambda = [&](int point) { return lo + (point + 0.5) * cell; };
    for (int t = 0; t < third; ++t) {
        const Rgbd wl{lambda(t), lambda(t + third), lambda(t + 2 * third)};
        // The relative index of each dielectric at the three wavelengths.
        const Stack at[3] = {stack.at_wavelengths(wl, 0), stack.at_wavelengths(wl, 1),
                             stack.at_wavelengths(wl, 2)};
        std::vector<char> dispersive(stack.layers.size(), 0);
        for (std::size_t i = 0; i < stack.layers.size(); ++i) {
            if (stack.layers[i].interface.type != InterfaceType::Dielectric) continue;
            double relative[3];
            for (int c = 0; c < 3; ++c)
                relative[c] = at[c].layers[i].interface.eta / at[c].eta_above(i);
            dispersive[i] = relative[0] != relative[1] || relative[1] != relative[2];
        }
        for (int h = 0; h < 3; ++h) {
            tr.stacks.push_back(compile_stack<float>(at[h], settings.transport));
            tr.dispersive.push_back(dispersive);
        }
    }
    // XYZ weights: the lattice sum of f · S · (x̄, ȳ, z̄) · cell over ∫ S ȳ dλ on 360–830 nm
    // (d65_y_integral), times L/3 for the three uniform channels a particle carries.
    const double norm_y = d65_y_integral();
    for (int point = 0; point < tr.lattice; ++point) {
        const Rgbd xyz = d65_xyz_weights(lambda(point)) * (cell * third / norm_y);
        const Rgbd srgb = xyz_to_linear_srgb(xyz);
        // The bound each tally contribution relies on (tally.h).
        LAMINA_CHECK(std::max(std::abs(srgb.max()), std::abs(srgb.min())) <= 5 && xyz.max() <= 5);
        tr.xyz_weight.push_back(Rgbf(xyz));
        tr.srgb_weight.push_back(Rgbf(srgb));
    }
    spectral_lanes(tr);
    return tr;
}

namespace {
/// The mean and standard error of the per-particle contributions whose sum and sum of squares a
/// tally entry holds (scales kSumScale, kSqScale), times `scale`.
std::pair<double, double> tally_estimate(Fixed128 sum, Fixed128 sum_sq, std::uint64_t n,
                                         double scale) {
    if (n == 0) return {0.0, 0.0};  // a wavelength group no particle of a tiny run reached
    const double mean = double(sum) / kSumScale / double(n);
    const double mean_sq = double(sum_sq) / kSqScale / double(n);
    const double var = std::max(0.0, mean_sq - mean * mean);
    return {mean * scale, n > 1 ? std::sqrt(var / double(n - 1)) * scale : 0.0};
}

/// The budget terms and the standard errors of R and T of one channel of a budget's sums, times
/// `scale`.
std::array<double, kBudgetTerms + 2> budget_estimate(
    const std::array<std::array<Fixed128, 3>, kBudgetTerms + 2>& sums, int c, std::uint64_t n,
    double scale) {
    std::array<double, kBudgetTerms + 2> out{};
    if (n == 0) return out;
    const double inv_n = 1.0 / double(n), dn = n > 1 ? double(n - 1) : 1.0;
    for (int t = 0; t < kBudgetTerms; ++t)
        out[std::size_t(t)] = double(sums[std::size_t(t)][std::size_t(c)]) / kBudgetScale * inv_n;
    for (int k = 0; k < 2; ++k) {
        const double m = out[std::size_t(k == 0 ? BudgetTerm::Reflected : BudgetTerm::Transmitted)];
        const double m2 =
            double(sums[std::size_t(kBudgetTerms + k)][std::size_t(c)]) / kBudgetScale * inv_n;
        out[std::size_t(kBudgetTerms + k)] = std::sqrt(std::max(0.0, m2 - m * m) / dn);
    }
    for (double& v : out)
        v *= scale;
    return out;
}

// The spectral tables of a spectral run (SpectralTables), and its sRGB table scaled back
// (IncidenceSums' spectral fields).
}  // namespace

void finalize_spectral(const SimulationSettings& settings, const SimulationSums& sums,
                       const HemisphereGrid& grid, bool transmits, SimulationResult& result) {
    SpectralTables& sp = result.spectral;
    const int bins = settings.spectral_bins, groups = bins / 3;
    const std::uint64_t n = settings.particles;
    for (int l = 0; l <= bins; ++l)
        sp.bin_edges_nm.push_back(settings.spectral_min_nm +
                                  (settings.spectral_max_nm - settings.spectral_min_nm) * l / bins);
    sp.n_directions = grid.size();
    sp.sides = transmits ? 2 : 1;
    const std::size_t n_inc = settings.theta_i_deg.size();
    sp.f.assign(n_inc * std::size_t(sp.sides) * grid.size() * std::size_t(bins), 0.0);
    sp.se = sp.f;
    sp.xyz = BinnedTable::zeros(grid, settings.theta_i_deg, true, transmits);
    // Wavelength bin c · groups + g: the mean over the n_g particles of group g of their channel
    // c (tallied divided by 4).
    for (std::size_t inc = 0; inc < n_inc; ++inc) {
        const IncidenceSums& total = sums.incidences[inc];
        for (int side = 0; side < sp.sides; ++side) {
            const Side s = side == 0 ? Side::Reflection : Side::Transmission;
            BinnedLobe& srgb = result.table.lobe(inc, s);
            BinnedLobe& xyz = sp.xyz.lobe(inc, s);
            for (std::size_t j = 0; j < grid.size(); ++j) {
                const double omega = grid.projected_solid_angle(j);
                const std::size_t entry = std::size_t(side) * grid.size() + j;
                for (int c = 0; c < 3; ++c) {
                    srgb.f[j][c] *= kSpectralTallyScale;
                    srgb.se[j][c] *= kSpectralTallyScale;
                    const auto& a = total.xyz_bins[entry];
                    const auto [m, e] = tally_estimate(a[c], a[3 + c], n, kSpectralTallyScale);
                    xyz.f[j][c] = m / omega;
                    xyz.se[j][c] = e / omega;
                    for (int g = 0; g < groups; ++g) {
                        const auto& b =
                            total.spectral_bins[entry * std::size_t(groups) + std::size_t(g)];
                        const auto [mb, eb] = tally_estimate(
                            b[c], b[3 + c], spectral_group_particles(n, groups, g), 4.0);
                        const std::size_t at = sp.index(inc, side, j, std::size_t(c * groups + g));
                        sp.f[at] = mb / omega;
                        sp.se[at] = eb / omega;
                    }
                }
            }
        }
        EnergyBudget xyz_budget;
        for (int c = 0; c < 3; ++c) {
            for (int g = 0; g < groups; ++g)
                sp.budget.emplace_back();  // filled below, in wavelength order
            const auto e = budget_estimate(total.xyz_budget, c, n, 1.0);
            for (int t = 0; t < kBudgetTerms; ++t)
                xyz_budget.term[std::size_t(t)][std::size_t(c)] = e[std::size_t(t)];
            xyz_budget.reflected_se[std::size_t(c)] = e[kBudgetTerms];
            xyz_budget.transmitted_se[std::size_t(c)] = e[kBudgetTerms + 1];
        }
        sp.xyz_budget.push_back(xyz_budget);
        const std::size_t first = inc * std::size_t(bins);
        for (int c = 0; c < 3; ++c)
            for (int g = 0; g < groups; ++g)
                sp.budget[first + std::size_t(c * groups + g)] =
                    budget_estimate(total.spectral_budget[std::size_t(g)], c,
                                    spectral_group_particles(n, groups, g), 1.0);
    }
}

}  // namespace lamina
