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
#include "export/rgl_fidelity.h"
#include "export/rgl_reader.h"
#include "export/tensor_file.h"
#include "models/numerics/binned.h"
#include "models/numerics/quadrature.h"
#include "models/registry.h"
#include "models/test_stacks.h"
#include "simulator/goniophotometer.h"
#include "study/configurations.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
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

/// The inverse-CDF map x → u of a bilinear density (one slice, not normalized), written from the
/// definition: u_y = the mass below y, u_x = the mass left of x on the row through y over that
/// row's mass. `prefix` holds, per node row, the integral from 0 to each node (trapezoids, exact
/// for a linear row); the row through y is the linear blend of its two node rows.
struct SliceInverse {
    std::size_t nx, ny;
    std::vector<double> prefix;  ///< [row][node]
    std::vector<double> below;   ///< mass below each node row
    double total;

    SliceInverse(const float* p, std::size_t nx_, std::size_t ny_) : nx(nx_), ny(ny_) {
        const double dx = 1.0 / double(nx - 1), dy = 1.0 / double(ny - 1);
        prefix.assign(nx * ny, 0.0);
        for (std::size_t b = 0; b < ny; ++b)
            for (std::size_t a = 1; a < nx; ++a)
                prefix[b * nx + a] =
                    prefix[b * nx + a - 1] + 0.5 * dx * (double(p[b * nx + a - 1]) + p[b * nx + a]);
        below.assign(ny, 0.0);
        for (std::size_t b = 1; b < ny; ++b)
            below[b] = below[b - 1] + 0.5 * dy * (row_mass(b - 1) + row_mass(b));
        total = below[ny - 1];
        values = p;
    }
    double row_mass(std::size_t b) const { return prefix[b * nx + nx - 1]; }

    /// (mass left of x on the row through y, that row's mass, the mass below y), over the total.
    std::array<double, 3> operator()(double x, double y) const {
        const double dx = 1.0 / double(nx - 1), dy = 1.0 / double(ny - 1);
        const double gy = std::clamp(y, 0.0, 1.0) * double(ny - 1);
        const std::size_t j = std::min<std::size_t>(std::size_t(gy), ny - 2);
        const double t = gy - double(j);
        const double r0 = row_mass(j), r1 = row_mass(j + 1);
        const double mass_below = below[j] + dy * (r0 * t + 0.5 * (r1 - r0) * t * t);
        const double gx = std::clamp(x, 0.0, 1.0) * double(nx - 1);
        const std::size_t i = std::min<std::size_t>(std::size_t(gx), nx - 2);
        const double s = gx - double(i);
        auto row_at_y = [&](std::size_t a) {
            return (1 - t) * values[j * nx + a] + t * values[(j + 1) * nx + a];
        };
        const double left = (1 - t) * prefix[j * nx + i] + t * prefix[(j + 1) * nx + i] +
                            dx * (row_at_y(i) * s + 0.5 * (row_at_y(i + 1) - row_at_y(i)) * s * s);
        return {left / total, ((1 - t) * r0 + t * r1) / total, mass_below / total};
    }

  private:
    const float* values;
};

struct BsdfReader {
    Array theta_i, phi_field, ndf, sigma, vndf, spectra, wavelengths;
    std::vector<float> theta_nodes;
    bool isotropic;                   ///< at most two φi slices: φm read relative to φi
    std::vector<SliceInverse> warps;  ///< per (φi, θi) slice, θi fastest (isotropic: the first φi)
    std::size_t channel_at[3];        ///< the wavelengths read as red, green, blue

    explicit BsdfReader(const TensorFile& f)
        : theta_i(field(f, "theta_i")),
          phi_field(field(f, "phi_i")),
          ndf(field(f, "ndf")),
          sigma(field(f, "sigma")),
          vndf(field(f, "vndf")),
          spectra(field(f, "spectra")),
          wavelengths(field(f, "wavelengths")),
          theta_nodes(theta_i.v),
          isotropic(phi_field.v.size() <= 2) {
        const std::size_t vy = vndf.shape[2], vx = vndf.shape[3];
        const std::size_t slices = (isotropic ? 1 : phi_field.v.size()) * theta_nodes.size();
        for (std::size_t k = 0; k < slices; ++k)
            warps.emplace_back(vndf.v.data() + k * vy * vx, vx, vy);
        // lamina's upsampling puts red, green and blue at 650, 550 and 450 nm (docs/formats.md).
        const float want[3] = {650, 550, 450};
        for (int c = 0; c < 3; ++c)
            channel_at[c] =
                std::size_t(std::find(wavelengths.v.begin(), wavelengths.v.end(), want[c]) -
                            wavelengths.v.begin());
    }

