// Exports (docs/formats.md, "Exports"): an RGL .bsdf file read back by a reader written here from
// the format's definition (as pbrt-v4 and Mitsuba 3 evaluate one: invert the VNDF warp at the half
// vector, interpolate the values, apply D/(4σ)), MERL round trips, malformed files.
#include "core/error.h"
#include "core/math.h"
#include "core/spherical.h"
#include "export/brdf_source.h"
#include "export/merl.h"
#include "export/npz.h"
#include "export/rgl_bsdf.h"
#include "export/tensor_file.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/test_stacks.h"
#include "simulator/goniophotometer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

namespace lamina {
namespace {

constexpr double kPiD = kPi<double>;

// ---- an independent reader of .bsdf files ------------------------------------------------------

/// One field as float32 values with its shape.
struct Array {
    std::vector<float> v;
    std::vector<std::uint64_t> shape;
};

Array field(const TensorFile& f, const char* name) {
    const TensorField& t = f.at(name);
    return {t.floats(), t.shape};
}

/// Linear interpolation weights of x over increasing nodes (clamped at the ends).
std::pair<std::size_t, double> bracket(const std::vector<float>& nodes, double x) {
    if (nodes.size() == 1 || x <= nodes.front()) return {0, 0.0};
    if (x >= nodes.back()) return {nodes.size() - 2, 1.0};
    std::size_t k = 0;
    while (nodes[k + 1] < x)
        ++k;
    return {k, (x - nodes[k]) / (nodes[k + 1] - nodes[k])};
}

/// Bilinear interpolation of the node values of a 2D slice (ny × nx, x fastest) at x ∈ [0, 1]².
double bilinear(const float* slice, std::size_t nx, std::size_t ny, double x, double y) {
    const double gx = std::clamp(x, 0.0, 1.0) * double(nx - 1),
                 gy = std::clamp(y, 0.0, 1.0) * double(ny - 1);
    const std::size_t i = std::min<std::size_t>(std::size_t(gx), nx - 2),
                      j = std::min<std::size_t>(std::size_t(gy), ny - 2);
    const double s = gx - double(i), t = gy - double(j);
    auto at = [&](std::size_t a, std::size_t b) { return double(slice[b * nx + a]); };
    return (1 - t) * ((1 - s) * at(i, j) + s * at(i + 1, j)) +
           t * ((1 - s) * at(i, j + 1) + s * at(i + 1, j + 1));
}

/// The inverse-CDF map x → u of a bilinear density (one slice, not normalized): u_y = the mass
/// below y, u_x = the mass left of x on the row through y over that row's mass. Written from the
/// definition by summing patch integrals (no precomputed tables).
std::array<double, 3> invert_slice(const float* p, std::size_t nx, std::size_t ny, double x,
                                   double y) {
    const double dx = 1.0 / double(nx - 1), dy = 1.0 / double(ny - 1);
    auto node = [&](std::size_t a, std::size_t b) { return double(p[b * nx + a]); };
    // ∫₀¹ p(x', y_b) dx' at a node row, and ∫₀^x of the row interpolated at y.
    auto row_mass = [&](std::size_t b) {
        double m = 0;
        for (std::size_t a = 0; a + 1 < nx; ++a)
            m += 0.5 * dx * (node(a, b) + node(a + 1, b));
        return m;
    };
    double total = 0;
    for (std::size_t b = 0; b + 1 < ny; ++b)
        total += 0.5 * dy * (row_mass(b) + row_mass(b + 1));
    const double gy = std::clamp(y, 0.0, 1.0) * double(ny - 1);
    const std::size_t j = std::min<std::size_t>(std::size_t(gy), ny - 2);
    const double t = gy - double(j);
    double below = 0;
    for (std::size_t b = 0; b < j; ++b)
        below += 0.5 * dy * (row_mass(b) + row_mass(b + 1));
    const double r0 = row_mass(j), r1 = row_mass(j + 1);
    below += dy * (r0 * t + 0.5 * (r1 - r0) * t * t);
    const double gx = std::clamp(x, 0.0, 1.0) * double(nx - 1);
    const std::size_t i = std::min<std::size_t>(std::size_t(gx), nx - 2);
    const double s = gx - double(i);
    auto row_at_y = [&](std::size_t a) { return (1 - t) * node(a, j) + t * node(a, j + 1); };
    double left = 0;
    for (std::size_t a = 0; a < i; ++a)
        left += 0.5 * dx * (row_at_y(a) + row_at_y(a + 1));
    left += dx * (row_at_y(i) * s + 0.5 * (row_at_y(i + 1) - row_at_y(i)) * s * s);
    const double row = (1 - t) * r0 + t * r1;
    // (mass left of x on the row, the row's mass, the mass below y), each over the total.
    return {left / total, row / total, below / total};
}

struct BsdfReader {
    Array theta_i, ndf, sigma, vndf, rgb;
    std::vector<float> theta_nodes;

