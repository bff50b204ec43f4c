#include "models/registry.h"

#include "core/error.h"
#include "models/belcour/belcour.h"
#include "models/belcour_barla/belcour_barla.h"
#include "models/ddb22/ddb22.h"
#include "models/lamina1/lamina1.h"
#include "models/lamina_coat/lamina_coat.h"
#include "models/production/production_coats.h"
#include "models/production/unity_stacklit.h"
#include "models/random_walk/random_walk_model.h"
#include "models/transfer_matrix/transfer_matrix.h"
#include "models/weidlich_wilkie/ww_family.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <map>

namespace lamina {

namespace {

// A variant of a family: its options are the family's flags with the variant's defaults, and its
// factory applies the user's flags to those defaults.
template <typename Choices>
ModelEntry variant(std::string name, std::string description, std::string supports,
                   ModelFamily<Choices> family, std::string group = "2019",
                   bool represents_anisotropy = false) {
    const std::string n = name;
    return {std::move(name),
            std::move(description),
            std::move(supports),
            [family, n] { return family.table(n).specs(family.variant(n)); },
            [family, n](const Stack& stack, const ModelOptions& o) {
                return family.make(n, stack, family.table(n).parse(o, family.variant(n)));
            },
            false,
            std::move(group),
            represents_anisotropy};
}

const ModelFamily<WWChoices> kWeidlichWilkie{
    [](const std::string&) -> const ModelOptionTable<WWChoices>& { return ww_option_table(); },
    ww_variant, make_ww_model};
const ModelFamily<BelcourChoices> kBelcour{
    [](const std::string& n) -> const ModelOptionTable<BelcourChoices>& {
        return n == "wb20" ? wb20_option_table() : belcour_option_table();
    },
    belcour_variant, make_belcour_model};
const ModelFamily<TmChoices> kTransferMatrix{tm_option_table, tm_variant, make_tm_model};
const ModelFamily<Ddb22Choices> kDdb22{
    [](const std::string&) -> const ModelOptionTable<Ddb22Choices>& {
        return ddb22_option_table();
    },
    [](const std::string&) { return Ddb22Choices{}; }, make_ddb22_model};

/// What a model is for a stack it does not represent (docs/physics.md §9 and §3): a thin film
/// (no model), or an anisotropic interface (alpha = [alpha_x, alpha_y]) for a model whose entry
/// does not represent anisotropy; the goniophotometer traces both. Such a model is not built: one
/// that ignored the film or the anisotropy would return another stack's values. It supports
/// nothing and says why.
class StackNotSupported final : public Model {
  public:
    StackNotSupported(std::string name, std::string reason)
        : name_(std::move(name)), reason_(std::move(reason)) {}
    std::string name() const override { return name_; }
    Support support() const override { return {false, false, reason_}; }
    Rgbd eval(const Vec3d&, const Vec3d&) const override { return Rgbd(0.0); }

