#include "study/configurations.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "layers/spectrum.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>
#include <sstream>

namespace lamina {

namespace {

std::string number_text(double v) {
    return fmt::format("{}", v);
}

// α1 in ids as in docs/study.md's example `paint-a0.001-a1.3`: "a1" followed by the value without
// its leading zero.
std::string alpha1_id(double v) {
    std::string s = number_text(v);
    return s.rfind("0.", 0) == 0 ? s.substr(1) : s;
}

// α, or "α_x×α_y" for an anisotropic interface.
std::string alpha_text(const InterfaceSpec& s) {
    return s.is_anisotropic() ? fmt::format("{}×{}", s.alpha, s.alpha_b()) : number_text(s.alpha);
}

std::string rgb_text(const Rgbd& v) {
    if (v[0] == v[1] && v[1] == v[2]) return number_text(v[0]);
    return fmt::format("({}, {}, {})", v[0], v[1], v[2]);
}

Layer coat(double alpha0, const Rgbd& tau_a) {
    Layer l;
    l.interface.type = InterfaceType::Dielectric;
    l.interface.eta = 1.5;  // docs/study.md: η0 = 1.5 throughout
    l.interface.alpha = alpha0;
    l.has_medium = true;
    l.medium.tau_a = tau_a;
    return l;
}

Layer lambertian(const Rgbd& rho) {
    return layer_of(lambertian_interface(rho));
}

Layer conductor(const Rgbd& eta, const Rgbd& k, double alpha) {
    return layer_of(conductor_interface(eta, k, alpha));
}

Layer dielectric(double eta, double alpha) {
    return layer_of(dielectric_interface(eta, alpha));
}

StudyConfiguration make(std::string id, std::string category, std::vector<Layer> layers) {
    StudyConfiguration c;
    c.id = std::move(id);
    c.category = std::move(category);
    c.stack = Stack{c.id, 1.0, std::move(layers)};
    c.parameters = describe_parameters(c.stack);
    return c;
}

bool glob_match(const char* p, const char* s) {
    if (*p == '\0') return *s == '\0';
    if (*p == '*') return glob_match(p + 1, s) || (*s != '\0' && glob_match(p, s + 1));
    if (*s != '\0' && (*p == '?' || *p == *s)) return glob_match(p + 1, s + 1);
    return false;
}

}  // namespace

std::map<std::string, std::string> describe_parameters(const Stack& stack) {
    std::map<std::string, std::string> p;
    if (stack.layers.empty()) return p;
    const Layer& top = stack.layers.front();
    if (top.interface.type == InterfaceType::Dielectric) {
        p["eta0"] = number_text(top.interface.eta);
        p["alpha0"] = alpha_text(top.interface);
        if (top.interface.is_anisotropic()) p["tangent0"] = number_text(top.interface.tangent_deg);
        p["tau"] = rgb_text(top.has_medium ? top.medium.tau_a : Rgbd(0.0));
        if (top.has_medium && top.medium.scatters()) p["tau_s"] = rgb_text(top.medium.tau_s);
    }
    // More than a coat over a base: the parameters above describe the top and the base only,
    // and the count says so (the explorer's single-coat live model is then not offered).
    if (stack.layers.size() > 2) p["layers"] = number_text(double(stack.layers.size()));
    if (stack.layers.size() >= 2) {
        const InterfaceSpec& base = stack.base();
        if (base.has_film) {
            const FilmSpec& f = base.film;
            p["film_nm"] = f.varies() ? fmt::format("[{}, {}]", f.thickness_nm, f.thickness_max_nm)
                                      : number_text(f.thickness_nm);
            p["film_eta"] = f.k > 0 ? fmt::format("{} + {}i", f.eta, f.k) : number_text(f.eta);
        }
        switch (base.type) {
            case InterfaceType::Lambertian:
                p["base"] = "lambertian";
                p["rho"] = rgb_text(base.albedo);
                break;
            case InterfaceType::Conductor:
                p["base"] = "conductor";
                p["alpha1"] = alpha_text(base);
                if (base.is_anisotropic()) p["tangent1"] = number_text(base.tangent_deg);
                if (!base.material.empty()) {
                    // A measured metal's index is its spectrum: the widgets show its name.
                    p["metal"] = base.material;
                    p["eta1"] = p["kappa1"] = base.material + " (measured)";
                } else {
                    p["eta1"] = rgb_text(base.eta_rgb);
                    p["kappa1"] = rgb_text(base.k);
                }
                break;
            case InterfaceType::Dielectric:
                p["base"] = "dielectric";
                p["alpha1"] = alpha_text(base);
                if (base.is_anisotropic()) p["tangent1"] = number_text(base.tangent_deg);
                p["eta1"] = number_text(base.eta);
                break;
        }
    }
    return p;
}

std::vector<StudyConfiguration> builtin_configurations() {
    std::vector<StudyConfiguration> out;
    const std::vector<double> alpha0_plastic = {0.001, 0.05, 0.1, 0.3, 0.5};
    // Plastics: α0 × (τa, ρ) pairs P1–P4.
    struct PlasticPair {
        const char* id;
        Rgbd tau, rho;
    };
    const PlasticPair pairs[] = {{"P1", Rgbd(0.0), Rgbd(0.8)},
                                 {"P2", Rgbd(0.0), Rgbd(0.8, 0.2, 0.1)},
                                 {"P3", Rgbd(0.1, 0.0, 0.9), Rgbd(0.8)},
                                 {"P4", Rgbd(0.1, 0.0, 0.9), Rgbd(0.1, 0.0, 0.0)}};
    for (const PlasticPair& pair : pairs)
        for (double a0 : alpha0_plastic)
            out.push_back(make(fmt::format("plastic-{}-a{}", pair.id, a0), "plastic",
                               {coat(a0, pair.tau), lambertian(pair.rho)}));
    // Metallic paints: τa = 0.1, conductor η1 = 1.45, κ1 = (1.0, 0.01, 0.01), rougher than the
    // coat.
    for (double a0 : {0.001, 0.05})
        for (double a1 : {0.1, 0.2, 0.3, 0.4, 0.5})
            out.push_back(
                make(fmt::format("paint-a{}-a1{}", a0, alpha1_id(a1)), "metallic-paint",
                     {coat(a0, Rgbd(0.1)), conductor(Rgbd(1.45), Rgbd(1.0, 0.01, 0.01), a1)}));
    // Frosted metals: τa = 0, gold, smoother than the coat.
    const Rgbd gold_eta(0.143, 0.374, 1.442), gold_k(3.983, 2.385, 1.603);
    for (double a0 : {0.1, 0.2, 0.3, 0.4, 0.5})
        for (double a1 : {0.001, 0.05})
            out.push_back(make(fmt::format("frosted-a{}-a1{}", a0, alpha1_id(a1)), "frosted-metal",
                               {coat(a0, Rgbd(0.0)), conductor(gold_eta, gold_k, a1)}));
    // Slabs: back to air (η1 = 1), BRDF and BTDF.
    for (double a0 : alpha0_plastic)
        for (double a1 : {0.001, 0.3})
            for (int t = 0; t < 2; ++t)
                out.push_back(make(
                    fmt::format("slab-a{}-a1{}-{}", a0, alpha1_id(a1), t == 0 ? "clear" : "tinted"),
                    "slab",
                    {coat(a0, t == 0 ? Rgbd(0.0) : Rgbd(0.1, 0.0, 0.9)), dielectric(1.0, a1)}));
    return out;
}

std::vector<StudyConfiguration> iridescent_configurations(bool quick_only) {
    // The metals are the measured ones (data/nk): an interference colour is a spectral quantity,
    // so the reference traces these stacks over wavelengths and the models are compared by their
    // colour (docs/study.md, "The iridescent category").
    struct Iridescent {
        const char* id;
        double alpha0;
        const char* metal;
        double alpha1, film_eta, film_k, min_nm, max_nm;
        bool quick;  // in the quick preset: the category's three cases the others vary
    };
    const Iridescent list[] = {
        // Anodized titanium: a 60 nm oxide of index 2.5, first-order interference, glossy and
        // rough.
        {"irid-ti-oxide-a0.05-a1.05", 0.05, "Ti", 0.05, 2.5, 0.0, 60, 60, false},
        {"irid-ti-oxide-a0.05-a1.3", 0.05, "Ti", 0.3, 2.5, 0.0, 60, 60, true},
        // An interference pigment: 300 nm of index 1.8 on gold (higher orders), under a rough
        // coat.
        {"irid-gold-film-a0.3-a1.05", 0.3, "Au", 0.05, 1.8, 0.0, 300, 300, true},
        // A protected mirror: MgF2 a quarter wave thick at 532 nm on aluminium, smooth coat.
        {"irid-al-mgf2-a0.001-a1.2", 0.001, "Al", 0.2, 1.38, 0.0, 96.4, 96.4, false},
        // A film whose thickness varies over the surface (200–600 nm of 1.5) on copper.
        {"irid-cu-range-a0.1-a1.1", 0.1, "Cu", 0.1, 1.5, 0.0, 200, 600, false},
        // Temper colours: an absorbing 80 nm oxide (2.3 + 0.1i) on iron.
        {"irid-fe-temper-a0.05-a1.1", 0.05, "Fe", 0.1, 2.3, 0.1, 80, 80, true},
    };
    std::vector<StudyConfiguration> out;
    for (const Iridescent& c : list) {
        if (quick_only && !c.quick) continue;
        Layer metal = conductor(Rgbd(1.0), Rgbd(1.0), c.alpha1);
        metal.interface.material = c.metal;
        metal.interface.eta_spectrum = conductor_material_eta(c.metal);
        metal.interface.k_spectrum = conductor_material_k(c.metal);
        metal.interface.has_film = true;
        metal.interface.film = {c.min_nm, c.max_nm, c.film_eta, c.film_k};
        StudyConfiguration config = make(c.id, "iridescent", {coat(c.alpha0, Rgbd(0.0)), metal});
        // The RGB values at the channels' wavelengths, as the stack reader sets them.
        config.stack = config.stack.at_wavelengths(config.stack.wavelengths_nm, 1);
        config.parameters = describe_parameters(config.stack);
        out.push_back(std::move(config));
    }
    return out;
}

std::vector<StudyConfiguration> brushed_configurations() {
    // The metals at the channels' wavelengths (630, 532, 465 nm; rounded from the
    // handbooks' tables); steel as iron.
    const Rgbd al_eta(1.2, 0.96, 0.65), al_k(7.3, 6.4, 5.4);
    const Rgbd fe_eta(2.87, 2.95, 2.65), fe_k(3.08, 2.93, 2.81);
    const Rgbd gold_eta(0.143, 0.374, 1.442), gold_k(3.983, 2.385, 1.603);  // the frosted metals'
    struct Brushed {
        const char* id;
        double alpha0x, alpha0y, coat_tangent;  // the coat (α0x = α0y: isotropic)
        Rgbd eta, k;
        double alpha1x, alpha1y, base_tangent;  // the brushed metal: α1x along its tangent
    };
    const Brushed list[] = {
        // Under a smooth clear coat (α0 = 0.001): the metal's lobe, stretched across the
        // brushing, seen through one smooth refraction; brushed along x, and at 30° to it (lit
        // from 0°, 45° and 90°: 30°, 15° and 60° from the brushing, no two alike).
        {"brushed-al-a0.001-a1.05x.3", 0.001, 0.001, 0, al_eta, al_k, 0.05, 0.3, 0},
        {"brushed-steel-a0.001-a1.1x.5", 0.001, 0.001, 0, fe_eta, fe_k, 0.1, 0.5, 0},
        {"brushed-gold-a0.001-a1.05x.3-t30", 0.001, 0.001, 0, gold_eta, gold_k, 0.05, 0.3, 30},
        // Under a rough isotropic coat (α0 = 0.2): the coat's spread over the anisotropic lobe.
        {"brushed-al-a0.2-a1.05x.3", 0.2, 0.2, 0, al_eta, al_k, 0.05, 0.3, 0},
        {"brushed-steel-a0.2-a1.1x.5-t30", 0.2, 0.2, 0, fe_eta, fe_k, 0.1, 0.5, 30},
        // A brushed lacquer (α0 = 0.05 × 0.2, its tangent along x) over brushed aluminium: the
        // tangents aligned, at 45° and crossed (90°).
        {"brushed-al-a0.05x.2-a1.05x.3-t0", 0.05, 0.2, 0, al_eta, al_k, 0.05, 0.3, 0},
        {"brushed-al-a0.05x.2-a1.05x.3-t45", 0.05, 0.2, 0, al_eta, al_k, 0.05, 0.3, 45},
        {"brushed-al-a0.05x.2-a1.05x.3-t90", 0.05, 0.2, 0, al_eta, al_k, 0.05, 0.3, 90},
    };
    std::vector<StudyConfiguration> out;
    for (const Brushed& b : list) {
        Layer top = coat(b.alpha0x, Rgbd(0.0));
        if (b.alpha0y != b.alpha0x)
            top.interface = anisotropic(top.interface, b.alpha0x, b.alpha0y, b.coat_tangent);
        Layer metal = conductor(b.eta, b.k, b.alpha1x);
        metal.interface = anisotropic(metal.interface, b.alpha1x, b.alpha1y, b.base_tangent);
        out.push_back(make(b.id, "brushed", {top, metal}));
    }
    return out;
}

std::vector<StudyConfiguration> dispersive_configurations() {
    // A dense flint (the catalogue's SF11: n_d = 1.78472, V_d = 25.68, Schott; rounded), whose
    // index falls from about 1.84 at 400 nm to 1.77 at 700 nm, as the two-term Cauchy formula
    // through n_d with that Abbe number: the slab category's shape (a glass over air, reflection
    // and transmission), with the index a spectrum. Read through the stack reader, so that the
    // stack is the one a file with these lines gives.
    struct Dispersive {
        const char* id;
        double alpha0, alpha1;
    };
    const Dispersive list[] = {
        // Smooth faces: the transmitted lobe is narrow, and its direction depends on the
        // wavelength (a prism's colour fringes, blurred by the exit's roughness).
        {"disp-flint-a0.001-a1.05", 0.001, 0.05},
        // Rough faces: the colours mix over broad lobes; what is left is the index's spectrum
        // in the Fresnel factors and the total internal reflection's cone.
        {"disp-flint-a0.1-a1.3", 0.1, 0.3},
    };
    std::vector<StudyConfiguration> out;
    for (const Dispersive& d : list) {
        const nlohmann::json stack = {
            {"name", d.id},
            {"layers",
             {{{"interface",
                {{"type", "dielectric"}, {"eta", {{"abbe", {1.785, 25.7}}}}, {"alpha", d.alpha0}}},
               {"medium", {{"tau_a", 0}}}},
              {{"interface", {{"type", "dielectric"}, {"eta", 1.0}, {"alpha", d.alpha1}}}}}}};
        StudyConfiguration config;
        config.id = d.id;
        config.category = "dispersive";
        config.stack = stack_from_json(stack, d.id);
        config.parameters = describe_parameters(config.stack);
        config.parameters["eta0"] = "flint (n_d 1.785, V_d 25.7)";
        out.push_back(std::move(config));
    }
    return out;
}

std::vector<StudyConfiguration> preset_configurations(const std::string& preset) {
    std::vector<StudyConfiguration> out = builtin_configurations();
    for (StudyConfiguration& c : iridescent_configurations(preset == "quick"))
        out.push_back(std::move(c));
    if (preset != "quick") {
        for (StudyConfiguration& c : brushed_configurations())
            out.push_back(std::move(c));
        for (StudyConfiguration& c : dispersive_configurations())
            out.push_back(std::move(c));
    }
    return out;
}

namespace {
// C0 controls, DEL, and the C1 controls U+0080–U+009F (UTF-8: 0xC2 then 0x80–0x9F).
bool has_control_character(const std::string& text) {
    for (std::size_t i = 0; i < text.size(); ++i) {
        const auto ch = static_cast<unsigned char>(text[i]);
        if (ch < 0x20 || ch == 0x7f) return true;
        if (ch == 0xc2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
            static_cast<unsigned char>(text[i + 1]) <= 0x9f)
            return true;
    }
    return false;
}

// An id or label names files and folders (configs/<id>/, figures/albedo-<category>.png,
// renders/<model>.png): a file name holds 255 bytes.
constexpr std::size_t kMaxNameBytes = 128;
}  // namespace

std::string configuration_id_key(const std::string& id) {
    std::string key = id;
    for (char& ch : key)
        if (ch >= 'A' && ch <= 'Z') ch = char(ch - 'A' + 'a');
    return key;
}

void check_configuration_id(const std::string& id, const std::string& where,
                            const std::string& field) {
    if (id.size() > kMaxNameBytes)
        throw InputError(where, field,
                         fmt::format("'{}…' is {} bytes long; allowed: at most {} (it names the "
                                     "configuration's folder and cache files)",
                                     id.substr(0, 40), id.size(), kMaxNameBytes));
    if (id.empty() || id.find_first_of("/\\ ,\"") != std::string::npos ||
        has_control_character(id) || id[0] == '.')
        throw InputError(where, field,
                         fmt::format("'{}' is not usable as an id (no spaces, slashes, commas, "
                                     "quotes, control characters or leading dot)",
                                     id));
    // The explorer's own data file is explorer/data/index.js beside each configuration's <id>.js.
    if (configuration_id_key(id) == "index")
        throw InputError(
            where, field,
            fmt::format("'{}' is reserved (the explorer's index); choose another id", id));
}

void check_study_label(const std::string& label, const char* what, const std::string& where,
                       const std::string& field) {
    if (label.size() > kMaxNameBytes)
        throw InputError(where, field,
                         fmt::format("'{}…' is {} bytes long; allowed: at most {} (it names "
                                     "files: figures, renderings)",
                                     label.substr(0, 40), label.size(), kMaxNameBytes));
    if (label.find_first_not_of(' ') == std::string::npos ||
        label.find_first_of(",\"/\\") != std::string::npos || has_control_character(label) ||
        label[0] == '.')
        throw InputError(where, field,
                         fmt::format("'{}' is not usable as a {} (not blank; no commas, quotes, "
                                     "slashes, control characters or leading dot: it names "
                                     "files)",
                                     label, what));
}

std::vector<StudyConfiguration> load_configurations(const std::filesystem::path& path) {
    const std::string where = path.string();
    const nlohmann::json j = parse_json_strict(
        read_file_bounded(path, kMaxConfigurationsFileBytes, "the configurations file"), where);
    if (!j.is_object() || !j.contains("configurations") || !j["configurations"].is_array())
        throw InputError(where, "/configurations",
                         "expected {\"configurations\": [{\"id\": ..., \"stack\": {...}}, ...]}");
    for (const auto& [key, value] : j.items())
        if (key != "configurations")
            throw InputError(where, "/" + key, "unknown key; allowed: configurations");
    std::vector<StudyConfiguration> out;
    std::set<std::string> ids;
    std::map<std::string, std::string> categories;  // in lower case → as first written
    const auto& list = j["configurations"];
    if (list.empty()) throw InputError(where, "/configurations", "the list is empty");
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string at = fmt::format("/configurations/{}", i);
        const auto& item = list[i];
        if (!item.is_object()) throw InputError(where, at, "expected an object");
        for (const auto& [key, value] : item.items())
            if (key != "id" && key != "category" && key != "stack")
                throw InputError(where, at + "/" + key,
                                 "unknown key; allowed: id, category, stack");
        if (!item.contains("id") || !item["id"].is_string())
            throw InputError(where, at + "/id", "a string id is required");
        StudyConfiguration c;
        c.id = item["id"].get<std::string>();
        check_configuration_id(c.id, where, at + "/id");
        if (!ids.insert(configuration_id_key(c.id)).second)
            throw InputError(where, at + "/id", fmt::format("'{}' {}", c.id, kIdTwice));
        c.category = "custom";
        if (item.contains("category")) {
            if (!item["category"].is_string())
                throw InputError(where, at + "/category", "must be a string");
            c.category = item["category"].get<std::string>();
            check_study_label(c.category, "category", where, at + "/category");
            // The summary's groups are the categories, "CATEGORY BTDF" and "all", "all BTDF"; a
            // category's figure is albedo-CATEGORY.png, one name in a case-blind file system.
            const std::string key = configuration_id_key(c.category);
            if (key == "all" || (key.size() >= 5 && key.compare(key.size() - 5, 5, " btdf") == 0))
                throw InputError(where, at + "/category",
                                 fmt::format("'{}' is one of the summary's group names; allowed: "
                                             "a category other than 'all' and not ending in "
                                             "' BTDF'",
                                             c.category));
            if (const auto seen = categories.emplace(key, c.category);
                !seen.second && seen.first->second != c.category)
                throw InputError(where, at + "/category",
                                 fmt::format("'{}' differs from the category '{}' in case only",
                                             c.category, seen.first->second));
        }
        if (!item.contains("stack")) throw InputError(where, at + "/stack", "a stack is required");
        try {
            c.stack = stack_from_json(item["stack"], where);
        } catch (const InputError& e) {
            // Re-anchor the stack's JSON pointer inside the configurations file.
            throw InputError(where, at + "/stack" + e.field(), e.problem());
        }
        c.parameters = describe_parameters(c.stack);
        out.push_back(std::move(c));
    }
    return out;
}

std::vector<StudyConfiguration> filter_configurations(std::vector<StudyConfiguration> configs,
                                                      const std::string& pattern) {
    if (pattern.empty()) return configs;
    std::vector<std::string> patterns;
    std::stringstream ss(pattern);
    for (std::string p; std::getline(ss, p, ',');)
        if (!p.empty()) patterns.push_back(p);
    std::vector<StudyConfiguration> out;
    for (auto& c : configs)
        for (const auto& p : patterns)
            if (glob_match(p.c_str(), c.id.c_str())) {
                out.push_back(std::move(c));
                break;
            }
    if (out.empty())
        throw InputError("command line", "--only",
                         fmt::format("'{}' matches no configuration (ids look like "
                                     "plastic-P1-a0.05, paint-a0.001-a1.3, frosted-a0.1-a1.05, "
                                     "slab-a0.1-a1.3-clear; * and ? are wildcards)",
                                     pattern));
    return out;
}

}  // namespace lamina
