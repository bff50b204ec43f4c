// lamina eval: a model's BSDF at points, at a batch of directions, or averaged over the
// goniophotometer's bins (docs/models.md, "Evaluating a model").
#include "cli/commands.h"
#include "cli/options.h"
#include "cli/settings_options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/incidences.h"
#include "core/math.h"
#include "core/spherical.h"
#include "layers/stack.h"
#include "models/numerics/binned.h"
#include "models/random_walk/random_walk_model.h"
#include "models/registry.h"
#include "models/spectral_projection.h"
#include "simulator/goniophotometer.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace lamina::cli {

namespace {

struct EvalArgs {
    std::string model, stack, theta_i, directions, out, grid = HemisphereGrid{}.to_string(),
                                                        side = "R";
    double theta_o = 0.0, phi_o = 0.0, phi_i = 0.0;
    bool theta_o_given = false, phi_o_given = false;  ///< whether --theta-o / --phi-o were given
    bool side_given = false, grid_given = false;      ///< whether --side / --grid were given
    bool binned = false, pdf = false;
    /// The spectral settings shared with simulate (spectral, spectral_min_nm, spectral_max_nm).
    SimulationSettings spectral;
    std::vector<std::string> options;
    std::uint64_t samples = 0, seed = 0;  ///< random-walk only; 0: the model's own option
};

/// Applies --samples/--seed to a random-walk model; rejects them for the analytic models (by the
/// registry's entry: a stochastic model the registry could not build for the stack, which is not
/// a RandomWalkModel, is left for the caller's support check to report).
RandomWalkModel* configure_random_walk(const ModelEntry& entry, Model& model, const EvalArgs& a) {
    auto* rw = dynamic_cast<RandomWalkModel*>(&model);
    if (!rw) {
        if (entry.stochastic) return nullptr;
        if (a.samples != 0 || a.seed != 0)
            throw InputError("command line", a.samples != 0 ? "--samples" : "--seed",
                             "only the stochastic model random-walk takes a sample count or seed");
        if (a.pdf)
            throw InputError("command line", "--pdf",
                             "only the stochastic model random-walk has a sampling density here");
        return nullptr;
    }
    if (a.samples != 0) rw->set_samples(a.samples);
    if (a.seed != 0) rw->set_seed(a.seed);
    return rw;
}

/// A decimal number, as every other number lamina reads (setting_detail::parse_real: no hex
/// floats, which strtod would take).
double parse_number(const std::string& text, const std::string& where, const std::string& field) {
    double v = 0;
    if (!setting_detail::parse_real(text, v) || text.find_first_of(" \t") != std::string::npos)
        throw InputError(where, field, fmt::format("'{}' is not a finite number", text));
    return v;
}

/// θ in degrees within [lo, hi) or [lo, hi] (closed_hi).
void check_angle(double v, double lo, double hi, bool closed_hi, const std::string& where,
                 const std::string& field) {
    if (!(v >= lo && (closed_hi ? v <= hi : v < hi)))  // NaN too
        throw InputError(
            where, field,
            fmt::format("{} degrees is outside [{}, {}{}", v, lo, hi, closed_hi ? "]" : ")"));
}

Side parse_side(const std::string& s, const std::string& where, const std::string& field) {
    if (s == "R") return Side::Reflection;
    if (s == "T") return Side::Transmission;
    throw InputError(where, field, fmt::format("side '{}' must be R or T", s));
}

/// The model evaluates `side` of `stack`: refused otherwise, an opaque stack's BTDF under `field`
/// of `where` (the option or the directions file's line), a model's missing side under --model of
/// the stack file.
void require_side(const Model& model, const Stack& stack, Side side, const std::string& stack_file,
                  const std::string& where, const std::string& field) {
    if (side == Side::Transmission && !stack.transmits())
        throw InputError(where, field,
                         "side T: the stack is opaque (its base is not a dielectric), so it has no "
                         "BTDF; allowed: R, or T for a slab");
    const Support s = model.support();
    if (side == Side::Reflection ? !s.brdf : !s.btdf)
        throw InputError(
            stack_file, "--model",
            fmt::format("not supported: {} ({})",
                        s.reason.empty() ? "this model has no BTDF for this stack" : s.reason,
                        side == Side::Reflection ? "BRDF" : "BTDF"));
}

/// The light's direction at (θi, φi) in degrees, as the goniophotometer's --phi-i.
Vec3d light_direction(double theta_i, double phi_i) {
    return direction_from_angles(deg_to_rad(theta_i), deg_to_rad(phi_i));
}

Rgbd eval_at(const Model& model, double theta_i, double phi_i, double theta_o, double phi_o,
             Side side) {
    return model.eval(light_direction(theta_i, phi_i),
                      direction_from_angles(deg_to_rad(theta_o), deg_to_rad(phi_o), side));
}

/// The model eval runs: the registry's, or on a spectral stack (simulate's `--spectral auto`
/// rule, is_spectral_run) its linear sRGB from per-wavelength models
/// (models/spectral_projection.h), the colour a spectral run's brdf.csv holds. The random walk
/// stays in the RGB mode.
std::unique_ptr<Model> make_eval_model(const ModelEntry& entry, const ModelOptions& options,
                                       const Stack& stack, const EvalArgs& a) {
    auto model = entry.make(stack, options);
    if (!is_spectral_run(stack, a.spectral)) return model;
    if (dynamic_cast<const RandomWalkModel*>(model.get())) {
        if (a.spectral.spectral == SpectralMode::On)
            throw InputError("command line", "--spectral",
                             "the random walk evaluates the RGB mode (each channel at its "
                             "wavelength); trace spectra with lamina simulate --spectral on");
        return model;
    }
    const double min_nm = a.spectral.spectral_min_nm, max_nm = a.spectral.spectral_max_nm;
    if (!(max_nm - min_nm >= 3))
        throw InputError(
            "command line", "--spectral-max-nm",
            fmt::format("the range [{}, {}] nm must be at least 3 nm wide", min_nm, max_nm));
    return make_spectral_projection([&](const Stack& at) { return entry.make(at, options); }, stack,
                                    SpectralQuadrature{.min_nm = min_nm, .max_nm = max_nm});
}

int run_eval(const EvalArgs& a) {
    // NAME or NAME:KEY=VALUE... (the study's ablation names); --option adds to the flags.
    const ModelSpec spec = parse_model_spec(a.model);
    const ModelEntry& entry = *spec.entry;
    std::vector<std::string> assignments = spec.assignments;
    assignments.insert(assignments.end(), a.options.begin(), a.options.end());
    const ModelOptions options = resolve_options(entry, assignments);
    if (!(a.phi_i >= 0 && a.phi_i <= 360))  // NaN too
        throw InputError("command line", "--phi-i",
                         fmt::format("{} degrees is outside [0, 360]", a.phi_i));
    const int modes = int(a.binned) + int(!a.directions.empty());
    if (modes > 1)
        throw InputError("command line", "--binned",
                         "--binned and --directions are different modes; use one");
    if ((a.binned || !a.directions.empty()) && a.out.empty())
        throw InputError("command line", "--out", "this mode writes a CSV file: give --out");
    if (modes == 1 && (a.theta_o_given || a.phi_o_given))
        throw InputError("command line", a.theta_o_given ? "--theta-o" : "--phi-o",
                         a.binned ? "--binned covers every outgoing direction: leave it out"
                                  : "the directions come from the --directions file: leave it out");
    // An option the mode has no use for is refused rather than ignored: the user meant something.
    if (modes == 1 && a.side_given)
        throw InputError("command line", "--side",
                         a.binned ? "--binned tabulates every side the model supports: leave it out"
                                  : "the directions file gives each row's side: leave it out");
    if (!a.binned && a.grid_given)
        throw InputError("command line", "--grid",
                         "the bins are for --binned; a point or a directions file has none");
    if (modes == 0 && !a.out.empty())
        throw InputError("command line", "--out",
                         "a point evaluation prints its value; --out is for --binned and "
                         "--directions");

    if (a.binned) {
        require_tabulable(entry, "command line", "--model");
        const std::vector<double> thetas = parse_incidences(
            a.theta_i.empty() ? default_incidences_text() : a.theta_i, "--theta-i");
        SimulationSettings binning;  // the goniophotometer's bins for this stack and φi
        binning.grid = HemisphereGrid::parse(a.grid, "--grid");
        binning.phi_i_deg = a.phi_i;
        const Stack stack = load_stack(a.stack);
        const HemisphereGrid grid = simulation_grid(stack, binning);
        const auto model = make_eval_model(entry, options, stack, a);
        configure_random_walk(entry, *model, a);
        const Support s = model->support();
        if (!s.brdf && !s.btdf) throw InputError(a.stack, "--model", "not supported: " + s.reason);
        write_file_atomic(a.out, bin_model(*model, grid, thetas, a.phi_i).to_csv());
        return 0;
    }

    if (!a.directions.empty()) {
        // Bounded (a stream without end is refused, not read into memory); a NUL byte is no
        // text.
        constexpr std::size_t kDirectionsMaxBytes = std::size_t(64) << 20;
        const std::string text =
            read_file_bounded(a.directions, kDirectionsMaxBytes, "the directions file");
        if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
            throw InputError(a.directions, "",
                             fmt::format("a NUL byte at offset {}; allowed: CSV text", nul));
        std::istringstream in(text);
        // The light's azimuth is --phi-i's, or each row's in a phi_i column (an anisotropic
        // stack seen from several azimuths in one batch).
        constexpr const char* kHeader = "theta_i,theta_o,phi_o,side";
        constexpr const char* kHeaderPhi = "theta_i,phi_i,theta_o,phi_o,side";
        std::string line;
        if (std::getline(in, line) && !line.empty() && line.back() == '\r') line.pop_back();
        const bool with_phi = line == kHeaderPhi;
        if (line != kHeader && !with_phi)
            throw InputError(a.directions, "line 1",
                             fmt::format("expected the header '{}' or '{}'", kHeader, kHeaderPhi));
        if (with_phi && a.phi_i != 0)
            throw InputError(
                "command line", "--phi-i",
                fmt::format("{} has a phi_i column: give the azimuths there", a.directions));
        const std::size_t columns = with_phi ? 5 : 4;
        struct Row {
            double ti, pi, to, po;
            Side side;
            std::string text, where;
        };
        std::vector<Row> rows;
        for (int n = 2; std::getline(in, line); ++n) {
            if (!line.empty() && line.back() == '\r') line.pop_back();
            if (line.empty()) continue;
            std::vector<std::string> cells;
            std::stringstream ls(line);
            for (std::string c; std::getline(ls, c, ',');)
                cells.push_back(c);
            if (line.back() == ',') cells.emplace_back();  // getline drops a last, empty cell
            const std::string where = fmt::format("line {}", n);
            if (cells.size() != columns)
                throw InputError(
                    a.directions, where,
                    fmt::format("expected {} columns, found {}", columns, cells.size()));
            const std::size_t o = with_phi ? 1 : 0;  // the columns after theta_i
            Row r{parse_number(cells[0], a.directions, where + ", theta_i"),
                  with_phi ? parse_number(cells[1], a.directions, where + ", phi_i") : a.phi_i,
                  parse_number(cells[1 + o], a.directions, where + ", theta_o"),
                  parse_number(cells[2 + o], a.directions, where + ", phi_o"),
                  parse_side(cells[3 + o], a.directions, where + ", side"),
                  line,
                  where};
            check_incidence(r.ti, a.directions, where + ", theta_i");
            check_angle(r.pi, 0, 360, true, a.directions, where + ", phi_i");
            check_angle(r.to, 0, 90, true, a.directions, where + ", theta_o");
            check_angle(r.po, -360, 360, true, a.directions, where + ", phi_o");
            rows.push_back(r);
        }
        const Stack stack = load_stack(a.stack);
        const auto model = make_eval_model(entry, options, stack, a);
        configure_random_walk(entry, *model, a);
        std::string out = std::string(with_phi ? kHeaderPhi : kHeader) + ",f_r,f_g,f_b\n";
        for (const Row& r : rows) {
            require_side(*model, stack, r.side, a.stack, a.directions, r.where + ", side");
            const Rgbd f = eval_at(*model, r.ti, r.pi, r.to, r.po, r.side);
            fmt::format_to(std::back_inserter(out), "{},{},{},{}\n", r.text, f[0], f[1], f[2]);
        }
        write_file_atomic(a.out, out);
        return 0;
    }

    // One point.
    const std::vector<double> thetas = parse_incidences(a.theta_i, "--theta-i");
    if (thetas.size() != 1)
        throw InputError("command line", "--theta-i",
                         "a point evaluation takes one angle (lists are for --binned)");
    if (!a.theta_o_given) throw InputError("command line", "--theta-o", "required");
    if (!a.phi_o_given) throw InputError("command line", "--phi-o", "required");
    check_angle(a.theta_o, 0, 90, true, "command line", "--theta-o");
    check_angle(a.phi_o, -360, 360, true, "command line", "--phi-o");
    const Side side = parse_side(a.side, "command line", "--side");
    const Stack stack = load_stack(a.stack);
    const auto model = make_eval_model(entry, options, stack, a);
    require_side(*model, stack, side, a.stack, "command line", "--side");
    if (const RandomWalkModel* rw = configure_random_walk(entry, *model, a)) {
        const Vec3d wi = light_direction(thetas[0], a.phi_i);
        const Vec3d wo = direction_from_angles(deg_to_rad(a.theta_o), deg_to_rad(a.phi_o), side);
        if (a.pdf) {
            // pdf se: the exit density of the walk's sample() at wo (docs/rendering.md §1.4).
            const RandomWalkPdf p = rw->pdf_estimate(wi, wo);
            fmt::print("{} {}\n", p.pdf, p.se);
            return 0;
        }
        // f_r f_g f_b se_r se_g se_b: the estimate and its standard error.
        const RandomWalkEstimate e = rw->estimate(wi, wo);
        fmt::print("{} {} {} {} {} {}\n", e.f[0], e.f[1], e.f[2], e.se[0], e.se[1], e.se[2]);
        return 0;
    }
    const Rgbd f = eval_at(*model, thetas[0], a.phi_i, a.theta_o, a.phi_o, side);
    fmt::print("{} {} {}\n", f[0], f[1], f[2]);
    return 0;
}

}  // namespace

