// Anisotropic interfaces in the goniophotometer: the stack format (alpha [alpha_x, alpha_y],
// tangent_deg), the unfolded grid, and the proofs of docs/physics.md §3 ("Anisotropic
// roughness"): equal roughnesses reproduce the isotropic tables, swapping α_x and α_y is turning
// the tangent by 90°, turning every tangent and the light by ψ turns the table by ψ in φ, and one
// anisotropic conductor reproduces the anisotropic microfacet BRDF (closed form, integrated over
// the bins by an independent quadrature here). Statistical comparisons use fixed seeds and
// tolerances from the tables' standard errors.
#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"
#include "layers/stack.h"
#include "physics/conductor.h"
#include "physics/fresnel.h"
#include "physics/microsurface_walk.h"
#include "simulator/goniophotometer.h"
#include "support/stacks.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

Stack parse(const std::string& text) {
    return parse_stack(text, "test.json");
}

std::string conductor_json(const std::string& roughness) {
    return R"({"layers": [{"interface": {"type": "conductor", "eta": 0.2, "k": 3, )" + roughness +
           "}}]}";
}

TEST(Anisotropy, StackFormat) {
    const Stack s = parse(conductor_json(R"("alpha": [0.1, 0.4], "tangent_deg": 30)"));
    const InterfaceSpec& i = s.base();
    EXPECT_EQ(i.alpha, 0.1);
    EXPECT_EQ(i.alpha_y, 0.4);
    EXPECT_EQ(i.tangent_deg, 30);
    EXPECT_TRUE(s.is_anisotropic());
    EXPECT_EQ(stack_from_json(stack_to_json(s), "again"), s);
    EXPECT_NE(describe(s).find("α=(0.1, 0.4) ψ=30°"), std::string::npos) << describe(s);
    // Equal roughnesses: not anisotropic; an isotropic stack's canonical JSON is unchanged.
    EXPECT_FALSE(parse(conductor_json(R"("alpha": [0.3, 0.3])")).is_anisotropic());
    const Stack iso = parse(conductor_json(R"("alpha": 0.3)"));
    EXPECT_FALSE(stack_to_json(iso)["layers"][0]["interface"].contains("tangent_deg"));
    EXPECT_TRUE(stack_to_json(iso)["layers"][0]["interface"]["alpha"].is_number());

    const auto fails = [&](const std::string& roughness, const std::string& says) {
        try {
            parse(conductor_json(roughness));
            ADD_FAILURE() << roughness << " was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
        }
    };
    fails(R"("alpha": [0.1, 0.2, 0.3])",
          "/layers/0/interface/alpha: expected a number or [alpha_x");
    fails(R"("alpha": [0.1, 0])", "/layers/0/interface/alpha/1");
    fails(R"("alpha": [0.1, 2])", "[0.0001, 1]");
    fails(R"("alpha": 0.1, "tangent_deg": 400)", "/layers/0/interface/tangent_deg");
    fails(R"("alpha": 0.1, "tangent_deg": "x")", "/layers/0/interface/tangent_deg");
    try {
        parse(
            R"({"layers": [{"interface": {"type": "lambertian", "albedo": 0.5, "tangent_deg": 3}}]})");
        ADD_FAILURE() << "a Lambertian tangent was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("unknown key \"tangent_deg\""), std::string::npos);
    }
}

TEST(Anisotropy, UnfoldedGrid) {
    const HemisphereGrid folded(9, 9);
    const HemisphereGrid grid = folded.unfolded();
    ASSERT_TRUE(grid.is_unfolded());
    EXPECT_EQ(grid.n_phi(), 18);
    EXPECT_EQ(grid.to_string(), "9x9 unfolded");
    double total = 0;
    for (std::size_t j = 0; j < grid.size(); ++j)
        total += grid.projected_solid_angle(j);
    EXPECT_NEAR(total, kPi<double>, 1e-12);
    for (double phi : {5.0, 95.0, 185.0, 275.0, 355.0}) {
        const Vec3d w = direction_from_angles(deg_to_rad(60.0), deg_to_rad(phi));
        const std::size_t j = grid.bin_of(w);
        EXPECT_EQ(int(j) / 18, 6);
        EXPECT_EQ(int(j) % 18, int(phi / 20)) << phi;
        EXPECT_EQ(folded.bin_of(w) % 9, std::size_t(phi < 180 ? phi / 20 : (360 - phi) / 20));
    }
}

