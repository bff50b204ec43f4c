// lamina render: a sphere of a stack rendered with a model or the random-walk reference, or the
// comparison sheet of every supporting model (docs/rendering.md).
#include "cli/commands.h"
#include "cli/settings_options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "layers/stack.h"
#include "models/random_walk/random_walk_model.h"
#include "models/registry.h"
#include "render/contact_sheet.h"
#include "render/image.h"
#include "render/renderer.h"
#include "simulator/goniophotometer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace lamina::cli {

namespace {

struct RenderArgs {
    std::string stack, model = "random-walk", env = "studio", light, out;
    /// The random-walk reference's transport (its named settings are its model options).
    TransportSettings transport;
    std::vector<std::string> options;
    int size = 512, spp = 64, threads = 0;
    std::uint64_t seed = 1;
    double exposure = 0;
    bool compare = false;
};

int run_render(const RenderArgs& a) {
    if (!(std::abs(a.exposure) <= kMaxExposureStops))  // NaN too
        throw InputError("command line", "--exposure",
                         fmt::format("{} stops is outside [-{:g}, {:g}]", a.exposure,
                                     kMaxExposureStops, kMaxExposureStops));
    const Stack stack = load_stack(a.stack);
    Environment env = Environment::named(a.env);
    if (!a.light.empty()) env.sun = parse_directional_light(a.light);
    RenderSettings s;
    s.size = a.size;
    s.spp = a.spp;
    s.seed = a.seed;
    s.threads = a.threads;
    s.lobe_alpha = lobe_alpha_for(stack);  // a proposal density only (renderer.h)
    s.brushed = brushed_for(stack);
    if (a.out.empty()) throw InputError("command line", "--out", "required");
    // The reference's transport settings become its model options unless given as --option
    // already; for another model they are an error unless left at their defaults.
    std::vector<std::string> options = a.options;
    const std::vector<std::string> defaults = random_walk_assignments(TransportSettings{});
    const std::vector<std::string> given = random_walk_assignments(a.transport);
    for (std::size_t k = 0; k < given.size(); ++k) {
        const std::string key = given[k].substr(0, given[k].find('='));
        const bool as_option = std::any_of(options.begin(), options.end(), [&](const auto& o) {
            return o.rfind(key + "=", 0) == 0;
        });
        if ((a.compare || a.model == "random-walk") && !as_option)
            options.push_back(given[k]);
        else if (given[k] != defaults[k])
            throw InputError(
                "command line", "--" + key,
                "applies to the random-walk reference only, not to --model " + a.model);
    }

    if (!a.compare) {
        const auto model = make_model(a.model, stack, options);
        if (!model->support().brdf)
            throw InputError(a.stack, "--model", "not supported: " + model->support().reason);
        // --out NAME, NAME.png or NAME.exr (any case): NAME.png and NAME.exr.
        std::filesystem::path out = a.out;
        std::string extension = out.extension().string();
        std::transform(extension.begin(), extension.end(), extension.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        if (extension == ".png" || extension == ".exr") out.replace_extension();
        const std::string name = out.filename().string();
        if (name.empty() || name == "." || name == "..")
            throw InputError(a.out, "--out",
                             "a file name is expected (NAME, NAME.png or NAME.exr), not a folder; "
                             "a folder is --compare's");
        // The folder before the rendering, so that an --out that cannot be written fails now; both
        // files are staged and moved into place together (nothing half-written, no folder left
        // behind by a failed or interrupted run).
        StagedOutput staged(out.has_parent_path() ? out.parent_path() : ".", "--out");
        const Rendering r = render_sphere(*model, env, s);
        write_png(staged.stage_path(name + ".png"), r.image, a.exposure);
        write_exr(staged.stage_path(name + ".exr"), r.image);
        staged.commit();
        fmt::print(stderr, "lamina render: {} in {:.1f} s -> {}.png (+ .exr)\n", a.model, r.seconds,
                   out.string());
        return 0;
    }

    // --compare: the reference and every analytic model, one sheet.
    const std::filesystem::path dir = a.out;
    write_comparison(stack, env, s, dir, a.exposure, options);
    fmt::print(stderr, "lamina render --compare: {} -> {}\n", stack.name,
               (dir / "compare.png").string());
    return 0;
}

}  // namespace

Runner add_render(CLI::App& app) {
    auto a = std::make_shared<RenderArgs>();
    auto* cmd = app.add_subcommand(
        "render", "Render a sphere of the stack with a model or the random-walk reference");
    cmd->add_option("stack", a->stack, "Stack JSON file")->required();
    cmd->add_option("--model", a->model, "Model name, or random-walk (default)");
    cmd->add_option("--option", a->options, "Model flag KEY=VALUE, repeatable");
    cmd->add_option("--env", a->env, "Environment: studio (default), uniform, sky, dark");
    cmd->add_option("--light", a->light,
                    "A directional light x,y,z,E (towards the light; irradiance E or Er,Eg,Eb)");
    cmd->add_option("--size", a->size, "Image width and height in pixels (default 512)")
        ->check(CLI::Range(8, 8192));
    cmd->add_option("--spp", a->spp, "Samples per pixel (default 64)")
        ->check(CLI::Range(1, 1 << 20));
    // Read as simulate's seed is: a whole number in [0, 2^64 − 1] ("-1" refused, not wrapped).
    add_setting_option(
        cmd, {.name = "seed", .help = "Seed (images are reproducible for a seed)", .min = 0},
        a->seed);
    cmd->add_option("--threads", a->threads,
                    fmt::format("Threads (default: all), at most {}", kMaxThreads))
        ->check(CLI::Range(0, kMaxThreads));  // as simulate's: OpenMP creates them all at once
    cmd->add_option("--exposure", a->exposure,
                    "Exposure in stops for the PNG, [-40, 40] (default 0)");
    // The reference's transport (layers/transport_settings.h), but the numbers it keeps at their
    // defaults (random_walk_options).
    add_physics_option(cmd, a->transport);
    add_settings_options(cmd, a->transport, {"max_microsurface_order", "max_events"});
    cmd->add_flag("--compare", a->compare,
                  "Render the reference and every analytic model; --out is then a folder holding "
                  "compare.png, one PNG+EXR per model and errors.csv");
    cmd->add_option("--out", a->out,
                    "Output image NAME, NAME.png or NAME.exr: NAME.png and NAME.exr are written "
                    "(with --compare: a folder)")
        ->required();
    return [a] { return run_render(*a); };
}

}  // namespace lamina::cli
