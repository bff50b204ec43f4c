#include "support/chi2.h"

#include "core/math.h"
#include "core/rng.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <vector>

namespace lamina::test {

namespace {

// Numerical Recipes in C, 2nd ed., §6.2 `gser`: P(a, x) by its series, for x < a + 1.
double gamma_p_series(double a, double x) {
    double ap = a, sum = 1 / a, del = sum;
    for (int n = 0; n < 10000; ++n) {
        ap += 1;
        del *= x / ap;
        sum += del;
        if (std::abs(del) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Numerical Recipes §6.2 `gcf`: Q(a, x) by its continued fraction (modified Lentz), x ≥ a + 1.
double gamma_q_continued_fraction(double a, double x) {
    constexpr double kTiny = 1e-300;
    double b = x + 1 - a, c = 1 / kTiny, d = 1 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        const double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        if (std::abs(d) < kTiny) d = kTiny;
        c = b + an / c;
        if (std::abs(c) < kTiny) c = kTiny;
        d = 1 / d;
        const double del = d * c;
        h *= del;
        if (std::abs(del - 1) < 1e-16) break;
    }
    return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

double simpson_step(const std::function<double(double)>& f, double a, double b, double fa,
                    double fm, double fb, double whole, double eps, int depth, int min_depth,
                    int max_depth) {
    const double m = (a + b) / 2, lm = (a + m) / 2, rm = (m + b) / 2;
    const double flm = f(lm), frm = f(rm);
    const double left = (m - a) / 6 * (fa + 4 * flm + fm);
    const double right = (b - m) / 6 * (fm + 4 * frm + fb);
    const double delta = left + right - whole;
    if (depth >= max_depth || (depth >= min_depth && std::abs(delta) <= 15 * eps))
        return left + right + delta / 15;  // Richardson extrapolation
    return simpson_step(f, a, m, fa, flm, fm, left, eps / 2, depth + 1, min_depth, max_depth) +
           simpson_step(f, m, b, fm, frm, fb, right, eps / 2, depth + 1, min_depth, max_depth);
}

struct Bin {
    double observed, expected, variance;
};

std::string dump_histograms(const std::string& name, int rows, int cols,
                            const std::vector<double>& observed,
                            const std::vector<double>& expected, double absent_observed,
                            double absent_expected) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(LAMINA_BINARY_DIR) / "chi2";
    std::error_code ec;
    fs::create_directories(dir, ec);
    const fs::path txt = dir / (name + ".txt"), pgm = dir / (name + ".pgm");
    {
        std::ofstream out(txt);
        out << "# chi-square histograms of " << name << ": rows = cos theta bins (from "
            << "cos_theta_min up), columns = phi bins\n# absent: observed " << absent_observed
            << " expected " << absent_expected << "\n# observed\n";
        for (int r = 0; r < rows; ++r) {
            for (int c = 0; c < cols; ++c)
                out << observed[r * cols + c] << (c + 1 < cols ? ' ' : '\n');
        }
        out << "# expected\n";
        for (int r = 0; r < rows; ++r) {
            for (int c = 0; c < cols; ++c)
                out << expected[r * cols + c] << (c + 1 < cols ? ' ' : '\n');
        }
    }
    {
        const double peak = std::max(*std::max_element(observed.begin(), observed.end()),
                                     *std::max_element(expected.begin(), expected.end()));
        std::ofstream out(pgm);
        out << "P2\n" << 2 * cols + 1 << ' ' << rows << "\n255\n";
        for (int r = rows - 1; r >= 0; --r) {  // top row of the image: largest cos θ
            for (int c = 0; c < 2 * cols + 1; ++c) {
                double v = 0;
                if (c < cols) v = observed[r * cols + c];
                if (c > cols) v = expected[r * cols + c - cols - 1];
                out << (c == cols ? 255 : int(std::lround(255 * v / std::max(peak, 1e-300))))
                    << ' ';
            }
            out << '\n';
        }
    }
    return txt.string() + " and " + pgm.string();
}

}  // namespace

double gamma_q(double a, double x) {
    if (x <= 0) return 1;
    if (x < a + 1) return 1 - gamma_p_series(a, x);
    return gamma_q_continued_fraction(a, x);
}

double adaptive_simpson(const std::function<double(double)>& f, double a, double b, double eps,
                        int min_depth, int max_depth) {
    const double fa = f(a), fm = f((a + b) / 2), fb = f(b);
    const double whole = (b - a) / 6 * (fa + 4 * fm + fb);
    return simpson_step(f, a, b, fa, fm, fb, whole, eps, 0, min_depth, max_depth);
}

double integrate_cell(const Chi2PdfFn& pdf, double c0, double c1, double p0, double p1,
                      double eps) {
    const double inner_eps = eps / (c1 - c0);
    return adaptive_simpson(
        [&](double c) {
            return adaptive_simpson([&](double p) { return pdf(direction_of(c, p)); }, p0, p1,
                                    inner_eps);
        },
        c0, c1, eps);
}

namespace {

// The expected counts N·mass per cell and the variance of each (0 for quadrature).
struct Expected {
    std::vector<double> count, variance;
};

// The expected counts and their variances, n·m and n²·v, from each cell's probability mass m
// (and its estimate's variance v) as `mass(row, column, cosθ0, cosθ1, φ0, φ1)` gives it, cells in
// parallel.
template <typename Mass>
Expected expected_by_cell(const Chi2Options& o, const Mass& mass) {
    const int rows = o.cos_theta_bins, cols = o.phi_bins;
    const double dc = (o.cos_theta_max - o.cos_theta_min) / rows, dp = 2 * kPi<double> / cols;
    const double n = double(o.sample_count);
    Expected e{std::vector<double>(std::size_t(rows) * cols, 0.0),
               std::vector<double>(std::size_t(rows) * cols, 0.0)};
#pragma omp parallel for schedule(dynamic)
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            const double c0 = o.cos_theta_min + r * dc;
            const Chi2CellMass m = mass(r, c, c0, c0 + dc, c * dp, (c + 1) * dp);
            e.count[std::size_t(r) * cols + c] = n * m.mass;
            e.variance[std::size_t(r) * cols + c] = n * n * m.variance;
        }
    }
    return e;
}

Chi2Result run_chi2_impl(const Chi2Options& o, const Chi2SampleFn& sample,
                         const std::function<Expected()>& expected_counts) {
    Chi2Result result;
    const int rows = o.cos_theta_bins, cols = o.phi_bins;
    const double dc = (o.cos_theta_max - o.cos_theta_min) / rows, dp = 2 * kPi<double> / cols;
    const double n = double(o.sample_count);
    std::ostringstream why;

    // 1. Histogram of the draws.
    std::vector<double> observed(std::size_t(rows) * cols, 0.0);
    double absent = 0;
    std::uint64_t seed = o.seed;
    if (seed == 0) {  // FNV-1a 64 (Fowler, Noll, Vo) of the name
        seed = 0xcbf29ce484222325ull;
        for (const char ch : o.name)
            seed = (seed ^ std::uint8_t(ch)) * 0x100000001b3ull;
    }
    // LAMINA_CHI2_SEED reruns every test on other numbers (to check the false-alarm rate).
    if (const char* env = std::getenv("LAMINA_CHI2_SEED")) seed ^= std::strtoull(env, nullptr, 10);
    ParticleRng rng(seed, 0, 0);
    std::size_t bad = 0;
    Vec3d bad_example;
    for (std::size_t i = 0; i < o.sample_count; ++i) {
        const std::array<double, 3> u = {rng.uniform_double(), rng.uniform_double(),
                                         rng.uniform_double()};
        const Chi2Draw d = sample(u);
        if (d.absent || !d.w) {
            absent += 1;
            continue;
        }
        const Vec3d w = *d.w;
        const bool finite = std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z);
        if (!finite || std::abs(length(w) - 1) > 1e-6) {
            if (bad++ == 0) bad_example = w;
            continue;
        }
        if (w.z < o.cos_theta_min || w.z > o.cos_theta_max) {  // outside a zoomed domain
            absent += 1;
            continue;
        }
        double phi = std::atan2(w.y, w.x);
        if (phi < 0) phi += 2 * kPi<double>;
        const int r = std::clamp(int((w.z - o.cos_theta_min) / dc), 0, rows - 1);
        const int c = std::clamp(int(phi / dp), 0, cols - 1);
        observed[std::size_t(r) * cols + c] += 1;
    }