// Both kernels trace an anisotropic stack and light from φi ≠ 0 (kernel_simd_test.cpp compares
// their tables); auto takes the SIMD kernel for them.
TEST(Anisotropy, BothKernelsTraceAnisotropyAndAzimuths) {
    const Stack s = parse(conductor_json(R"("alpha": [0.1, 0.4])"));
    SimulationSettings settings;
    settings.theta_i_deg = {30};
    settings.particles = 100;
    for (const Kernel kernel : {Kernel::Simd, Kernel::Scalar}) {
        settings.kernel = kernel;
        settings.phi_i_deg = 0;
        EXPECT_NO_THROW(simulate(s, settings));
        settings.phi_i_deg = 10;
        EXPECT_NO_THROW(simulate(parse(conductor_json(R"("alpha": 0.2)")), settings));
    }
    settings.kernel = Kernel::Auto;
    EXPECT_EQ(kernel_for(settings, s), Kernel::Simd);
}

// ---- Statistical proofs -------------------------------------------------------------------------

SimulationSettings anisotropic_scalar_settings(double theta_i, std::uint64_t particles,
                                               int n = 18) {
    SimulationSettings s;
    s.theta_i_deg = {theta_i};
    s.particles = particles;
    s.grid = HemisphereGrid(n, n);
    s.kernel = Kernel::Scalar;
    s.threads = 2;
    return s;
}

// Counts the bins (of one channel) where |a − b| exceeds k standard errors of the difference, among
// those where either is non-zero; `map(j)` is b's bin for a's bin j.
template <typename Map>
void expect_tables_agree(const BinnedLobe& a, const BinnedLobe& b, std::size_t n, Map map,
                         const std::string& what, double k = 4.5) {
    int compared = 0, outside = 0;
    double worst = 0;
    for (std::size_t j = 0; j < n; ++j) {
        const std::size_t jb = map(j);
        const double fa = a.f[j][0], fb = b.f[jb][0];
        if (fa == 0 && fb == 0) continue;
        const double se = std::hypot(a.se[j][0], b.se[jb][0]);
        ++compared;
        const double z = std::abs(fa - fb) / std::max(se, 1e-300);
        worst = std::max(worst, z);
        if (z > k) ++outside;
    }
    // At k = 4.5 a bin is outside with probability 7e-6 under the hypothesis of equality.
    EXPECT_EQ(outside, 0) << what << ": " << outside << " of " << compared << " bins beyond " << k
                          << " se (worst " << worst << ")";
    EXPECT_GT(compared, 20) << what;
}

Stack brushed_conductor(double alpha_x, double alpha_y, double tangent_deg) {
    return test::make_stack({layer_of(anisotropic(
        conductor_interface(Rgbd(0.2), Rgbd(3.0), alpha_x), alpha_x, alpha_y, tangent_deg))});
}