    explicit BsdfReader(const TensorFile& f)
        : theta_i(field(f, "theta_i")),
          ndf(field(f, "ndf")),
          sigma(field(f, "sigma")),
          vndf(field(f, "vndf")),
          rgb(field(f, "rgb")),
          theta_nodes(theta_i.v) {}

    static double theta2u(double theta) { return std::sqrt(theta / (kPiD / 2)); }
    static double phi2u(double phi) { return (phi + kPiD) / (2 * kPiD); }

    /// f(wi, wo) (1/sr): wi parameterizes the tables (Mitsuba 3's convention).
    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const {
        if (wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        const Vec3d m = normalize(wi + wo);
        const double theta_i = std::acos(std::min(1.0, wi.z)), phi_i = std::atan2(wi.y, wi.x);
        const double theta_m = std::acos(std::min(1.0, m.z)), phi_m = std::atan2(m.y, m.x);
        double uy = phi2u(phi_m - phi_i);
        uy -= std::floor(uy);
        const double ux = theta2u(theta_m);
        // The VNDF warp of the mixture of the two θi slices around theta_i (slice φi = 0 of the
        // two equal ones): u_y = Σ w M(y), u_x = Σ w C(x, y) / Σ w R(y).
        const auto [k, w] = bracket(theta_nodes, theta_i);
        const std::size_t vy = vndf.shape[2], vx = vndf.shape[3];
        double left = 0, row = 0, below = 0;
        for (int e = 0; e < 2; ++e) {
            const double we = e == 0 ? 1 - w : w;
            if (we == 0) continue;
            const auto [l, r, b] = invert_slice(vndf.v.data() + (k + e) * vy * vx, vx, vy, ux, uy);
            left += we * l;
            row += we * r;
            below += we * b;
        }
        const double sx = row > 0 ? left / row : 0, sy = below;
        const std::size_t ny = rgb.shape[3], nx = rgb.shape[4];
        Rgbd s(0.0);
        for (int c = 0; c < 3; ++c)
            for (int e = 0; e < 2; ++e) {
                const double we = e == 0 ? 1 - w : w;
                if (we == 0) continue;
                s[c] += we * bilinear(rgb.v.data() + ((k + e) * 3 + c) * ny * nx, nx, ny, sx, sy);
            }
        const double d = bilinear(ndf.v.data(), ndf.shape[1], ndf.shape[0], ux, uy);
        const double sig = bilinear(sigma.v.data(), sigma.shape[1], sigma.shape[0],
                                    theta2u(theta_i), phi2u(phi_i));
        return s * (d / (4 * sig * wo.z));
    }
};

// ---- sources ---------------------------------------------------------------------------------

std::shared_ptr<const Model> plastic_model() {
    // A rough coat (α = 0.3) on a coloured Lambertian base: a glossy lobe over a diffuse one.
    const Stack stack =
        test::coated(1.5, 0.3, test::lambertian(Rgbd(0.8, 0.4, 0.1)), Rgbd(0.1, 0.0, 0.5));
    return make_model("ww-prime", stack);
}

Vec3d random_direction(std::mt19937_64& rng, double max_theta_deg) {
    std::uniform_real_distribution<double> u(0, 1);
    const double theta = deg_to_rad(max_theta_deg) * std::sqrt(u(rng));
    return direction_from_angles(theta, 2 * kPiD * u(rng));
}

/// Relative errors |Y(a) − Y(b)| / Y(b) at random pairs (θi, θo ≤ 80°), sorted.
std::vector<double> errors(const BsdfReader& reader, const BrdfSource& source, int n,
                           const std::vector<double>& theta_i_nodes = {},
                           double max_theta_deg = 80) {
    std::mt19937_64 rng(7);
    std::vector<double> out;
    for (int k = 0; k < n; ++k) {
        Vec3d wi = random_direction(rng, max_theta_deg);
        if (!theta_i_nodes.empty())  // the source exists only at its incidences
            wi = direction_from_angles(deg_to_rad(theta_i_nodes[k % theta_i_nodes.size()]),
                                       std::atan2(wi.y, wi.x));
        const Vec3d wo = random_direction(rng, max_theta_deg);
        const double want = luminance(source.f(wi, wo)), got = luminance(reader.eval(wi, wo));
        out.push_back(std::abs(got - want) / want);
    }
    std::sort(out.begin(), out.end());
    return out;
}

double quantile(const std::vector<double>& sorted, double q) {
    return sorted[std::size_t(q * double(sorted.size() - 1))];
}

RglOptions options(int resolution, double dtheta) {
    RglOptions o;
    o.resolution = resolution;
    o.vndf_resolution = 2 * resolution;
    o.ndf_resolution = 2 * resolution;
    for (double t = 0; t < 89; t += dtheta)
        o.theta_i_deg.push_back(t);
    return o;
}

// ---- tests -----------------------------------------------------------------------------------

TEST(TensorFile, RoundTripsAndRefusesMalformedFiles) {
    TensorFile f;
    f["a"] = tensor_float32({1, 2, 3, 4, 5, 6}, {2, 3});
    f["name"] = tensor_uint8("hello", {5});
    const std::string bytes = tensor_file_bytes(f);
    const TensorFile g = parse_tensor_file(bytes, "t.bsdf");
    EXPECT_EQ(g.at("a").shape, (std::vector<std::uint64_t>{2, 3}));
    EXPECT_EQ(g.at("a").floats(), (std::vector<float>{1, 2, 3, 4, 5, 6}));
    EXPECT_EQ(g.at("name").data, "hello");
    auto message = [](const std::string& b) {
        try {
            parse_tensor_file(b, "t.bsdf");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(message(bytes.substr(0, bytes.size() - 3)).find("truncated"), std::string::npos);
    EXPECT_NE(message(bytes.substr(0, 25)).find("truncated"), std::string::npos);
    EXPECT_NE(message("tensor_fil"), "accepted");
    std::string bad = bytes;
    bad[0] = 'x';
    EXPECT_NE(message(bad).find("not a tensor file"), std::string::npos);
    bad = bytes;
    bad[12] = 2;  // version 2.0
    EXPECT_NE(message(bad).find("version"), std::string::npos);
}

TEST(RglBsdf, HasTheFieldsTheReadersRequire) {
    const BrdfSource src = model_brdf(plastic_model(), "test");
    const TensorFile f = rgl_bsdf(src, options(8, 20));
    EXPECT_NO_THROW(check_rgl_bsdf(f, "t.bsdf"));
    EXPECT_EQ(f.at("spectra").shape,
              (std::vector<std::uint64_t>{2, 5, rgl_wavelengths().size(), 8, 8}));
    EXPECT_EQ(f.at("jacobian").data, std::string(1, '\1'));
    // The spectra are the RGB values' upsampling: 550 nm is green, 400 nm blue, 700 nm red.
    const auto rgb = f.at("rgb").floats(), spectra = f.at("spectra").floats();
    const std::size_t n = 64, nl = rgl_wavelengths().size();
    for (std::size_t j = 0; j < n; ++j) {
        EXPECT_EQ(spectra[3 * n + j], rgb[1 * n + j]);
        EXPECT_EQ(spectra[0 * n + j], rgb[2 * n + j]);
        EXPECT_EQ(spectra[(nl - 1) * n + j], rgb[0 * n + j]);
    }
    TensorFile missing = f;
    missing.erase("sigma");
    EXPECT_THROW(check_rgl_bsdf(missing, "t.bsdf"), InputError);
    TensorFile wrong = f;
    wrong["vndf"] = tensor_float32(std::vector<float>(8, 1.f), {2, 2, 2});
    EXPECT_THROW(check_rgl_bsdf(wrong, "t.bsdf"), InputError);
}

// The model exported at high resolution and read back: its BRDF within a tolerance that the
// interpolation explains. Bilinear interpolation (in s, and linear in θi) errs by O(h²): the
// error must fall by about 4× when the grids are refined 2× (at least 2.5× is asked). At the
// finer resolution (48 s nodes a side, incidences every 2°) 90% of random pairs with θi, θo ≤ 80°
// must agree to 2%, and 99% of those with θi, θo ≤ 70° to 5% (measured: 0.74% and 1.0%). Past
// 70° both directions grazing, with half vectors far from the normal, the warp gives few nodes to
// a region where S varies fast with θi: there the tail reaches tens of percent (measured p99 over
// θ ≤ 80°: 33%; docs/formats.md says so).
TEST(RglBsdf, ReaderAgreesWithTheModel) {
    const BrdfSource src = model_brdf(plastic_model(), "test");
    const BsdfReader coarse(rgl_bsdf(src, options(24, 4)));
    const BsdfReader fine(rgl_bsdf(src, options(48, 2)));
    const std::vector<double> e1 = errors(coarse, src, 4000), e2 = errors(fine, src, 4000);
    const std::vector<double> e70 = errors(fine, src, 4000, {}, 70);
    const double q1 = quantile(e1, 0.9), q2 = quantile(e2, 0.9);
    std::printf(
        "relative error p50/p90/p99 (θ ≤ 80°): coarse %.4f %.4f %.4f, fine %.4f %.4f %.4f; "
        "fine, θ ≤ 70°: %.4f %.4f %.4f\n",
        quantile(e1, 0.5), q1, quantile(e1, 0.99), quantile(e2, 0.5), q2, quantile(e2, 0.99),
        quantile(e70, 0.5), quantile(e70, 0.9), quantile(e70, 0.99));
    EXPECT_LT(q2, 0.02);
    EXPECT_LT(quantile(e70, 0.99), 0.05);
    EXPECT_GT(q1 / q2, 2.5);
}

// A reference table (the goniophotometer's bins, interpolated between bin centres) exported at its
// incidences: the reader gives back the interpolated table at those incidences.
TEST(RglBsdf, ReaderAgreesWithAReferenceTable) {
    const Stack stack =
        test::coated(1.5, 0.3, test::lambertian(Rgbd(0.8, 0.4, 0.1)), Rgbd(0.1, 0.0, 0.5));
    SimulationSettings s;
    s.theta_i_deg = {0, 30, 60};
    s.particles = 400'000;
    s.grid = HemisphereGrid(30, 30);
    const SimulationResult r = simulate(stack, s);
    const BrdfSource src = table_brdf(r.table, "reference", "test");
    RglOptions o = options(48, 90);
    o.theta_i_deg = s.theta_i_deg;
    const BsdfReader reader(rgl_bsdf(src, o));
    const std::vector<double> e = errors(reader, src, 3000, s.theta_i_deg);
    std::printf("table: relative error p50/p90/p99 %.4f %.4f %.4f\n", quantile(e, 0.5),
                quantile(e, 0.9), quantile(e, 0.99));
    // The table's interpolant has kinks at the bin centres (and Monte-Carlo noise between bins),
    // which bilinear interpolation in s smooths: looser than the smooth model's bound.
    EXPECT_LT(quantile(e, 0.9), 0.05);
}

TEST(Merl, RoundTripAndNearestBinLookup) {
    const BrdfSource src = model_brdf(plastic_model(), "test");
    const std::string bytes = merl_binary(src);
    EXPECT_EQ(bytes.size(), 12u + 3u * 90 * 90 * 180 * 8);
    const MerlBrdf merl = parse_merl(bytes, "t.binary");
    // At the bins' centres the file gives back the source (to the scale's rounding).
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<int> ih(0, 89), id(0, 89), ip(0, 179);
    int checked = 0;
    for (int k = 0; k < 2000; ++k) {
        const double u = (ih(rng) + 0.5) / 90;
        const auto [wi, wo] = merl_directions(u * u * kPiD / 2, (id(rng) + 0.5) / 90 * kPiD / 2,
                                              (ip(rng) + 0.5) / 180 * kPiD);
        if (wi.z <= 0 || wo.z <= 0) continue;
        const Rgbd want = src.f(normalize(wi), normalize(wo)), got = merl.eval(wi, wo);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want[c], 1e-12 * (1 + want[c]));
        ++checked;
    }
    EXPECT_GT(checked, 1000);
    // Reciprocity of the lookup: swapping wi and wo lands in the same bin (φd folded by π).
    const Vec3d a = normalize(Vec3d(0.3, 0.1, 0.9)), b = normalize(Vec3d(-0.5, 0.2, 0.7));
    EXPECT_EQ(merl.eval(a, b)[0], merl.eval(b, a)[0]);
    EXPECT_THROW(parse_merl(bytes.substr(0, bytes.size() - 8), "t.binary"), InputError);
    std::string bad = bytes;
    bad[0] = 91;
    EXPECT_THROW(parse_merl(bad, "t.binary"), InputError);
}

TEST(Export, SmoothInterfacesAreRefused) {
    const Stack stack = test::coated(1.5, 0.0, test::lambertian(Rgbd(0.5)));
    EXPECT_THROW(model_brdf(make_model("ww-prime", stack), "s.json"), InputError);
}

TEST(Npz, IsAStoredZip) {
    const std::string z = zip_stored({{"a.npy", "abc"}, {"metadata.json", "{}"}});
    EXPECT_EQ(z.substr(0, 4), std::string("PK\x03\x04", 4));
    EXPECT_NE(z.find("PK\x05\x06"), std::string::npos);
    EXPECT_NE(z.find("abc"), std::string::npos);
}

}  // namespace
}  // namespace lamina
