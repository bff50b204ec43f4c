// Bin averages of the models on the goniophotometer's grid.
#include "models/numerics/binned.h"
#include "core/error.h"
#include "core/math.h"
#include "core/spherical.h"
#include "models/registry.h"
#include "models/tables/fgd_table.h"
#include "models/test_stacks.h"
#include "physics/conductor.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace lamina {
namespace {

using test::coated;

/// ∫ f μo dωo of a model by a dense midpoint rule in (u, φ), independent of the adaptive rule.
Rgbd dense_albedo(const Model& model, const Vec3d& wi, Side side, int nu = 800, int nphi = 300) {
    Rgbd sum(0.0);
    for (int a = 0; a < nu; ++a)
        for (int b = 0; b < nphi; ++b) {
            const double u = (a + 0.5) / nu, phi = kPi<double> * (b + 0.5) / nphi;
            const double s = std::sqrt(u), z = std::sqrt(1 - u);
            sum += model.eval(
                wi, Vec3d(s * std::cos(phi), s * std::sin(phi), side == Side::Reflection ? z : -z));
        }
    return sum * (kPi<double> / (double(nu) * nphi));
}

// A model's binned table integrates to its own albedo: Σ_j f_j Ω⊥_j (the goniophotometer's
// energy) equals ∫ f μo dωo computed by an independent dense rule, for every model on a rough
// configuration it supports, both sides where it has them.
// Slow (every model × three stacks): in the `stat` label.
TEST(BinnedStat, IntegratesToTheModelsOwnAlbedo) {
    const Stack plastic = coated(1.5, 0.2, test::lambertian(Rgbd(0.8, 0.4, 0.1)), Rgbd(0.1));
    const Stack metal = coated(1.5, 0.2, test::gold(0.3), Rgbd(0.1));
    const Stack slab = coated(1.5, 0.25, test::dielectric(1.3, 0.3), Rgbd(0.05));
    const HemisphereGrid grid(45, 45);
    for (const auto& entry : model_registry()) {
        if (entry.stochastic) continue;  // tested against the goniophotometer instead
        for (const Stack* s : {&plastic, &metal, &slab}) {
            const auto model = entry.make(*s, resolve_options(entry, {}));
            if (!model->support().brdf) continue;
            const BinnedTable t = bin_model(*model, grid, {20, 65});
            for (std::size_t i = 0; i < 2; ++i) {
                const Vec3d wi = incident_direction(deg_to_rad(t.theta_i_deg[i]));
                for (Side side : {Side::Reflection, Side::Transmission}) {
                    if (side == Side::Transmission && !model->support().btdf) continue;
                    const Rgbd want = dense_albedo(*model, wi, side);
                    const Rgbd got = t.albedo(i, side);
                    for (int c = 0; c < 3; ++c)
                        EXPECT_NEAR(got[c], want[c], 2e-4 * want[c] + 2e-5)
                            << entry.name << " " << t.theta_i_deg[i] << " side " << int(side);
                }
            }
        }
    }
}

// A sharp lobe (α = 0.001) sits inside one bin: no coarse node sees it, and the quadrature must
// still find all of it. Bel' on a bare rough conductor is the exact microfacet reflection, whose
// albedo is FGD(μi, α, η, κ) by definition (computed directly, no table; on 512 × 512 nodes, whose
// value at 85° is within 5·10⁻⁶ of 256 × 256, where 64 × 64 is 3.6·10⁻⁵ off). At 85° the lobe
// is narrow in φ and wider in θ: it leaks past the rectangles that hold its peak, and without
// their neighbours bisected with them the table missed 0.7 % of it. Just off the normal (θi of
// 0.001°–0.5°, the lobe 0.06° wide) the lobe spills over the pole into the bins of every azimuth,
// which the rectangles next to the peak's in (θ, φ) do not reach: the table and model_albedo
// missed up to 85 % of it there. model_albedo's 16 × 16 rectangles likewise, up to 85° (2.7·10⁻⁴
// low there while a peak's neighbours were only the rectangles within one size of it).
TEST(Binned, CapturesSharpLobes) {
    const InterfaceSpec base = test::gold(0.001);
    const auto model = make_model("bel-prime", test::single(base));
    const std::vector<double> thetas = {0, 0.001, 0.01, 0.05, 0.1, 0.5, 30, 70, 85};
    const BinnedTable t = bin_model(*model, HemisphereGrid(90, 90), thetas);
    for (std::size_t i = 0; i < t.theta_i_deg.size(); ++i) {
        const double c = std::cos(deg_to_rad(t.theta_i_deg[i]));
        const Rgbd albedo =
            model_albedo(*model, incident_direction(deg_to_rad(thetas[i])), Side::Reflection);
        for (int ch = 0; ch < 3; ++ch) {
            const double want = FgdTable::direct(c, 0.001, base.eta_rgb[ch], base.k[ch], 512, 512);
            EXPECT_NEAR(t.albedo(i, Side::Reflection)[ch], want, 1e-4 * want)
                << t.theta_i_deg[i] << " " << ch;
            EXPECT_NEAR(albedo[ch], want, 1e-4 * want) << t.theta_i_deg[i] << " " << ch;
        }
    }
}

// Each bin is good to 1e-4 relative: the default tables against ones computed with a tolerance
// 100× tighter and deeper refinement, for a rough, a glossy (α = 0.05) and a sharp (α = 0.001)
// configuration, on the 90 × 90 grid (bins below 1e-6 of the lobe's peak bin are compared in
// absolute terms). The tighter run refines with the same adaptive rule and shares its blindness to
// bends along θ alone: the check independent of it is the composite rule of
// SharedNodesSettleSmoothBinsAtFewerEvaluationsWithinTheTolerance below.
TEST(Binned, BinAveragesAreGoodTo1e4Relative) {
    BinnedOptions tight;
    tight.rel_tol = 1e-6;
    tight.max_depth = 14;
    tight.eval_budget = 2000000;
    for (const Stack& s : {coated(1.5, 0.3, test::gold(0.3)), coated(1.5, 0.05, test::gold(0.1)),
                           test::single(test::gold(0.001))}) {
        for (const char* name : {"bel-prime", "ww-prime"}) {
            const auto model = make_model(name, s);
            if (!model->support().brdf) continue;
            const HemisphereGrid grid(90, 90);
            // 30°, and 0.5°, where the lobe of α = 0.001 spans a dozen bins of the pole's row.
            const BinnedTable a = bin_model(*model, grid, {30, 0.5});
            const BinnedTable b = bin_model(*model, grid, {30, 0.5}, tight);
            for (std::size_t i = 0; i < 2; ++i) {
                const auto& fa = a.lobe(i, Side::Reflection).f;
                const auto& fb = b.lobe(i, Side::Reflection).f;
                double peak = 0;
                for (const Rgbd& v : fb)
                    peak = std::max(peak, v.max());
                for (std::size_t j = 0; j < fa.size(); ++j)
                    for (int c = 0; c < 3; ++c)
                        ASSERT_NEAR(fa[j][c], fb[j][c], 1e-4 * fb[j][c] + 1e-10 * peak)
                            << name << " θi " << a.theta_i_deg[i] << " bin " << j;
            }
        }
    }
}

/// A model's evaluations counted (all threads), the model otherwise itself.
class CountingModel final : public Model {
  public:
    explicit CountingModel(std::unique_ptr<Model> inner) : inner_(std::move(inner)) {}
    std::string name() const override { return inner_->name(); }
    Support support() const override { return inner_->support(); }
    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        ++evaluations;
        return inner_->eval(wi, wo);
    }
    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        return inner_->peak_directions(wi);
    }
    mutable std::atomic<long> evaluations{0};

  private:
    std::unique_ptr<Model> inner_;
};