    static double theta2u(double theta) { return std::sqrt(theta / (kPiD / 2)); }
    static double phi2u(double phi) { return (phi + kPiD) / (2 * kPiD); }

    /// f(wi, wo) (1/sr): wi parameterizes the tables (Mitsuba 3's convention); both readers divide
    /// by cos θ of the other direction.
    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const {
        if (wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        const Vec3d m = normalize(wi + wo);
        const double theta_i = std::acos(std::min(1.0, wi.z)), phi_i = std::atan2(wi.y, wi.x);
        const double theta_m = std::acos(std::min(1.0, m.z)), phi_m = std::atan2(m.y, m.x);
        double uy = phi2u(isotropic ? phi_m - phi_i : phi_m);
        uy -= std::floor(uy);
        const double ux = theta2u(theta_m);
        // The warp of the mixture of the (up to four) slices around (φi, θi), weighted
        // bilinearly: u_y = Σ w M(y), u_x = Σ w C(x, y) / Σ w R(y).
        const std::size_t n_inc = theta_nodes.size();
        const auto [k, w] = bracket(theta_nodes, theta_i);
        const auto [p, v] =
            isotropic ? std::pair<std::size_t, double>{0, 0.0} : bracket(phi_field.v, phi_i);
        std::vector<std::pair<std::size_t, double>> mix;  // (slice, weight)
        for (std::size_t a = 0; a < (isotropic ? 1 : 2); ++a)
            for (std::size_t e = 0; e < 2 && k + e < n_inc; ++e) {
                const double we = (a == 0 ? 1 - v : v) * (e == 0 ? 1 - w : w);
                if (we != 0) mix.push_back({(p + a) * n_inc + k + e, we});
            }
        double left = 0, row = 0, below = 0;
        for (const auto& [slice, we] : mix) {
            const auto [l, r, b] = warps[slice](ux, uy);
            left += we * l;
            row += we * r;
            below += we * b;
        }
        const double sx = row > 0 ? left / row : 0, sy = below;
        const std::size_t nl = spectra.shape[2], ny = spectra.shape[3], nx = spectra.shape[4];
        Rgbd s(0.0);
        for (int c = 0; c < 3; ++c)
            for (const auto& [slice, we] : mix)
                s[c] += we * bilinear(spectra.v.data() + (slice * nl + channel_at[c]) * ny * nx, nx,
                                      ny, sx, sy);
        const double d = bilinear(ndf.v.data(), ndf.shape[1], ndf.shape[0], ux, uy);
        const double sig = bilinear(sigma.v.data(), sigma.shape[1], sigma.shape[0],
                                    theta2u(theta_i), phi2u(phi_i));
        return s * (d / (4 * sig * wo.z));
    }
};

/// ∫ f(wi, wo) cos θo dωo of any f, over the half vector: dωo = 4 (wi·ωm) dωm with
/// dωm = sin θm dθm dφm, and θm = (π/2) t⁴ (dθm = 2π t³ dt), which crowds the nodes near ωm = n,
/// where near-specular lobes sit whatever θi. 8-point Gauss–Legendre on 40 × 40 cells of (t, φm).
template <typename F>
Rgbd half_vector_albedo(F&& f, const Vec3d& wi) {
    static const QuadratureRule q = gauss_legendre(8);
    constexpr int kCells = 40;
    Rgbd sum(0.0);
    for (int a = 0; a < kCells; ++a)
        for (int ga = 0; ga < 8; ++ga) {
            const double t = (a + q.x[ga]) / kCells, theta_m = kPiD / 2 * t * t * t * t;
            const double d_theta = 2 * kPiD * t * t * t / kCells * q.w[ga];
            for (int b = 0; b < kCells; ++b)
                for (int gb = 0; gb < 8; ++gb) {
                    const double phi_m = 2 * kPiD * (b + q.x[gb]) / kCells;
                    const Vec3d m = direction_from_angles(theta_m, phi_m);
                    const double c = dot(wi, m);
                    const Vec3d wo = m * (2 * c) - wi;
                    if (c <= 0 || wo.z <= 0) continue;
                    sum += f(wi, wo) * (wo.z * 4 * c * std::sin(theta_m) * d_theta * 2 * kPiD /
                                        kCells * q.w[gb]);
                }
        }
    return sum;
}

// ---- sources ---------------------------------------------------------------------------------

/// A rough coat (α = 0.3) on a coloured Lambertian base: a glossy lobe over a diffuse one.
Stack plastic_stack() {
    return test::coated(1.5, 0.3, test::lambertian(Rgbd(0.8, 0.4, 0.1)), Rgbd(0.1, 0.0, 0.5));
}
std::shared_ptr<const Model> plastic_model() {
    return make_model("ww-prime", plastic_stack());
}

/// lamina-1's BRDF of one of the study's configurations.
BrdfSource study_source(const std::string& id, const std::string& model = "lamina-1",
                        const std::vector<std::string>& options = {}) {
    for (const StudyConfiguration& c : builtin_configurations())
        if (c.id == id) return model_brdf(make_model(model, c.stack, options), c.stack, id);
    throw std::runtime_error("no configuration " + id);
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

/// The goals' value figure: pairs uniform in solid angle over θ ≤ 85° (cos θ uniform), sorted
/// relative errors of Y.
std::vector<double> goal_errors(const BsdfReader& reader, const BrdfSource& source, int n,
                                std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    const double cos_max = std::cos(deg_to_rad(RglFidelityGoals::kMaxThetaDeg));
    auto direction = [&] {
        const double cos_theta = 1 - (1 - cos_max) * u(rng);
        return direction_from_angles(std::acos(cos_theta), 2 * kPiD * u(rng));
    };
    std::vector<double> out;
    for (int k = 0; k < n; ++k) {
        const Vec3d wi = direction(), wo = direction();
        const double want = luminance(source.f(wi, wo));
        if (want > 0) out.push_back(std::abs(luminance(reader.eval(wi, wo)) / want - 1));
    }
    std::sort(out.begin(), out.end());
    return out;
}

/// |a/b − 1| in the worst channel.
double worst_channel_error(const Rgbd& a, const Rgbd& b) {
    double e = 0;
    for (int c = 0; c < 3; ++c)
        e = std::max(e, std::abs(a[c] / b[c] - 1));
    return e;
}

double quantile(const std::vector<double>& sorted, double q) {
    return sorted[std::size_t(q * double(sorted.size() - 1))];
}

RglOptions options(int resolution, double dtheta) {
    RglOptions o;
    o.resolution = resolution;
    for (double t = 0; t < 89; t += dtheta)
        o.theta_i_deg.push_back(t);
    return o;
}

// ---- tests -----------------------------------------------------------------------------------

/// `lamina export --check`'s reader and the independent one give the same f at random pairs (to
/// float32 rounding of the interpolation).
void expect_readers_agree(const RglReader& check, const BsdfReader& independent) {
    std::mt19937_64 rng(5);
    for (int k = 0; k < 2000; ++k) {
        const Vec3d wi = random_direction(rng, 89), wo = random_direction(rng, 89);
        const Rgbd a = check.eval(wi, wo), b = independent.eval(wi, wo);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a[c], b[c], 1e-5 * (std::abs(b[c]) + 1e-3));
    }
}

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
    const BrdfSource src = model_brdf(plastic_model(), plastic_stack(), "test");
    const TensorFile f = rgl_bsdf(src, options(8, 20));
    EXPECT_NO_THROW(check_rgl_bsdf(f, "t.bsdf"));
    // One φi slice (isotropic), five incidences, 8 × 8 sample nodes; tables of θ alone are two
    // equal rows.
    EXPECT_EQ(f.at("spectra").shape,
              (std::vector<std::uint64_t>{1, 5, rgl_wavelengths().size(), 8, 8}));
    EXPECT_EQ(f.at("ndf").shape, (std::vector<std::uint64_t>{2, 512}));
    EXPECT_EQ(f.at("vndf").shape, (std::vector<std::uint64_t>{1, 5, 2, 512}));
    EXPECT_EQ(f.at("jacobian").data, std::string(1, '\1'));
    EXPECT_EQ(f.count("rgb"), 0u);
    // The spectra are a partition of unity over r, g, b: grey stays grey, and 450, 550 and 650 nm
    // hold b, g and r themselves.
    const auto spectra = f.at("spectra").floats();
    const std::size_t n = 64, nl = rgl_wavelengths().size();
    for (std::size_t l = 0; l < nl; ++l) {
        const Rgbd w = rgl_spectral_weights(l);
        EXPECT_DOUBLE_EQ(w[0] + w[1] + w[2], 1.0);
    }
    EXPECT_EQ(rgl_spectral_weights(1), Rgbd(0, 0, 1));
    EXPECT_EQ(rgl_spectral_weights(3), Rgbd(0, 1, 0));
    EXPECT_EQ(rgl_spectral_weights(5), Rgbd(1, 0, 0));
    for (std::size_t j = 0; j < n; ++j)
        EXPECT_GE(spectra[j], 0.f);
    TensorFile missing = f;
    missing.erase("sigma");
    EXPECT_THROW(check_rgl_bsdf(missing, "t.bsdf"), InputError);
    TensorFile wrong = f;
    wrong["vndf"] = tensor_float32(std::vector<float>(8, 1.f), {2, 2, 2});
    EXPECT_THROW(check_rgl_bsdf(wrong, "t.bsdf"), InputError);
    // Values a renderer cannot use: a wavelength that is NaN or out of order, an incidence below
    // the horizon or negative — each refused naming its field.
    auto field_refused = [&](const std::string& name, std::size_t at, float value) {
        TensorFile damaged = f;
        std::vector<float> v = damaged.at(name).floats();
        v.at(at) = value;
        damaged[name] = tensor_float32(v, damaged.at(name).shape);
        try {
            check_rgl_bsdf(damaged, "t.bsdf");
        } catch (const InputError& e) {
            return e.field() == name;
        }
        return false;
    };
    EXPECT_TRUE(field_refused("wavelengths", 2, std::nanf("")));
    EXPECT_TRUE(field_refused("wavelengths", 2, 1.f));  // below its predecessor
    EXPECT_TRUE(field_refused("theta_i", 0, -0.1f));
    EXPECT_TRUE(field_refused("theta_i", 4, 2.f));
    EXPECT_FALSE(field_refused("theta_i", 0, 0.f));  // the normal is an incidence
    // A BRDF value and the luminance a reader samples by are never negative.
    EXPECT_TRUE(field_refused("spectra", 7, -1e-3f));
    EXPECT_TRUE(field_refused("luminance", 7, -1e-3f));
    EXPECT_FALSE(field_refused("spectra", 7, 0.f));
}