Runner add_eval(CLI::App& app) {
    auto a = std::make_shared<EvalArgs>();
    auto* cmd = app.add_subcommand(
        "eval", "Evaluate an analytic model: at a point, a batch of directions, or on the bins");
    cmd->add_option("--model", a->model, "Model name (see `lamina models`)")->required();
    cmd->add_option("--stack", a->stack, "Stack JSON file")->required();
    cmd->add_option("--theta-i", a->theta_i,
                    "Incidence(s) in degrees, [0, 90); a comma list with --binned (default " +
                        default_incidences_text() + ")");
    cmd->add_option("--phi-i", a->phi_i,
                    "Incidence azimuth in degrees, [0, 360] (as simulate's); a non-zero one, or "
                    "an anisotropic stack, bins on the unfolded grid (phi over [0, 360))")
        ->capture_default_str();
    // Decimal numbers only, as --theta-i and the --directions file (CLI11 alone takes hex too).
    auto decimal = [](const std::string& text) -> std::string {
        double v = 0;
        return setting_detail::parse_real(text, v) ? "" : "'" + text + "' is not a number";
    };
    cmd->add_option("--theta-o", a->theta_o, "Outgoing polar angle in degrees, [0, 90]")
        ->check(decimal)
        ->each([a](const std::string&) { a->theta_o_given = true; });
    cmd->add_option("--phi-o", a->phi_o,
                    "Outgoing azimuth in degrees, [-360, 360] (the mirror direction at 180)")
        ->check(decimal)
        ->each([a](const std::string&) { a->phi_o_given = true; });
    cmd->add_option("--side", a->side, "R (reflection) or T (transmission; θo from -z)")
        ->each([a](const std::string&) { a->side_given = true; });
    cmd->add_option("--directions", a->directions,
                    "CSV of directions: header theta_i,theta_o,phi_o,side (the light at "
                    "--phi-i) or theta_i,phi_i,theta_o,phi_o,side");
    cmd->add_flag("--binned", a->binned,
                  "Cos-weighted bin averages in the goniophotometer's brdf.csv format");
    cmd->add_option("--grid", a->grid, "Bins for --binned, NTHETAxNPHI")
        ->capture_default_str()
        ->each([a](const std::string&) { a->grid_given = true; });
    cmd->add_option("--out", a->out, "Output CSV (written atomically)");
    add_settings_options_only(cmd, a->spectral, {"spectral", "spectral_min_nm", "spectral_max_nm"});
    // Whole numbers read as the settings' are ("-3" refused, not wrapped; the bounds named);
    // 0, the default, leaves the model's own option. ≥ 2 samples: one walk has no standard error;
    // ≤ 1e9: a billion walks take about an hour for one query (3 s per million on the benchmark
    // plastic, one core); the bound keeps a typo from running for days.
    auto add_whole = [cmd](const SettingInfo& info, std::uint64_t& member) {
        cmd->add_option_function<std::string>(
            option_name(info.name),
            [&member, info](const std::string& text) {
                member = SettingCodec<std::uint64_t>::from_text(text, info, "command line",
                                                                option_name(info.name));
            },
            info.help);
    };
    add_whole({.name = "samples",
               .help = "random-walk: walks per query, at least 2 (default: its samples option, "
                       "1024), at most 1e9; a point evaluation then prints f_r f_g f_b se_r "
                       "se_g se_b",
               .min = 2,
               .max = 1e9},
              a->samples);
    cmd->add_flag("--pdf", a->pdf,
                  "random-walk, one point: print the exit density of its sampling at wo and its "
                  "standard error (pdf se, 1/sr) instead of f");
    add_whole({.name = "seed", .help = "random-walk: seed of the walks (≥ 1)", .min = 1}, a->seed);
    cmd->add_option("--option", a->options,
                    "Model flag KEY=VALUE, repeatable (see `lamina models --options`)");
    return [a] { return run_eval(*a); };
}

}  // namespace lamina::cli