/// The cos-weighted average over [θ0, θ1] × [φ0, φ1] by a 12 × 12 composite of 3 × 3
/// Gauss–Legendre rules, independent of bin_model's adaptive rules.
Rgbd composite_average(const Model& model, const Vec3d& wi, double t0, double t1, double p0,
                       double p1) {
    constexpr int kN = 12;
    const double x[3] = {0.5 - 0.3872983346207417, 0.5, 0.5 + 0.3872983346207417};
    const double w[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
    Rgbd sum(0.0);
    double weight = 0;
    for (int i = 0; i < kN; ++i)
        for (int j = 0; j < kN; ++j)
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                    const double theta = t0 + (t1 - t0) * (i + x[a]) / kN;
                    const double phi = p0 + (p1 - p0) * (j + x[b]) / kN;
                    const double c = w[a] * w[b] * std::sin(2 * theta);
                    sum += model.eval(wi, direction_from_angles(theta, phi)) * c;
                    weight += c;
                }
    return sum / weight;
}

// Neighbouring bins share the nodes of their edges (the shared-node pass, binned.cpp): a smooth
// lobe costs under 6 evaluations per bin rather than RectIntegrator's 9 at least (and more near
// a peak), and every bin is
// still within its tolerance of an independent composite rule (every bin of every third row and
// column, the horizon's row included).
TEST(Binned, SharedNodesSettleSmoothBinsAtFewerEvaluationsWithinTheTolerance) {
    for (const char* name : {"bel-prime", "openpbr"}) {
        CountingModel model(make_model(name, coated(1.5, 0.3, test::gold(0.3))));
        const HemisphereGrid grid(90, 90);
        for (double theta_i : {0.0, 40.0, 75.0}) {
            model.evaluations = 0;
            const BinnedTable t = bin_model(model, grid, {theta_i});
            // At normal incidence the peak is at the pole, and the bins of the first rows, of
            // every azimuth, are split towards it.
            EXPECT_LT(double(model.evaluations) / double(grid.size()), theta_i == 0 ? 8.0 : 6.0)
                << name << " θi " << theta_i;
            const Vec3d wi = incident_direction(deg_to_rad(theta_i));
            const auto& f = t.lobe(0, Side::Reflection).f;
            for (int r = 0; r < 90; r += 3)
                for (int p = 0; p < 90; p += 3) {
                    const int row = r == 87 ? 89 : r;
                    const Rgbd want =
                        composite_average(model, wi, grid.theta_lo(row), grid.theta_hi(row),
                                          grid.phi_lo(p), grid.phi_hi(p));
                    const Rgbd got = f[std::size_t(row) * 90 + p];
                    const BinnedOptions o;
                    const double tol = o.rel_tol * want.max() + o.abs_tol;
                    for (int c = 0; c < 3; ++c)
                        ASSERT_NEAR(got[c], want[c], tol)
                            << name << " θi " << theta_i << " bin " << row << "," << p;
                }
        }
    }
}