TEST(RglBsdf, DefaultIncidencesGetDenserTowardsGrazing) {
    const std::vector<double> t = rgl_default_incidences();
    ASSERT_GE(t.size(), 3u);
    EXPECT_EQ(t.front(), 0.0);
    EXPECT_EQ(t.back(), 88.0);
    // Past the goals' 85°, so that every incidence they judge is interpolated, not held.
    EXPECT_GT(t[t.size() - 2], RglFidelityGoals::kMaxThetaDeg);
    for (std::size_t k = 1; k < t.size(); ++k) {
        const double step = t[k] - t[k - 1];
        EXPECT_LE(step, 4.0 + 1e-9);
        if (k + 1 < t.size()) {
            EXPECT_LE(step, 0.25 * (90 - t[k - 1]) + 0.01);
        }
    }
}

// The file's bytes do not depend on the thread count.
BrdfSource brushed_source(double tangent_deg);

// Isotropic and anisotropic (φi slices) files alike.
TEST(RglBsdf, FileDoesNotDependOnTheThreadCount) {
    RglOptions o = options(16, 10);
    o.azimuths = 4;
    for (const BrdfSource& src : {study_source("paint-a0.05-a1.3"), brushed_source(20)}) {
        const int threads = omp_get_max_threads();
        omp_set_num_threads(1);
        const std::string one = tensor_file_bytes(rgl_bsdf(src, o));
        omp_set_num_threads(std::max(2, threads));
        const std::string many = tensor_file_bytes(rgl_bsdf(src, o));
        omp_set_num_threads(threads);
        EXPECT_TRUE(one == many) << src.name;
    }
}