    // 2. Expected counts: N ∫_cell pdf dω (and their variances when estimated).
    const Expected e = expected_counts();
    const std::vector<double>& expected = e.count;
    result.pdf_integral = std::accumulate(expected.begin(), expected.end(), 0.0) / n;
    const double variance_sum = std::accumulate(e.variance.begin(), e.variance.end(), 0.0);
    result.pdf_integral_se = std::sqrt(variance_sum) / n;
    result.absent_fraction = absent / n;
    const double absent_expected = std::max(0.0, n * (1 - result.pdf_integral));

    // 3. Draws outside the support.
    constexpr double kZero = 1e-9;
    std::size_t outside = 0;
    for (std::size_t i = 0; i < observed.size(); ++i) {
        if (expected[i] <= kZero && observed[i] > 0) outside += std::size_t(observed[i]);
    }
    if (bad > 0) {
        why << bad << " draws are not unit directions, e.g. (" << bad_example.x << ", "
            << bad_example.y << ", " << bad_example.z << "). ";
    }
    if (outside > 0) why << outside << " draws fall where the pdf is zero. ";
    if (absent_expected <= kZero && absent > 0) {
        why << absent
            << " draws are absent (failed, lost, delta or outside the domain) but the pdf "
               "integrates to "
            << result.pdf_integral << ". ";
    }
    if (result.pdf_integral > 1 + 1e-6 + 5 * result.pdf_integral_se) {
        why << "the pdf integrates to " << result.pdf_integral << " > 1. ";
    }