/// f = 1 below the line θ = a + b φ and 0 above it: a cut-off inside a bin, as a model's total
/// internal reflection or a term that switches off makes one. Counts its evaluations.
class StepEvaluator final : public IncidentEvaluator {
  public:
    StepEvaluator(double a, double b) : a_(a), b_(b) {}
    Rgbd eval(const Vec3d& wo) const override {
        ++evaluations;
        return theta_of(wo) < a_ + b_ * phi_of(wo) ? Rgbd(1.0) : Rgbd(0.0);
    }
    mutable long evaluations = 0;

  private:
    double a_, b_;
};

// A jump along a curve inside the bin: the rectangles along it keep their error however small
// they get, so the evaluation budget decides. The bin average against its closed form: with
// θc(φ) = a + b φ inside [θ0, θ1], ∫∫_{θ<θc} sin θ cos θ dθ dφ = ∫ (sin²θc − sin²θ0)/2 dφ, and
// ∫ sin²(a + b φ) dφ = φ/2 − sin(2a + 2b φ)/(4b). Each accepted rectangle the line crosses is
// off by at most its own weight (f is 0 or 1 and the 3×3 rule's weights are positive); with the
// budget spent evenly along the line, the rectangles it crosses at depth d weigh about 2·2⁻ᵈ of
// the bin, so N evaluations (9 per rectangle, 4 rectangles per split) leave about
// 2 / (N / 36 / 2) of it — the bound below, and the evaluations stay within the budget. (Spent
// depth first, the same budgets refine one end of the line to max_depth and leave the rest
// coarse: 1.7 % and 2.3 % of the bin off at 2000 and 10⁴, the latter past this bound.)
TEST(Binned, AJumpInsideABinCostsItsBudgetAndIsGoodToWhatTheBudgetBuys) {
    // One bin of the default grid, 1° × 2°: the budget is per such bin.
    const double t0 = deg_to_rad(40.0), t1 = deg_to_rad(41.0);
    const double p0 = deg_to_rad(20.0), p1 = deg_to_rad(22.0);
    // The line from (θ0, φ0 + ¼ of the width) to (θ1, φ1 − ¼ of it), diagonal across the bin.
    const double b = (t1 - t0) / ((p1 - p0) / 2), a = t0 - b * (p0 + (p1 - p0) / 4);
    const double pa = (t0 - a) / b, pb = (t1 - a) / b;  // where the line enters and leaves
    auto sin2_integral = [&](double phi) {
        return phi / 2 - std::sin(2 * a + 2 * b * phi) / (4 * b);
    };
    const double s0 = sqr(std::sin(t0)), s1 = sqr(std::sin(t1));
    // [p0, pa]: f = 0 everywhere (the line is below θ0); [pa, pb]: up to the line; [pb, p1]: 1.
    const double inside = 0.5 * (sin2_integral(pb) - sin2_integral(pa) - s0 * (pb - pa)) +
                          0.5 * (s1 - s0) * (p1 - pb);
    const double want = inside / (0.5 * (s1 - s0) * (p1 - p0));
    for (long budget : {2000L, 10000L, 50000L}) {
        BinnedOptions options;
        options.eval_budget = budget;
        StepEvaluator f(a, b);
        const Rgbd got = cos_weighted_average(f, Side::Reflection, t0, t1, p0, p1, {}, options);
        const double bound = 2.0 / (double(budget) / 36 / 2);
        EXPECT_NEAR(got[0], want, bound * want) << "budget " << budget;
        // The last split may start when the budget is all but spent: four rectangles over it.
        EXPECT_LE(f.evaluations, budget + 9 + 36) << "budget " << budget;
    }
}