// The model exported and read back: its BRDF within a tolerance that the interpolation explains.
// Bilinear interpolation (in s, and linear in θi) errs by O(h²): the error must fall by about 4×
// when the grids are refined 2× (at least 2.5× is asked). At the finer resolution (48 s nodes a
// side, incidences every 2°) 90% of random pairs with θi, θo ≤ 80° must agree to 2%, and 99% of
// those with θi, θo ≤ 70° to 5%.
TEST(RglBsdf, ReaderAgreesWithTheModel) {
    const BrdfSource src = model_brdf(plastic_model(), plastic_stack(), "test");
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

// The source's albedo by the half-vector quadrature (rgl_fidelity.h) against the model's own
// sampler, on the study's hardest case for it: a coat of α = 0.001 over a rough metal at 84°,
// where the whole coat reflection sits within 0.1° of the mirror direction. The Monte-Carlo
// estimate's standard error is computed; 5 of them are allowed (plus 1e-4 for the quadrature).
TEST(RglBsdf, SourceAlbedoAgreesWithTheModelsSampler) {
    for (const StudyConfiguration& c : builtin_configurations()) {
        if (c.id != "paint-a0.001-a1.3") continue;
        const std::shared_ptr<const Model> model = make_model("lamina-1", c.stack);
        ASSERT_TRUE(model->has_sampling());
        const BrdfSource src = model_brdf(model, c.stack, c.id);
        for (double theta : {0.0, 60.0, 84.0}) {
            const Vec3d wi = incident_direction(deg_to_rad(theta));
            std::mt19937_64 rng(11);
            std::uniform_real_distribution<double> u(0, 1);
            constexpr int kN = 400000;
            double sum = 0, sum2 = 0;
            for (int k = 0; k < kN; ++k) {
                const auto sample = model->sample(wi, Vec3d(u(rng), u(rng), u(rng)));
                const double y = sample && sample->wo.z > 0 ? luminance(sample->weight) : 0.0;
                sum += y;
                sum2 += y * y;
            }
            const double mean = sum / kN, se = std::sqrt((sum2 / kN - mean * mean) / kN);
            const double quad = luminance(directional_albedo(src.f, wi));
            const double independent = luminance(half_vector_albedo(src.f, wi));
            std::printf("θi %2.0f: sampler %.5f ± %.5f, source_albedo %.5f, test quadrature %.5f\n",
                        theta, mean, se, quad, independent);
            EXPECT_NEAR(quad, mean, 5 * se + 1e-4);
            EXPECT_NEAR(independent, quad, 2e-4 * quad);
        }
    }
}

// What `lamina export --check` reports (export/rgl_reader.h, rgl_fidelity.h) is what the
// independent reader finds: the same f at random pairs (to float32 rounding of the interpolation),
// the same albedo. (A plastic without the orders ≥ 2's cosine lobes: their albedo is the
// separable lobe's, which the two quadratures of the tabulated data integrate 3e-4 apart at
// normal incidence, a budget that would test the quadratures instead of the readers.)
TEST(RglBsdf, CheckReaderAgreesWithTheIndependentReader) {
    const BrdfSource src = study_source("plastic-P4-a0.05", "lamina-1", {"microsurface=single"});
    const TensorFile file = rgl_bsdf(src, options(24, 6));
    const RglReader check(file, "t.bsdf");
    const BsdfReader independent(file);
    expect_readers_agree(check, independent);
    for (double theta : {0.0, 37.0, 71.0, 84.5}) {
        const Vec3d wi = incident_direction(deg_to_rad(theta));
        const Rgbd a = directional_albedo(
            [&](const Vec3d& i, const Vec3d& o) { return check.eval(i, o); }, wi);
        const Rgbd b = half_vector_albedo(
            [&](const Vec3d& i, const Vec3d& o) { return independent.eval(i, o); }, wi);
        EXPECT_LT(worst_channel_error(a, b), 2e-4) << "θi " << theta;
    }
}

// The defaults, judged by the independent reader where the previous ones failed (pbrt-v4 made a
// metallic paint's albedo 32% too high at 80°): the study's metallic paint and plastic with the
// smoothest coat (α = 0.001: all of the coat's reflection within 0.1° of the mirror direction),
// at grazing incidences between the file's nodes. Goals (rgl_fidelity.h): albedo within 2% at
// every θi ≤ 85°, values within 5% for 90% of pairs with θi, θo ≤ 85°.
TEST(RglBsdf, DefaultsMeetTheGoalsAtGrazingAngles) {
    using Goals = RglFidelityGoals;
    for (const char* id : {"paint-a0.001-a1.3", "plastic-P4-a0.05"}) {
        const BrdfSource src = study_source(id);
        const BsdfReader reader(rgl_bsdf(src, RglOptions{}));
        double worst = 0;
        for (double theta : {0.0, 45.0, 70.0, 74.0, 78.0, 80.0, 83.0, 85.0}) {
            const Vec3d wi = incident_direction(deg_to_rad(theta));
            const Rgbd file = half_vector_albedo(
                [&](const Vec3d& i, const Vec3d& o) { return reader.eval(i, o); }, wi);
            const double e = worst_channel_error(file, half_vector_albedo(src.f, wi));
            EXPECT_LE(e, Goals::kAlbedo) << id << " θi " << theta;
            worst = std::max(worst, e);
        }
        const std::vector<double> e = goal_errors(reader, src, 4000, 3);
        std::printf("%s: worst albedo error %.4f; values p50 %.4f p90 %.4f p99 %.4f\n", id, worst,
                    quantile(e, 0.5), quantile(e, Goals::kValueQuantile), quantile(e, 0.99));
        EXPECT_LE(quantile(e, Goals::kValueQuantile), Goals::kValue) << id;
    }
}

// Past the last incidence (88°) the readers hold S, and lamina holds σ with it: f stays bounded
// as θi → 90° (a σ falling to 0 with cos θi would make it grow without bound), and the albedo
// falls as more of the held lobe passes below the horizon.
TEST(RglBsdf, BoundedPastTheLastIncidence) {
    const BrdfSource src = study_source("plastic-P1-a0.05");
    const BsdfReader reader(rgl_bsdf(src, RglOptions{}));
    auto albedo = [&](double theta) {
        return luminance(
            half_vector_albedo([&](const Vec3d& i, const Vec3d& o) { return reader.eval(i, o); },
                               incident_direction(deg_to_rad(theta))));
    };
    const double a88 = albedo(88), a90 = albedo(89.9);
    const double s90 = luminance(half_vector_albedo(src.f, incident_direction(deg_to_rad(89.9))));
    std::printf("albedo at 88°: %.4f; at 89.9°: %.4f, the source %.4f\n", a88, a90, s90);
    EXPECT_TRUE(std::isfinite(a90));
    EXPECT_LT(a90, a88);
}

// A reference table (the goniophotometer's bins, interpolated between bin centres) exported at its
// incidences: the reader gives back the interpolated table at those incidences.
TEST(RglBsdf, ReaderAgreesWithAReferenceTable) {
    const Stack stack =
        test::coated(1.5, 0.3, test::lambertian(Rgbd(0.8, 0.4, 0.1)), Rgbd(0.1, 0.0, 0.5));
    SimulationSettings s;
    s.theta_i_deg = {0, 30, 60};
    s.particles = 2'000'000;  // at 400 000 the bins' own noise (≈5%) dominates the error
    s.grid = HemisphereGrid(30, 30);
    const SimulationResult r = simulate(stack, s);
    const BrdfSource src = table_brdf(r.table, "reference", "test");
    RglOptions o;
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
    const BrdfSource src = model_brdf(plastic_model(), plastic_stack(), "test");
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
    EXPECT_THROW(model_brdf(make_model("ww-prime", stack), stack, "s.json"), InputError);
}

// ---- anisotropic sources ------------------------------------------------------------------------

/// Brushed gold (α_x = 0.08 along a tangent at tangent_deg, α_y = 0.4) under a clear coat of
/// α = 0.1, as the OpenPBR specification evaluates it (anisotropic in both lobes).
BrdfSource brushed_source(double tangent_deg) {
    const Stack stack =
        test::coated(1.5, 0.1, anisotropic(test::gold(0.08), 0.08, 0.4, tangent_deg));
    return model_brdf(make_model("openpbr", stack), stack, "brushed");
}

/// The file's φi slices, as a copy holding only those from first to last (inclusive).
TensorFile phi_slices(const TensorFile& file, std::size_t first, std::size_t last) {
    TensorFile out = file;
    const std::size_t n = last - first + 1;
    for (const char* name : {"phi_i", "vndf", "luminance", "spectra"}) {
        const TensorField& t = file.at(name);
        std::vector<std::uint64_t> shape = t.shape;
        const std::size_t slice = t.floats().size() / shape[0];
        const std::vector<float> v = t.floats();
        shape[0] = n;
        out[name] =
            tensor_float32(std::vector<float>(v.begin() + std::ptrdiff_t(first * slice),
                                              v.begin() + std::ptrdiff_t((last + 1) * slice)),
                           shape);
    }
    return out;
}

// A brushed stack (its tangent turned 30° from x) gets φi slices over [−π, π] that Mitsuba 3
// reads without mirroring (2π over their span rounds to 1), and a renderer reading the file
// meets the goals of rgl_fidelity.h (albedo at φi = 0°, 45°, 90°, 135°; values at pairs of
// random azimuths) with the default settings. The check's reader agrees with the independent one.
TEST(RglBsdf, AnisotropicStackMeetsTheGoals) {
    const BrdfSource src = brushed_source(30);
    ASSERT_FALSE(src.isotropic);
    const TensorFile file = rgl_bsdf(src, RglOptions{});
    check_rgl_bsdf(file, "brushed.bsdf");
    const std::vector<float> phi = file.at("phi_i").floats();
    ASSERT_EQ(phi.size(), std::size_t(RglOptions{}.azimuths) + 1);
    EXPECT_EQ(std::lround(2 * kPiD / (double(phi.back()) - phi.front())), 1);
    const RglReader reader(file, "brushed.bsdf");
    const RglFidelity r = rgl_fidelity(reader, src, RglFidelityOptions{}, "brushed.bsdf");
    std::printf("brushed gold under a coat: worst albedo error %.4f; values p50 %.4f p90 %.4f\n",
                r.worst_albedo_error(), r.value_error(0.5),
                r.value_error(RglFidelityGoals::kValueQuantile));
    EXPECT_TRUE(r.meets_goals());
    expect_readers_agree(reader, BsdfReader(file));
}

// Turning the tangent turns the file: the φi slices, D's rows and the s nodes are the same
// directions turned, when the turn is a whole number of slices (22.5° with --azimuths 16), of D's
// rows (5.625°: 4 of them) and of the s grid along u_y (33 nodes a side: 2 of them). The file of
// the stack turned by 22.5°, read at (ωi, ωo), then gives what the file of the straight stack
// gives at (ωi, ωo) turned back — to float32 rounding — wherever the directions fall: the slices
// and rows are indexed by the absolute azimuth as the readers index them.
TEST(RglBsdf, AnisotropicSlicesTurnWithTheTangent) {
    RglOptions o = options(33, 8);
    o.azimuths = 16;
    const double psi = 22.5;
    const RglReader turned(rgl_bsdf(brushed_source(10 + psi), o), "turned.bsdf"),
        straight(rgl_bsdf(brushed_source(10), o), "straight.bsdf");
    auto rotate = [](const Vec3d& w, double deg) {
        const double c = std::cos(deg_to_rad(deg)), s = std::sin(deg_to_rad(deg));
        return Vec3d(c * w.x - s * w.y, s * w.x + c * w.y, w.z);
    };
    std::mt19937_64 rng(9);
    std::vector<double> e;
    for (int k = 0; k < 4000; ++k) {
        const Vec3d wi = random_direction(rng, 85), wo = random_direction(rng, 85);
        const double a = luminance(turned.eval(wi, wo)),
                     b = luminance(straight.eval(rotate(wi, -psi), rotate(wo, -psi)));
        if (b > 0) e.push_back(std::abs(a / b - 1));
    }
    std::sort(e.begin(), e.end());
    std::printf("turned by 22.5°: p50 %.2e p99 %.2e max %.2e\n", quantile(e, 0.5),
                quantile(e, 0.99), e.back());
    EXPECT_LT(e.back(), 1e-5);  // float32 tables: measured 4.8e-7
}

// Files measured with a mirror symmetry hold half (or a quarter) of the azimuths, and the readers
// mirror ωi into them: the half of a full file of a stack whose tangent lies along x (symmetric
// under y → −y), read as such a file, gives the full file's values.
TEST(RglReader, ReadsHalfTheAzimuthsOfAMirrorSymmetricFile) {
    RglOptions o = options(16, 10);
    o.azimuths = 8;
    const TensorFile full = rgl_bsdf(brushed_source(0), o);
    const RglReader whole(full, "full.bsdf"), half(phi_slices(full, 0, 4), "half.bsdf");
    std::mt19937_64 rng(3);
    for (int k = 0; k < 2000; ++k) {
        const Vec3d wi = random_direction(rng, 85), wo = random_direction(rng, 85);
        const Rgbd a = half.eval(wi, wo), b = whole.eval(wi, wo);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a[c], b[c], 1e-4 * b[c] + 1e-6) << wi.y;
    }
    EXPECT_THROW(RglReader(phi_slices(full, 0, 3), "third.bsdf"), InputError);  // spans 3π/4
}