    // 4. Pearson statistic over the cells plus the absent bin, pooling expected counts < 5.
    std::vector<Bin> bins;
    bins.reserve(observed.size() + 1);
    for (std::size_t i = 0; i < observed.size(); ++i)
        bins.push_back({observed[i], expected[i], e.variance[i]});
    bins.push_back({absent, absent_expected, variance_sum});
    std::sort(bins.begin(), bins.end(),
              [](const Bin& a, const Bin& b) { return a.expected < b.expected; });
    constexpr double kMinExpected = 5;
    double chi2 = 0, pooled_obs = 0, pooled_exp = 0, pooled_var = 0;
    int dof = 0;
    for (const Bin& b : bins) {
        if (b.expected < kMinExpected || (pooled_exp > 0 && pooled_exp < kMinExpected)) {
            pooled_obs += b.observed;
            pooled_exp += b.expected;
            pooled_var += b.variance;
        } else {
            chi2 += sqr(b.observed - b.expected) / (b.expected + b.variance);
            ++dof;
        }
    }
    if (pooled_exp > kZero) {
        chi2 += sqr(pooled_obs - pooled_exp) / (pooled_exp + pooled_var);
        ++dof;
    }
    dof -= 1;
    result.chi2 = chi2;
    result.dof = dof;
    result.level = 1 - std::pow(1 - o.significance, 1.0 / o.test_count);
    result.p_value = dof > 0 ? gamma_q(dof / 2.0, chi2 / 2) : 1.0;
    if (dof <= 0) why << "no degrees of freedom left after pooling. ";
    if (result.p_value < result.level) {
        why << "chi2 = " << chi2 << " with " << dof << " dof: p = " << result.p_value
            << " < Sidak level " << result.level << ". ";
    }
    result.passed = why.str().empty();
    if (!result.passed) {
        why << "(pdf integral " << result.pdf_integral << ", absent fraction "
            << result.absent_fraction << ") Histograms: "
            << dump_histograms(o.name, rows, cols, observed, expected, absent, absent_expected);
        result.message = o.name + ": " + why.str();
    }
    return result;
}

}  // namespace

Chi2Result run_chi2(const Chi2Options& o, const Chi2SampleFn& sample, const Chi2PdfFn& pdf) {
    return run_chi2_impl(o, sample, [&] {
        return expected_by_cell(o, [&](int, int, double c0, double c1, double p0, double p1) {
            return Chi2CellMass{integrate_cell(pdf, c0, c1, p0, p1, o.cell_tolerance), 0.0};
        });
    });
}

Chi2Result run_chi2_estimated(const Chi2Options& o, const Chi2SampleFn& sample,
                              const Chi2CellMassFn& cell_mass) {
    return run_chi2_impl(o, sample, [&] { return expected_by_cell(o, cell_mass); });
}

double integrate_hemisphere(const Chi2PdfFn& f, double alpha, double eps, int phi_pieces) {
    std::vector<double> s = {0.0};
    for (double x = sqr(alpha) / 64; x < 1; x *= 4)
        s.push_back(x);
    s.push_back(1.0);
    double total = 0;
    for (std::size_t k = 0; k + 1 < s.size(); ++k) {
        // D(wm) is defined as 0 on the horizon (wm.z = 0) while its limit is not: the lowest band
        // starts just above it, so that Simpson's end nodes see the limit (a null set either way).
        const double c0 = std::max(1 - s[k + 1], std::numeric_limits<double>::min());
        for (int p = 0; p < phi_pieces; ++p)
            total += integrate_cell(f, c0, 1 - s[k], 2 * kPi<double> * p / phi_pieces,
                                    2 * kPi<double> * (p + 1) / phi_pieces,
                                    eps / double(s.size() * phi_pieces));
    }
    return total;
}

}  // namespace lamina::test