/// f = 1 below the line θ = a + b φ (φ ∈ [0, π], the folded grid's) and 0 above it, as a model.
class StepModel final : public Model {
  public:
    StepModel(double a, double b) : a_(a), b_(b) {}
    std::string name() const override { return "step"; }
    Support support() const override { return {true, false, ""}; }
    Rgbd eval(const Vec3d& /*wi*/, const Vec3d& wo) const override {
        return theta_of(wo) < a_ + b_ * std::abs(std::atan2(wo.y, wo.x)) ? Rgbd(1.0) : Rgbd(0.0);
    }

  private:
    double a_, b_;
};

// A jump along a line across many bins of the table: the bins the line crosses take the adaptive
// rule and are good to what its budget buys (the bound of the test above); every other bin is
// exactly 0 or 1, although the shared-node rules of the bins next to the line reach half a bin
// into the bins it crosses. Against the bin averages by the inner integral in closed form,
// ∫_{θ0}^{min(θc, θ1)} sin θ cos θ dθ = (sin² min(θc, θ1) − sin² θ0)/2, over φ by a midpoint rule
// of 4000 nodes per bin (its error, where θc enters or leaves the bin, is of order 10⁻⁸).
TEST(Binned, AJumpAcrossTheTableIsLeftToTheAdaptiveRule) {
    const double a = deg_to_rad(20.0), b = 0.25;
    const StepModel model(a, b);
    const HemisphereGrid grid(90, 90);
    const BinnedTable t = bin_model(model, grid, {30});
    const auto& f = t.lobe(0, Side::Reflection).f;
    const double bound = 2.0 / (double(BinnedOptions{}.eval_budget) / 36 / 2);
    int crossed = 0;
    for (int row = 0; row < 90; ++row)
        for (int p = 0; p < 90; ++p) {
            const double t0 = grid.theta_lo(row), t1 = grid.theta_hi(row);
            const double p0 = grid.phi_lo(p), p1 = grid.phi_hi(p);
            constexpr int kNodes = 4000;
            double inside = 0;
            for (int k = 0; k < kNodes; ++k) {
                const double phi = p0 + (p1 - p0) * (k + 0.5) / kNodes;
                const double theta_c = std::clamp(a + b * phi, t0, t1);
                inside += (sqr(std::sin(theta_c)) - sqr(std::sin(t0))) / 2;
            }
            const double want = inside * (p1 - p0) / kNodes /
                                (0.5 * (p1 - p0) * (sqr(std::sin(t1)) - sqr(std::sin(t0))));
            const double got = f[std::size_t(row) * 90 + p][0];
            const bool crosses = a + b * p0 < t1 && a + b * p1 > t0;
            crossed += crosses;
            if (crosses)
                EXPECT_NEAR(got, want, bound) << "bin " << row << "," << p;
            else
                EXPECT_NEAR(got, want, 1e-12) << "bin " << row << "," << p;
        }
    EXPECT_GT(crossed, 100);
}