TEST(Npz, IsAStoredZip) {
    const std::string z = zip_stored({{"a.npy", "abc"}, {"metadata.json", "{}"}});
    EXPECT_EQ(z.substr(0, 4), std::string("PK\x03\x04", 4));
    EXPECT_NE(z.find("PK\x05\x06"), std::string::npos);
    EXPECT_NE(z.find("abc"), std::string::npos);
}

}  // namespace
}  // namespace lamina

namespace lamina {
namespace {

// The defaults on the study's configurations (docs/formats.md, "How close a renderer gets"),
// judged by the independent reader: every category, the smoothest and roughest coats and bases,
// with lamina-1 and ww-prime. Albedo within 2% at θi every 10° to 50°, then every degree to 85°
// (between the file's incidences, where the readers interpolate); values within 5% for 90% of
// 20 000 pairs with θi, θo ≤ 85°. lamina-1's slabs over a near-smooth bottom (α1 = 0.001) meet
// the albedo goal only: off the mirror direction their f is small and not a function of the half
// vector alone, and 10% of the pairs are off by 6% (α0 = 0.05) to 55% (α0 = 0.001)
// (docs/formats.md); the nearly smooth slab (α0 = α1 = 0.001) sits at the albedo goal, 2.00% at
// 74° on this test's incidences (its later orders leave through the nearly smooth coat sharply
// forward, which the file's grid interpolates): checked against 2.5%.
TEST(RglBsdfStat, DefaultsMeetTheGoalsOnTheStudy) {
    using Goals = RglFidelityGoals;
    struct Case {
        const char* id;
        const char* model;
        bool values;
        double albedo = Goals::kAlbedo;
    };
    const Case cases[] = {{"plastic-P1-a0.001", "lamina-1", true},
                          {"plastic-P4-a0.05", "ww-prime", true},
                          {"plastic-P2-a0.5", "lamina-1", true},
                          {"paint-a0.001-a1.1", "lamina-1", true},
                          {"paint-a0.05-a1.5", "ww-prime", true},
                          {"frosted-a0.1-a1.001", "lamina-1", true},
                          {"frosted-a0.5-a1.05", "lamina-1", true},
                          {"slab-a0.001-a1.3-tinted", "lamina-1", true},
                          {"slab-a0.05-a1.001-clear", "lamina-1", false},
                          {"slab-a0.5-a1.3-clear", "lamina-1", true},
                          {"slab-a0.001-a1.001-clear", "lamina-1", false, 0.025}};
    std::vector<double> thetas = {0, 10, 20, 30, 40, 50};
    for (double t = 60; t <= Goals::kMaxThetaDeg; t += 1)
        thetas.push_back(t);
    for (const Case& c : cases) {
        const BrdfSource src = study_source(c.id, c.model);
        const BsdfReader reader(rgl_bsdf(src, RglOptions{}));
        std::vector<double> error(thetas.size());
#pragma omp parallel for schedule(dynamic, 1)
        for (std::size_t k = 0; k < thetas.size(); ++k) {
            const Vec3d wi = incident_direction(deg_to_rad(thetas[k]));
            error[k] = worst_channel_error(
                half_vector_albedo(
                    [&](const Vec3d& i, const Vec3d& o) { return reader.eval(i, o); }, wi),
                half_vector_albedo(src.f, wi));
        }
        const auto worst = std::max_element(error.begin(), error.end());
        const std::vector<double> e = goal_errors(reader, src, 20000, 9);
        std::printf("%s (%s): worst albedo error %.4f at %g°; values p50 %.4f p90 %.4f p99 %.4f\n",
                    c.id, c.model, *worst, thetas[std::size_t(worst - error.begin())],
                    quantile(e, 0.5), quantile(e, Goals::kValueQuantile), quantile(e, 0.99));
        EXPECT_LE(*worst, c.albedo) << c.id;
        if (c.values) {
            EXPECT_LE(quantile(e, Goals::kValueQuantile), Goals::kValue) << c.id;
        }
    }
}

}  // namespace
}  // namespace lamina