TEST(AnisotropyStat, NearlyEqualRoughnessesReproduceTheIsotropicTable) {
    // α_y = α_x (1 + 1e-6) takes the anisotropic instance of every formula and the unfolded grid;
    // folded back (the two mirror patches averaged), it is the isotropic table. With exactly equal
    // roughnesses the stack is isotropic and the table is the isotropic one bit for bit.
    for (bool multiple : {false, true}) {
        SimulationSettings s = anisotropic_scalar_settings(50, 400'000);
        s.transport.microsurface = multiple ? Microsurface::Multiple : Microsurface::Single;
        const Stack iso = brushed_conductor(0.3, 0.3, 40);
        ASSERT_FALSE(iso.is_anisotropic());
        const SimulationResult a = simulate(iso, s);
        const SimulationResult same = simulate(
            test::make_stack({layer_of(conductor_interface(Rgbd(0.2), Rgbd(3.0), 0.3))}), s);
        EXPECT_EQ(a.table.lobe(0, Side::Reflection).f, same.table.lobe(0, Side::Reflection).f);
        s.seed = 7;
        const SimulationResult b = simulate(brushed_conductor(0.3, 0.3 * (1 + 1e-6), 40), s);
        ASSERT_TRUE(b.table.grid.is_unfolded());
        // Fold b: the folded bin (t, p) is the mean of the unfolded bins p and 2n − 1 − p.
        const int n = 18;
        BinnedLobe folded = a.table.lobe(0, Side::Reflection);
        const BinnedLobe& u = b.table.lobe(0, Side::Reflection);
        for (int t = 0; t < n; ++t)
            for (int p = 0; p < n; ++p) {
                const std::size_t j = std::size_t(t * n + p);
                const std::size_t j1 = std::size_t(t * 2 * n + p),
                                  j2 = std::size_t(t * 2 * n + 2 * n - 1 - p);
                folded.f[j] = (u.f[j1] + u.f[j2]) * 0.5;
                for (int c = 0; c < 3; ++c)
                    folded.se[j][c] = 0.5 * std::hypot(u.se[j1][c], u.se[j2][c]);
            }
        expect_tables_agree(
            folded, a.table.lobe(0, Side::Reflection), std::size_t(n * n),
            [](std::size_t j) { return j; }, multiple ? "multiple" : "single");
    }
}

TEST(AnisotropyStat, SwappingRoughnessesIsTurningTheTangentBy90Degrees) {
    SimulationSettings s = anisotropic_scalar_settings(40, 400'000);
    const SimulationResult a = simulate(brushed_conductor(0.1, 0.4, 20), s);
    s.seed = 11;
    const SimulationResult b = simulate(brushed_conductor(0.4, 0.1, 110), s);
    const std::size_t n = a.table.grid.size();
    expect_tables_agree(
        a.table.lobe(0, Side::Reflection), b.table.lobe(0, Side::Reflection), n,
        [](std::size_t j) { return j; }, "swap");
}

TEST(AnisotropyStat, TurningTangentsAndLightTurnsTheTable) {
    // A coat brushed one way over a base brushed another, both tangents and the light turned by
    // ψ = 60° (a multiple of the 10° bins): the table turns by ψ in φ, bin for bin.
    const auto stack = [](double turn) {
        Layer coat = test::dielectric_layer(1.5, 0.1);
        coat.interface = anisotropic(coat.interface, 0.05, 0.2, 10 + turn);
        coat = with_medium(coat, Rgbd(0.1));
        const Layer base = layer_of(
            anisotropic(conductor_interface(Rgbd(0.2), Rgbd(3.0), 0.1), 0.1, 0.35, -35 + turn));
        return test::make_stack({coat, base});
    };
    SimulationSettings s = anisotropic_scalar_settings(35, 400'000);
    s.phi_i_deg = 20;
    const SimulationResult a = simulate(stack(0), s);
    s.phi_i_deg = 80;
    s.seed = 5;
    const SimulationResult b = simulate(stack(60), s);
    const int n_phi = 36, shift = 6;  // 60° of 10° bins
    expect_tables_agree(
        a.table.lobe(0, Side::Reflection), b.table.lobe(0, Side::Reflection), a.table.grid.size(),
        [&](std::size_t j) {
            const int t = int(j) / n_phi, p = int(j) % n_phi;
            return std::size_t(t * n_phi + (p + shift) % n_phi);
        },
        "turned");
}

// The anisotropic microfacet BRDF of one conductor with the height-correlated Smith G2, written
// here from angles in the tangent frame (Walter et al. 2007, Eq. 20, with the anisotropic GGX D
// and Λ with α(φ)), and its cos-weighted average over a bin by a midpoint rule.
struct ClosedForm {
    double alpha_x, alpha_y, psi;
    double D(const Vec3d& m) const {
        const double phi = std::atan2(m.y, m.x) - psi, cos2 = m.z * m.z, tan2 = (1 - cos2) / cos2;
        const double e = tan2 * (sqr(std::cos(phi) / alpha_x) + sqr(std::sin(phi) / alpha_y));
        return 1 / (kPi<double> * alpha_x * alpha_y * cos2 * cos2 * sqr(1 + e));
    }
    double lambda(const Vec3d& w) const {
        const double phi = std::atan2(w.y, w.x) - psi, cos2 = w.z * w.z, tan2 = (1 - cos2) / cos2;
        const double a2 = sqr(std::cos(phi) * alpha_x) + sqr(std::sin(phi) * alpha_y);
        return (-1 + std::sqrt(1 + a2 * tan2)) / 2;
    }
    double f(const Vec3d& wi, const Vec3d& wo) const {
        const Vec3d m = normalize(wi + wo);
        const double F = fresnel_conductor(dot(wi, m), 0.2, 3.0);
        return F * D(m) / (1 + lambda(wi) + lambda(wo)) / (4 * wi.z * wo.z);
    }
};

// ∫_bin f cos θ dω / Ω⊥ by a 24 × 24 midpoint rule in (sin²θ, φ), whose measure is the projected
// solid angle (d(sin²θ)/2 dφ); `below`: the bin's mirror image under the surface.
template <typename F>
double bin_midpoint_average(const HemisphereGrid& grid, int t, int p, bool below, const F& f) {
    const double s0 = sqr(std::sin(grid.theta_lo(t))), s1 = sqr(std::sin(grid.theta_hi(t)));
    constexpr int kNodes = 24;
    double sum = 0;
    for (int a = 0; a < kNodes; ++a)
        for (int b = 0; b < kNodes; ++b) {
            const double u = s0 + (s1 - s0) * (a + 0.5) / kNodes;
            const double phi =
                grid.phi_lo(p) + (grid.phi_hi(p) - grid.phi_lo(p)) * (b + 0.5) / kNodes;
            const double st = std::sqrt(u), ct = std::sqrt(1 - u);
            sum += f(Vec3d{st * std::cos(phi), st * std::sin(phi), below ? -ct : ct});
        }
    return sum / (kNodes * kNodes);
}

void single_conductor_matches_the_closed_form(Kernel kernel) {
    const ClosedForm brdf{0.15, 0.45, deg_to_rad(25.0)};
    SimulationSettings s = anisotropic_scalar_settings(40, 1'000'000);
    s.kernel = kernel;
    s.phi_i_deg = 30;
    s.transport.microsurface = Microsurface::Single;
    s.transport.polarization = false;
    const SimulationResult r =
        simulate(brushed_conductor(brdf.alpha_x, brdf.alpha_y, rad_to_deg(brdf.psi)), s);
    const HemisphereGrid& grid = r.table.grid;
    const BinnedLobe& lobe = r.table.lobe(0, Side::Reflection);
    const Vec3d wi = direction_from_angles(deg_to_rad(40.0), deg_to_rad(30.0));
    int compared = 0, outside = 0;
    double worst = 0;
    for (int t = 0; t < grid.n_theta(); t += 2)
        for (int p = 0; p < grid.n_phi(); p += 3) {
            const double expected = bin_midpoint_average(
                grid, t, p, false, [&](const Vec3d& wo) { return brdf.f(wi, wo); });
            const std::size_t j = std::size_t(t) * grid.n_phi() + std::size_t(p);
            const double measured = lobe.f[j][0], se = lobe.se[j][0];
            if (expected < 1e-3) continue;
            ++compared;
            // The midpoint rule's error on these smooth lobes (α ≥ 0.15 over 5° × 10° bins) is
            // below 0.5 %, added to the statistical tolerance.
            const double z = std::abs(measured - expected) / (se + 5e-3 * expected);
            worst = std::max(worst, z);
            if (z > 4.5) ++outside;
        }
    EXPECT_EQ(outside, 0) << outside << " of " << compared << " bins (worst " << worst << ")";
    EXPECT_GT(compared, 30);
}

// The rough dielectric of relative index eta with the anisotropic D and Λ of ClosedForm (Walter et
// al. 2007, Eqs. 20 and 21) and the Smith microsurface's G2: 1/(1 + Λi + Λo) for reflection,
// B(1 + Λi, 1 + Λo) for refraction (docs/physics.md §3; std::beta).
double dielectric_closed_form(const ClosedForm& c, double eta, const Vec3d& wi, const Vec3d& wo) {
    const bool reflect = wo.z > 0;
    Vec3d m = reflect ? wi + wo : -(wi + wo * eta);
    m = normalize(m);
    if (m.z < 0) m = -m;
    const double ci = dot(wi, m), co = dot(wo, m);
    if (ci <= 0 || (reflect ? co <= 0 : co >= 0)) return 0;
    const double F = fresnel_dielectric(ci, eta);
    const double li = c.lambda(wi), lo = c.lambda(wo);
    if (reflect) return F * c.D(m) / (1 + li + lo) / (4 * wi.z * wo.z);
    const double G2 = std::beta(1 + li, 1 + lo);
    return (1 - F) * c.D(m) * G2 * eta * eta * std::abs(ci * co) /
           (std::abs(wi.z * wo.z) * sqr(ci + eta * co));
}

void single_dielectric_matches_the_closed_form(Kernel kernel) {
    const ClosedForm shape{0.2, 0.5, deg_to_rad(-40.0)};
    const double eta = 1.5;
    SimulationSettings s = anisotropic_scalar_settings(50, 1'000'000);
    s.kernel = kernel;
    s.phi_i_deg = 10;
    s.transport.microsurface = Microsurface::Single;
    s.transport.polarization = false;
    const Stack stack = test::make_stack({layer_of(
        anisotropic(dielectric_interface(eta, shape.alpha_x), shape.alpha_x, shape.alpha_y, -40))});
    const SimulationResult r = simulate(stack, s);
    const HemisphereGrid& grid = r.table.grid;
    const Vec3d wi = direction_from_angles(deg_to_rad(50.0), deg_to_rad(10.0));
    int compared = 0, outside = 0;
    double worst = 0;
    for (Side side : {Side::Reflection, Side::Transmission}) {
        const BinnedLobe& lobe = r.table.lobe(0, side);
        for (int t = 0; t < grid.n_theta(); t += 2)
            for (int p = 0; p < grid.n_phi(); p += 3) {
                const double expected = bin_midpoint_average(
                    grid, t, p, side == Side::Transmission,
                    [&](const Vec3d& wo) { return dielectric_closed_form(shape, eta, wi, wo); });
                const std::size_t j = std::size_t(t) * grid.n_phi() + std::size_t(p);
                if (expected < 1e-3) continue;
                ++compared;
                const double z =
                    std::abs(lobe.f[j][0] - expected) / (lobe.se[j][0] + 5e-3 * expected);
                worst = std::max(worst, z);
                if (z > 4.5) ++outside;
            }
    }
    EXPECT_EQ(outside, 0) << outside << " of " << compared << " bins (worst " << worst << ")";
    EXPECT_GT(compared, 60);
}

// On both kernels (each instantiates the general GGX templates; the SIMD kernel on its vectors).
TEST(AnisotropyStat, SingleConductorMatchesTheAnisotropicMicrofacetBrdf) {
    for (const Kernel kernel : {Kernel::Scalar, Kernel::Simd}) {
        SCOPED_TRACE(enum_text(kernel));
        single_conductor_matches_the_closed_form(kernel);
    }
}

TEST(AnisotropyStat, SingleDielectricMatchesTheAnisotropicMicrofacetBsdf) {
    for (const Kernel kernel : {Kernel::Scalar, Kernel::Simd}) {
        SCOPED_TRACE(enum_text(kernel));
        single_dielectric_matches_the_closed_form(kernel);
    }
}

TEST(AnisotropyStat, WalkFirstOrderIsTheSingleScatteringInterface) {
    // The fraction of anisotropic microsurface walks that leave after their first facet is the
    // single-scattering interface's escape fraction E[G2/G1] (its first order, docs/physics.md §3),
    // on a conductor whose facets reflect everything (F = 1).
    const GGX<double> ggx = GGX<double>::anisotropic(0.3, 0.7, 0.6);
    const ConductorInterface<double> iface{Rgbd(1.0), Rgbd(0.0), 0.3, false, ggx.anisotropy};
    const auto white = [](double) { return Rgbd(1.0); };
    for (double theta : {20.0, 60.0, 80.0}) {
        for (double phi : {0.0, 1.2}) {
            const Vec3d wi = direction_from_angles(deg_to_rad(theta), phi);
            ParticleRng rng(3, std::uint64_t(theta * 10 + phi), 0);
            auto uniform = [&] { return double(rng.uniform_float()); };
            constexpr int kN = 200'000;
            double first = 0, escape = 0, escape2 = 0;
            for (int n = 0; n < kN; ++n) {
                const auto e = walk_rough_conductor<true>(ggx, white, wi, uniform, 100);
                if (e && e->escaped && e->order == 1) first += 1;
                const auto smp = iface.sample<false, true>(wi, uniform(), uniform());
                const double g = smp ? smp->shadowing : 0.0;
                escape += g;
                escape2 += g * g;
            }
            const double p = first / kN, mean = escape / kN;
            const double se = std::hypot(std::sqrt(p * (1 - p) / kN),
                                         std::sqrt(std::max(0.0, escape2 / kN - mean * mean) / kN));
            EXPECT_NEAR(p, mean, 4.5 * se) << theta << " " << phi;
            EXPECT_LT(p, 1.0);
        }
    }
}

TEST(AnisotropyStat, UnfoldedTablesAreReciprocal) {
    // Reciprocity, f(wa, wb) = f(wb, wa), on a rough coat brushed one way over a conductor brushed
    // another, polarized with multiple scattering (the defaults): the table lit from wa, in the bin
    // that holds wb, against the table lit from wb, in the bin that holds wa. Each direction sits
    // at its bin's centroid in the bins' own measure (uniform in sin²θ and φ), so the bin average
    // differs from the point value only to second order in the bin width (≈ 0.5 % for these
    // roughnesses, a sixth of the standard error of the difference). Light from two azimuths,
    // two polar angles each: six pairs, three channels.
    Layer coat = test::dielectric_layer(1.5, 0.3);
    coat.interface = anisotropic(coat.interface, 0.3, 0.5, 20);
    coat = with_medium(coat, Rgbd(0.05, 0.1, 0.2));
    const Layer base = layer_of(anisotropic(
        conductor_interface(Rgbd(0.2, 0.4, 1.2), Rgbd(3.4, 2.4, 1.9), 0.2), 0.2, 0.6, -35));
    const Stack stack = test::make_stack({coat, base});
    const auto centroid_theta = [](double lo_deg, double hi_deg) {
        const double u =
            (sqr(std::sin(deg_to_rad(lo_deg))) + sqr(std::sin(deg_to_rad(hi_deg)))) / 2;
        return rad_to_deg(std::asin(std::sqrt(u)));
    };
    const double thetas[2] = {centroid_theta(20, 25), centroid_theta(45, 50)};
    const double phis[2] = {5, 125};  // centres of the 10° bins [0°, 10°) and [120°, 130°)
    struct Lit {
        Vec3d w;
        const BinnedLobe* lobe;
    };
    std::vector<SimulationResult> runs;
    for (int a = 0; a < 2; ++a) {
        SimulationSettings s = anisotropic_scalar_settings(0, 1'000'000);
        s.theta_i_deg = {thetas[0], thetas[1]};
        s.phi_i_deg = phis[a];
        s.seed = 17 + a;
        runs.push_back(simulate(stack, s));
        ASSERT_TRUE(runs.back().table.grid.is_unfolded());
    }
    std::vector<Lit> lit;
    for (int a = 0; a < 2; ++a)
        for (int t = 0; t < 2; ++t)
            lit.push_back({direction_from_angles(deg_to_rad(thetas[t]), deg_to_rad(phis[a])),
                           &runs[std::size_t(a)].table.lobe(std::size_t(t), Side::Reflection)});
    const HemisphereGrid& grid = runs[0].table.grid;
    int compared = 0;
    for (std::size_t i = 0; i < lit.size(); ++i)
        for (std::size_t j = i + 1; j < lit.size(); ++j) {
            const std::size_t bin_j = grid.bin_of(lit[j].w), bin_i = grid.bin_of(lit[i].w);
            for (int c = 0; c < 3; ++c) {
                const double fij = lit[i].lobe->f[bin_j][c], fji = lit[j].lobe->f[bin_i][c];
                const double se = std::hypot(lit[i].lobe->se[bin_j][c], lit[j].lobe->se[bin_i][c]);
                ASSERT_GT(fij, 0);
                EXPECT_LT(std::abs(fij - fji), 4.5 * se)
                    << "pair " << i << "-" << j << " channel " << c << ": " << fij << " vs " << fji
                    << " (se " << se << ")";
                ++compared;
            }
        }
    EXPECT_EQ(compared, 18);
}

TEST(AnisotropyStat, LightFromAnotherAzimuthDrawsOtherNumbers) {
    // A smooth interface lit from φi = 0 and φi = 60° with the same seed: the physics is the
    // same (the reflected energy agrees within its standard errors), the random numbers are not
    // (the incidence's stream includes φi), so the two estimates differ by noise. On a smooth
    // interface each particle's fate (reflect if u < F) does not depend on the azimuth, so a
    // shared stream would give the same estimate to rounding.
    const Stack stack = test::make_stack({test::dielectric_layer(1.5, 0.0)});
    SimulationSettings s = anisotropic_scalar_settings(50, 200'000, 6);
    const double r0 = simulate(stack, s).incidences[0].budget[BudgetTerm::Reflected][0];
    s.phi_i_deg = 60;
    const SimulationResult b = simulate(stack, s);
    const double r60 = b.incidences[0].budget[BudgetTerm::Reflected][0];
    const double se = b.incidences[0].budget.reflected_se[0];
    EXPECT_LT(std::abs(r60 - r0), 4.5 * std::sqrt(2.0) * se) << r0 << " " << r60;
    EXPECT_GT(std::abs(r60 - r0), 0.01 * se) << "the same random numbers at both azimuths";
}

TEST(AnisotropyStat, MultipleScatteringConservesEnergyOnAWhiteConductor) {
    // The white furnace: a conductor of F ≈ 1 (a tiny real part, a huge k: F > 0.9996 at every
    // angle) with multiple scattering keeps all but what F absorbs; single scattering loses the
    // masked part. Both anisotropic, unfolded.
    Stack s = test::make_stack(
        {layer_of(anisotropic(conductor_interface(Rgbd(0.01), Rgbd(10.0), 0.2), 0.2, 0.8, 15))});
    SimulationSettings settings = anisotropic_scalar_settings(60, 200'000);
    settings.transport.polarization = false;
    const SimulationResult multiple = simulate(s, settings);
    const EnergyBudget& b = multiple.incidences[0].budget;
    EXPECT_LT(b[BudgetTerm::LostMicrosurface][0], 1e-4);
    EXPECT_GT(b[BudgetTerm::Reflected][0], 0.995);
    EXPECT_NEAR(b.sum()[0], 1, 1e-9);
    settings.transport.microsurface = Microsurface::Single;
    const SimulationResult single = simulate(s, settings);
    EXPECT_GT(single.incidences[0].budget[BudgetTerm::LostMicrosurface][0], 0.02);
}

}  // namespace
}  // namespace lamina