// Delta lobes: a smooth bare conductor puts F(μi)/Ω⊥ into the mirror bin and nothing elsewhere.
TEST(Binned, DeltaLobeLandsInTheMirrorBin) {
    const InterfaceSpec base = test::gold(0.0);
    const auto model = make_model("bel-prime", test::single(base));
    const HemisphereGrid grid(90, 90);
    const BinnedTable t = bin_model(*model, grid, {30.5});
    const Vec3d wi = incident_direction(deg_to_rad(30.5));
    const std::size_t j = grid.bin_of(mirror_direction(wi));
    const ConductorInterface<double> exact{base.eta_rgb, base.k, 0.0};
    const Rgbd F = exact.fresnel(wi.z);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(t.lobe(0, Side::Reflection).f[j][c] * grid.projected_solid_angle(j), F[c],
                    1e-12);
        EXPECT_NEAR(t.albedo(0, Side::Reflection)[c], F[c], 1e-12);
    }
}

// ---- The unfolded grid (an anisotropic stack, or light from φi ≠ 0: core/grid.h) --------------
// The largest |a − b| allowed between two bin averages each good to τ = rel_tol·|f| + abs_tol.
double two_tolerances(double a, double b) {
    const BinnedOptions o;
    return o.rel_tol * (std::abs(a) + std::abs(b)) + 2 * o.abs_tol;
}