  private:
    std::string name_, reason_;
};

/// The entries with their factories refusing filmed stacks unless the entry represents films
/// (ModelEntry::films), and anisotropic ones unless it represents anisotropy
/// (ModelEntry::represents_anisotropy), with StackNotSupported.
std::vector<ModelEntry> refusing_unrepresented(std::vector<ModelEntry> entries) {
    for (ModelEntry& e : entries)
        e.make = [make = std::move(e.make), name = e.name, films = e.films,
                  anisotropic = e.represents_anisotropy](
                     const Stack& stack, const ModelOptions& options) -> std::unique_ptr<Model> {
            if (stack.has_film() && !films)
                return std::make_unique<StackNotSupported>(
                    name,
                    "thin films are not supported by this model (the goniophotometer traces "
                    "them: lamina simulate)");
            if (stack.is_anisotropic() && !anisotropic)
                return std::make_unique<StackNotSupported>(
                    name,
                    "the stack has an anisotropic interface (alpha = [alpha_x, alpha_y]), which "
                    "this model does not represent");
            return make(stack, options);
        };
    return entries;
}

}  // namespace

const std::vector<ModelEntry>& model_registry() {
    static const std::vector<ModelEntry> entries = refusing_unrepresented({
        variant(
            "ww09",
            "Weidlich & Wilkie, SIGGRAPH Asia 2009 course code: T01 and refraction at h, base at "
            "outside directions",
            "bases: lambertian, conductor, dielectric (slab reflection); anisotropic coat and "
            "conductor; sides: R",
            kWeidlichWilkie, "2019", /*represents_anisotropy=*/true),
        variant("ele10",
                "Elek 2010 (CESCG, Alg. 1): T01 at h, refraction about n, alpha1 <- max(alpha0, "
                "alpha1)",
                "bases: lambertian, conductor, dielectric (slab reflection); anisotropic coat and "
                "conductor; sides: R",
                kWeidlichWilkie, "2019", /*represents_anisotropy=*/true),
        variant("ww-prime",
                "WW': T01, T10 and refraction at n, 1/eta0^2 compression, alpha1 <- max(alpha0, "
                "alpha1)",
                "bases: lambertian, conductor, dielectric (slab reflection); anisotropic coat and "
                "conductor; sides: R",
                kWeidlichWilkie, "2019", /*represents_anisotropy=*/true),
        variant("bel18-forward",
                "Belcour 2018 adding of lobe statistics, cosine mu_i (not reciprocal)",
                "bases: conductor, dielectric; media: absorbing, forward-scattering; sides: R",
                kBelcour),
        variant("bel18-symmetric",
                "Belcour 2018 adding of lobe statistics, cosine |wi.h| (reciprocal)",
                "bases: conductor, dielectric; media: absorbing, forward-scattering; sides: R",
                kBelcour),
        variant("bel-prime",
                "Bel': Bel18 forward with the exact top reflection and a slab BTDF lobe",
                "bases: conductor, dielectric; media: absorbing, forward-scattering; sides: R, T "
                "(slab)",
                kBelcour),
        variant("wb20",
                "after Weier & Belcour 2020: Bel18 forward with 2x2 lobe covariances (Bel18's "
                "variance map per axis, not the paper's refit), each lobe an anisotropic GGX",
                "bases: conductor, dielectric; media: absorbing, forward-scattering; anisotropic "
                "interfaces with their tangents; sides: R",
                kBelcour, "successors", /*represents_anisotropy=*/true),
        variant("tm2",
                "Randrianandrasana et al. 2021 transfer matrices: lobes by energy and HG asymmetry "
                "(conductor base: plugin tm2, exact top; slab: tm2_dielectric, transmitted lobe)",
                "bases: conductor, dielectric; media: absorbing; sides: R, T (slab)",
                kTransferMatrix, "successors"),
        {"lamina-1",
         "lamina-1: exact top reflection, first order through the coat's directional "
         "transmittance, inter-reflection series, lobe widened by the coat's refraction spread",
         "bases: lambertian, conductor, dielectric; media: absorbing, scattering (HG); "
         "anisotropic coat and conductor (not slabs; single scattering); microsurfaces' orders "
         ">= 2 restored on isotropic interfaces; sides: R, T (slab)",
         lamina1_options, make_lamina1, false, "lamina", /*represents_anisotropy=*/true},
        {"random-walk",
         "Position-free random walks with next-event estimation (Guo et al. 2018): the stochastic "
         "per-query reference, unbiased",
         "every stack; sides: R, T (slab)", random_walk_options, make_random_walk, true,
         "reference", /*represents_anisotropy=*/true},
        // The coats engines ship (production_coats.cpp, docs/models.md "Production coats").
        {"openpbr",
         "OpenPBR Surface 1.1 specification: albedo-scaled coat, coat darkening, base "
         "roughening, view-dependent tint",
         "bases: lambertian, conductor (with a thin film); media: absorbing; anisotropic coat and "
         "metal; sides: R",
         openpbr_options, make_openpbr, false, "production", /*represents_anisotropy=*/true,
         /*films=*/true},
        {"openpbr-adobe",
         "Adobe openpbr-bsdf: OpenPBR with view-only albedo scaling (reciprocal off), average "
         "Fresnel darkening, IOR-scaled roughening",
         "bases: lambertian, conductor (with a thin film); media: absorbing; anisotropic coat and "
         "metal; sides: R",
         openpbr_adobe_options, make_openpbr_adobe, false, "production",
         /*represents_anisotropy=*/true, /*films=*/true, /*specification=*/"openpbr"},
        {"standard-surface",
         "Autodesk Standard Surface: coat + coat_color (1 - E_coat(wo)) base, view-only",
         "bases: lambertian, conductor; media: absorbing; sides: R", standard_surface_options,
         make_standard_surface, false, "production"},
        {"enterprise-pbr",
         "Dassault Enterprise PBR 2025x clearcoat: Schlick 0.04, base x (1 - max(Fc(n.v), "
         "Fc(n.l))), reciprocal",
         "bases: lambertian, conductor; eta0 = 1.5; sides: R", enterprise_pbr_options,
         make_enterprise_pbr, false, "production"},
        {"filament",
         "Google Filament clear coat: Schlick 0.04 at l.h, Kelemen visibility, base x (1 - Fc), "
         "base roughness >= coat's",
         "bases: lambertian, conductor; eta0 = 1.5; sides: R", filament_options, make_filament,
         false, "production"},
        {"gltf-clearcoat", "glTF KHR_materials_clearcoat: mix(base, coat, 0.04 Schlick at n.v)",
         "bases: lambertian, conductor; eta0 = 1.5; sides: R", gltf_clearcoat_options,
         make_gltf_clearcoat, false, "production"},
        {"blender-principled",
         "Blender Cycles Principled coat: compensated coat lobe, base x (1 - Cycles' estimate of "
         "its albedo at wo) x tint^(1/mu_t,o), compensated F82-tint metal",
         "bases: lambertian, conductor (with a thin film); media: absorbing; sides: R",
         blender_principled_options, make_blender_principled, false, "production",
         /*represents_anisotropy=*/false, /*films=*/true},
        {"kulla-conty",
         "Kulla & Conty 2017 layering: base x (1 - E(mu_i))(1 - E(mu_o))/(1 - E_avg), reciprocal",
         "bases: lambertian, conductor; media: absorbing; sides: R", kulla_conty_options,
         make_kulla_conty, false, "production"},
        // The registry-wide fuzz draws each model's options in this order, so models are added at
        // the end: the draws of those before them stay as they were.
        variant("tm6",
                "Randrianandrasana et al. 2021 transfer matrices with HG media (plugin tm6): "
                "primary, forward- and back-scattered lobes, exact top, lobes normalized by their "
                "GGX albedo",
                "bases: conductor; media: absorbing, scattering (HG); sides: R", kTransferMatrix,
                "successors"),
        variant("ddb22",
                "de Dinechin & Belcour 2022 as lamina reads it: exact coat reflection + one GGX "
                "lobe with the energy and projected variance of the light the Lambertian returns",
                "bases: lambertian (under 1-8 coats); media: absorbing; sides: R", kDdb22,
                "successors"),
        {"threejs-clearcoat",
         "three.js MeshPhysicalMaterial clearcoat: Schlick 0.04 (spherical-Gaussian fit) at v.h "
         "on the lobe, base x (1 - Fc(n.v)), roughness >= 0.045, compensated metal",
         "bases: lambertian, conductor (with a thin film: KHR_materials_iridescence); eta0 = "
         "1.5; sides: R",
         threejs_clearcoat_options, make_threejs_clearcoat, false, "production",
         /*represents_anisotropy=*/false, /*films=*/true, /*specification=*/"gltf-clearcoat"},
        {"openpbr-materialx",
         "OpenPBR in MaterialX (its graph, GLSL generator): coat throughput 1 - E(wo) by its "
         "fitted albedo, constant coat_color, darkening with F0, compensated lobes",
         "bases: lambertian, conductor; media: absorbing; sides: R", openpbr_materialx_options,
         make_openpbr_materialx, false, "production", /*represents_anisotropy=*/false,
         /*films=*/false, /*specification=*/"openpbr"},
        {"lamina-coat",
         "lamina-coat: OpenPBR's structure and cost (coat lobe, attenuated, darkened, roughened "
         "base) with terms derived from the layering and fitted on the study's reference",
         "bases: lambertian, conductor; media: absorbing; eta0 in [1.1, 2.6]; sides: R",
         lamina_coat_options, make_lamina_coat, false, "lamina"},
        {"unity-stacklit",
         "Unity HDRP StackLit coat: Belcour 2018's adding of energy and variance per view "
         "(Fresnel chain, roughened base), coat and base lobes compensated by HDRP's FGD texture",
         "bases: lambertian, conductor; media: absorbing; eta0 >= 1; anisotropic metal; sides: R",
         unity_stacklit_options, make_unity_stacklit, false, "production",
         /*represents_anisotropy=*/true},
        {"standard-surface-materialx",
         "Standard Surface in MaterialX (its graph, GLSL generator): coat throughput 1 - E(wo) by "
         "its fitted albedo, constant coat_color, compensated lobes, artistic_ior metal",
         "bases: lambertian, conductor; media: absorbing; sides: R",
         standard_surface_materialx_options, make_standard_surface_materialx, false, "production",
         /*represents_anisotropy=*/false, /*films=*/false, /*specification=*/"standard-surface"},
        {"bb17",
         "Belcour & Barla 2017 as their shader ships it: GGX lobe, uncorrelated Smith, film "
         "Fresnel by the Airy sum's 3 orders on the CIE fit, in CIE 1931 RGB",
         "bases: conductor under the ambient (no coat), with or without a thin film "
         "(transparent, index >= the ambient's); sides: R",
         belcour_barla_options, make_belcour_barla, false, "films",
         /*represents_anisotropy=*/false, /*films=*/true},
    });
    return entries;
}

const std::vector<std::string>& model_groups() {
    static const std::vector<std::string> groups = {"lamina",     "2019",  "successors",
                                                    "production", "films", "reference"};
    return groups;
}

const ModelEntry& find_model(const std::string& name, const std::string& field) {
    const auto& entries = model_registry();
    const auto it = std::find_if(entries.begin(), entries.end(),
                                 [&](const ModelEntry& e) { return e.name == name; });
    if (it != entries.end()) return *it;
    std::vector<std::string> names;
    for (const auto& e : entries)
        names.push_back(e.name);
    throw InputError(
        "command line", field,
        fmt::format("unknown model '{}'; known models: {}", name, fmt::join(names, ", ")));
}

void require_tabulable(const ModelEntry& entry, const std::string& file, const std::string& field) {
    if (!entry.stochastic) return;
    throw InputError(file, field,
                     fmt::format("{} is a stochastic estimator, which lamina does not tabulate: "
                                 "its table is the goniophotometer's (lamina simulate traces the "
                                 "same transport; export --simulation writes it); evaluate it at "
                                 "points or with --directions",
                                 entry.name));
}

ModelOptions resolve_options(const ModelEntry& entry, const std::vector<std::string>& assignments,
                             const std::string& field) {
    const std::vector<OptionSpec> specs = entry.options();
    ModelOptions out;
    for (const auto& s : specs)
        out[s.key] = s.default_value;
    std::map<std::string, std::string> given;  // key → the value first given
    for (const auto& a : assignments) {
        const auto eq = a.find('=');
        if (eq == std::string::npos || eq == 0)
            throw InputError("command line", field,
                             fmt::format("'{}' is not an assignment: expected KEY=VALUE", a));
        const std::string key = a.substr(0, eq), value = a.substr(eq + 1);
        const auto spec = std::find_if(specs.begin(), specs.end(),
                                       [&](const OptionSpec& s) { return s.key == key; });
        if (spec == specs.end()) {
            std::vector<std::string> keys;
            for (const auto& s : specs)
                keys.push_back(s.key);
            throw InputError("command line", field,
                             fmt::format("model '{}' has no option '{}'; its options: {}",
                                         entry.name, key, fmt::join(keys, ", ")));
        }
        if (std::find(spec->values.begin(), spec->values.end(), value) == spec->values.end())
            throw InputError("command line", field,
                             fmt::format("option '{}' of model '{}' cannot be '{}'; allowed: {}",
                                         key, entry.name, value, fmt::join(spec->values, ", ")));
        // A key given twice (in a spec and an --option, or two --option) has no one meaning.
        if (const auto [at, first] = given.emplace(key, value); !first)
            throw InputError("command line", field,
                             fmt::format("option '{}' of model '{}' given twice ({}, then {}); "
                                         "give it once",
                                         key, entry.name, at->second, value));
        out[key] = value;
    }
    return out;
}

ModelSpec parse_model_spec(const std::string& spec, const std::string& field) {
    ModelSpec out;
    std::size_t start = 0;
    std::vector<std::string> parts;
    while (true) {
        const std::size_t colon = spec.find(':', start);
        parts.push_back(spec.substr(start, colon - start));
        if (colon == std::string::npos) break;
        start = colon + 1;
    }
    out.entry = &find_model(parts.front(), field);
    out.assignments.assign(parts.begin() + 1, parts.end());
    resolve_options(*out.entry, out.assignments, field);  // validates
    return out;
}

std::vector<std::string> ablation_variants(const ModelEntry& entry) {
    std::vector<std::string> out;
    for (const OptionSpec& o : entry.options())
        for (const std::string& v : o.values)
            if (v != o.default_value) out.push_back(fmt::format("{}:{}={}", entry.name, o.key, v));
    return out;
}

std::unique_ptr<Model> make_model(const std::string& name, const Stack& stack,
                                  const std::vector<std::string>& assignments) {
    const ModelSpec spec = parse_model_spec(name);
    std::vector<std::string> all = spec.assignments;
    all.insert(all.end(), assignments.begin(), assignments.end());
    return spec.entry->make(stack, resolve_options(*spec.entry, all));
}

}  // namespace lamina
