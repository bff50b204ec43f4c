// lamina render: a sphere of a stack rendered with a model or the random-walk reference, or the
// comparison sheet of every supporting model (docs/rendering.md).
#include "cli/commands.h"
#include "core/error.h"
#include "layers/stack.h"
#include "models/registry.h"
#include "physics/microfacet.h"
#include "render/contact_sheet.h"
#include "render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace lamina::cli {

namespace {

struct RenderArgs {
    std::string stack, model = "random-walk", env = "studio", light, out;
    std::string transmission_masking = "smith";
    std::string microsurface = "single";
    std::vector<std::string> options;
    int size = 512, spp = 64, threads = 0;
    std::uint64_t seed = 1;
    double exposure = 0;
    bool compare = false;
};

void write_pair(const std::filesystem::path& png, const Image& img, double ev) {
    write_png(png, img, ev);
    std::filesystem::path exr = png;
    exr.replace_extension(".exr");
    write_exr(exr, img);
}

int run_render(const RenderArgs& a) {
    const Stack stack = load_stack(a.stack);
    Environment env = Environment::named(a.env);
    if (!a.light.empty()) env.sun = parse_directional_light(a.light);
    RenderSettings s;
    s.size = a.size;
    s.spp = a.spp;
    s.seed = a.seed;
    s.threads = a.threads;
    s.lobe_alpha = lobe_alpha_for(stack);  // a proposal density only (renderer.h)
    if (a.out.empty()) throw InputError("command line", "--out", "required");
    // The reference's refraction masking, a model option of random-walk (validated there).
    parse_transmission_masking(a.transmission_masking);
    std::vector<std::string> options = a.options;
    // The reference's flags become its model options unless given as --option already.
    auto pass_to_reference = [&](const std::string& key, const std::string& value,
                                 const std::string& fallback, const std::string& flag) {
        const bool given_as_option =
            std::any_of(options.begin(), options.end(),
                        [&](const auto& o) { return o.rfind(key + "=", 0) == 0; });
        if ((a.compare || a.model == "random-walk") && !given_as_option)
            options.push_back(key + "=" + value);
        else if (value != fallback)
            throw InputError(
                "command line", flag,
                "applies to the random-walk reference only, not to --model " + a.model);
    };
    pass_to_reference("transmission-masking", a.transmission_masking, "smith",
                      "--transmission-masking");
    if (a.microsurface != "single" && a.microsurface != "multiple")
        throw InputError("command line", "--microsurface",
                         "'" + a.microsurface +
                             "' is not a microsurface model: use single or "
                             "multiple");
    pass_to_reference("microsurface", a.microsurface, "single", "--microsurface");

    if (!a.compare) {
        const auto model = make_model(a.model, stack, options);
        if (!model->support().brdf)
            throw InputError(a.stack, "--model", "not supported: " + model->support().reason);
        const Rendering r = render_sphere(*model, env, s);
        std::filesystem::path out = a.out;
        if (out.extension() != ".png") out += ".png";
        if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
        write_pair(out, r.image, a.exposure);
        fmt::print(stderr, "lamina render: {} in {:.1f} s -> {} (+ .exr)\n", a.model, r.seconds,
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
    cmd->add_option("--seed", a->seed, "Seed (images are reproducible for a seed)");
    cmd->add_option("--threads", a->threads, "Threads (default: all)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--exposure", a->exposure, "Exposure in stops for the PNG (default 0)");
    cmd->add_option("--transmission-masking", a->transmission_masking,
                    "The random-walk reference's masking of light refracted by a rough dielectric: "
                    "smith (default, B(1+Λi, 1+Λo)) or pbrt (1/(1+Λi+Λo), as pbrt-v4)");
    cmd->add_option("--microsurface", a->microsurface,
                    "The random-walk reference's rough interfaces: single (default, single-"
                    "scattering microfacet BSDFs) or multiple (the microsurface random walk of "
                    "Heitz et al. 2016, nothing lost)");
    cmd->add_flag("--compare", a->compare,
                  "Render the reference and every analytic model; --out is then a folder holding "
                  "compare.png, one PNG+EXR per model and errors.csv");
    cmd->add_option("--out", a->out, "Output PNG (an EXR is written next to it), or a folder")
        ->required();
    return [a] { return run_render(*a); };
}

}  // namespace lamina::cli