// Lit from φi = 0, an isotropic model's unfolded table is its folded one on the half y ≥ 0 (the
// same rectangles and peaks: bitwise) and the mirror image on y < 0 (mirrored nodes: within the
// two bins' tolerances); its albedo over the full azimuth is the folded one's.
TEST(Binned, UnfoldedGridAtPhiZeroIsTheFoldedTableMirrored) {
    for (const Stack& s : {coated(1.5, 0.3, test::gold(0.3)), coated(1.5, 0.05, test::gold(0.1))}) {
        const auto model = make_model("bel-prime", s);
        const HemisphereGrid folded(18, 18), unfolded = folded.unfolded();
        const BinnedTable a = bin_model(*model, folded, {30});
        const BinnedTable b = bin_model(*model, unfolded, {30}, 0.0);
        ASSERT_EQ(b.grid, unfolded);
        const auto& fa = a.lobe(0, Side::Reflection).f;
        const auto& fb = b.lobe(0, Side::Reflection).f;
        const int n = unfolded.n_phi();
        for (int t = 0; t < folded.n_theta(); ++t)
            for (int p = 0; p < folded.n_phi(); ++p) {
                const Rgbd& folded_f = fa[std::size_t(t * folded.n_phi() + p)];
                const Rgbd& upper = fb[std::size_t(t * n + p)];
                const Rgbd& lower = fb[std::size_t(t * n + n - 1 - p)];
                for (int c = 0; c < 3; ++c) {
                    EXPECT_EQ(upper[c], folded_f[c]) << "bin " << t << "," << p;
                    EXPECT_NEAR(lower[c], folded_f[c], two_tolerances(lower[c], folded_f[c]))
                        << "bin " << t << "," << p;
                }
            }
        BinnedOptions full;
        full.full_azimuth = true;
        const Vec3d wi = incident_direction(deg_to_rad(30.0));
        const Rgbd half = model_albedo(*model, wi, Side::Reflection);
        const Rgbd whole = model_albedo(*model, wi, Side::Reflection, full);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(whole[c], half[c], two_tolerances(whole[c], half[c]));
    }
}

// Light from φi = k·Δφ (Δφ the bin width) turns an isotropic model's unfolded table by k bins, the
// peaks and the delta lobe with it; off the grid's bins the light still gets the same energy.
TEST(Binned, TurningTheLightTurnsTheUnfoldedTable) {
    const HemisphereGrid grid = HemisphereGrid(18, 18).unfolded();  // 36 bins of 10°
    const int n = grid.n_phi(), k = 5;
    for (const Stack& s : {coated(1.5, 0.2, test::gold(0.25)), test::single(test::gold(0.0))}) {
        const auto model = make_model("bel-prime", s);
        const BinnedTable a = bin_model(*model, grid, {40}, 0.0);
        const BinnedTable b = bin_model(*model, grid, {40}, 10.0 * k);
        const auto& fa = a.lobe(0, Side::Reflection).f;
        const auto& fb = b.lobe(0, Side::Reflection).f;
        for (int t = 0; t < grid.n_theta(); ++t)
            for (int p = 0; p < n; ++p) {
                const Rgbd& turned = fb[std::size_t(t * n + (p + k) % n)];
                const Rgbd& f = fa[std::size_t(t * n + p)];
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(turned[c], f[c], two_tolerances(turned[c], f[c]) + 1e-9 * f[c])
                        << "bin " << t << "," << p;
            }
        const BinnedTable off = bin_model(*model, grid, {40}, 123.4);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(off.albedo(0, Side::Reflection)[c], a.albedo(0, Side::Reflection)[c],
                        2e-4 * a.albedo(0, Side::Reflection)[c]);
    }
}

// Output does not depend on the thread count (every bin is computed independently), also for the
// models whose evaluator for one thread keeps what depends on wo.z (openpbr, unity-stacklit).
TEST(Binned, DeterministicForAnyThreadCount) {
    for (const char* name : {"bel18-symmetric", "openpbr", "unity-stacklit"}) {
        const auto model = make_model(name, coated(1.5, 0.1, test::gold(0.2)));
        const int before = omp_get_max_threads();
        omp_set_num_threads(1);
        const BinnedTable a = bin_model(*model, HemisphereGrid(30, 30), {0, 45});
        omp_set_num_threads(3);
        const BinnedTable b = bin_model(*model, HemisphereGrid(30, 30), {0, 45});
        omp_set_num_threads(before);
        EXPECT_EQ(a.to_csv(), b.to_csv()) << name;
    }
}

// The table has exactly the goniophotometer's brdf.csv form and reads back.
TEST(Binned, WritesTheBrdfCsvFormat) {
    const auto model = make_model("bel-prime", coated(1.5, 0.2, test::dielectric(1.3, 0.3)));
    const BinnedTable t = bin_model(*model, HemisphereGrid(9, 6), {0, 60});
    const std::string csv = t.to_csv();
    EXPECT_EQ(csv.substr(0, csv.find('\n')), kBrdfCsvHeader);
    const BinnedTable back = BinnedTable::from_csv(csv, "test");
    EXPECT_TRUE(back.has_reflection);
    EXPECT_TRUE(back.has_transmission);
    EXPECT_EQ(back.theta_i_deg, t.theta_i_deg);
    EXPECT_EQ(back.grid, t.grid);
}

// A value is a decimal number: a subnormal one (a model that returns 1e-320) reads back as itself,
// a hexadecimal one is refused by line and column (std::stod took 0x10 as 16 and refused 1e-320).
TEST(Binned, ReadsSubnormalValuesAndRefusesHexadecimal) {
    const auto model = make_model("bel-prime", coated(1.5, 0.2, test::dielectric(1.3, 0.3)));
    const std::string csv = bin_model(*model, HemisphereGrid(3, 3), {0}).to_csv();
    // The first data row's f_r (column 7) replaced.
    const auto with_f = [&](const std::string& value) {
        const std::size_t row = csv.find('\n') + 1;
        std::size_t at = row;
        for (int comma = 0; comma < 6; ++comma)
            at = csv.find(',', at) + 1;
        return csv.substr(0, at) + value + csv.substr(csv.find(',', at));
    };
    const BinnedTable tiny = BinnedTable::from_csv(with_f("1e-320"), "test");
    EXPECT_EQ(tiny.lobe(0, Side::Reflection).f[0][0], 1e-320);
    try {
        BinnedTable::from_csv(with_f("0x10"), "test");
        ADD_FAILURE() << "0x10 accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.field(), "line 2, column 7");
        EXPECT_NE(std::string(e.what()).find("'0x10' is not a finite decimal number"),
                  std::string::npos)
            << e.what();
    }
}

// On a grid whose edges are whole degrees (30 × 30: 3° in θ, 6° in φ; unfolded 6° up to 360°)
// every edge is written as the whole number, so `phi_hi == 180` selects rows on any such grid.
TEST(Binned, WritesWholeDegreeEdgesAsWholeNumbers) {
    const auto model = make_model("bel-prime", coated(1.5, 0.2, test::dielectric(1.3, 0.3)));
    for (const bool unfolded : {false, true}) {
        const HemisphereGrid grid =
            unfolded ? HemisphereGrid(30, 30).unfolded() : HemisphereGrid(30, 30);
        const BinnedTable t = bin_model(*model, grid, {30}, unfolded ? 40.0 : 0.0);
        std::istringstream in(t.to_csv());
        std::string line;
        std::getline(in, line);
        int rows = 0, last_phi = 0;
        while (std::getline(in, line)) {
            std::vector<std::string> field;
            std::stringstream ss(line);
            for (std::string f; std::getline(ss, f, ',');)
                field.push_back(f);
            ASSERT_EQ(field.size(), 12u) << line;
            for (int k = 2; k < 6; ++k)
                EXPECT_EQ(field[std::size_t(k)].find_first_not_of("0123456789"), std::string::npos)
                    << "edge '" << field[std::size_t(k)] << "' in " << line;
            last_phi = std::max(last_phi, std::stoi(field[5]));
            ++rows;
        }
        EXPECT_EQ(rows, 2 * int(grid.size()));  // the slab: R and T
        EXPECT_EQ(last_phi, unfolded ? 360 : 180);
    }
}

}  // namespace
}  // namespace lamina
