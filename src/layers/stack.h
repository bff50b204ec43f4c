#pragma once
// A layer stack as data (docs/physics.md §2; docs/style.md §5). Every estimator — the
// goniophotometer, the analytic models, the random walk — reads this same description.
//
// From top to bottom: the ambient medium (index `ambient_eta`, default 1), then layers. A layer is
// an interface and, below it, an optional homogeneous medium whose refractive index is the `eta`
// of the interface above it. The last interface is the base: a dielectric base makes a slab (light
// leaving downwards is the BTDF, into a half-space of index eta), a conductor or Lambertian base is
// opaque. Opaque interfaces may only be last; the last layer has no medium.

#include "core/rgb.h"
#include "layers/spectrum.h"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

enum class InterfaceType { Dielectric, Conductor, Lambertian };

/// A thin film on a dielectric or conductor interface (docs/physics.md §9): a homogeneous layer of
/// absolute complex index eta + ik, thin enough for the waves inside it to add coherently, whose
/// thickness is thickness_nm, or uniformly distributed over [thickness_nm, thickness_max_nm] across
/// the surface when the two differ.
struct FilmSpec {
    double thickness_nm = 0.0;      ///< in [0, 10000]; the lower end of a range
    double thickness_max_nm = 0.0;  ///< ≥ thickness_nm; equal for one thickness
    double eta = 1.5;               ///< in [0.01, 5]
    double k = 0.0;                 ///< in [0, 10]
    bool varies() const { return thickness_max_nm > thickness_nm; }
    bool operator==(const FilmSpec&) const = default;
};

struct InterfaceSpec {
    InterfaceType type = InterfaceType::Dielectric;
    /// Dielectric: absolute index of what lies below (scalar: one path serves all channels).
    double eta = 1.5;
    /// Conductor: absolute complex index eta_rgb + i·k (RGB).
    Rgbd eta_rgb{1.0};
    Rgbd k{0.0};
    /// GGX roughness α ∈ {0} ∪ [1e-4, 1] of dielectric and conductor interfaces; 0 = smooth. An
    /// anisotropic interface's α_x, along its tangent.
    double alpha = 0.0;
    /// An anisotropic interface's α_y (along its bitangent), in [1e-4, 1] as α; −1: none, α_y = α
    /// (the stack file's `"alpha": [alpha_x, alpha_y]` sets both; docs/stack-format.md).
    double alpha_y = -1.0;
    /// The tangent's angle ψ from +x in degrees, [−360, 360] (`tangent_deg`): α_x lies along
    /// (cos ψ, sin ψ, 0), so that coat and base may be brushed in different directions.
    double tangent_deg = 0.0;
    /// Lambertian albedo ∈ [0, 1] (RGB).
    Rgbd albedo{0.0};
    /// A thin film on the interface (dielectric and conductor only).
    bool has_film = false;
    FilmSpec film;

    bool is_opaque() const { return type != InterfaceType::Dielectric; }
    /// α along the bitangent (α itself unless alpha_y is set).
    double alpha_b() const { return alpha_y < 0 ? alpha : alpha_y; }
    /// A rough dielectric or conductor with α_y ≠ α_x.
    bool is_anisotropic() const { return type != InterfaceType::Lambertian && alpha_b() != alpha; }
    /// Spectral values, where the stack file gives them (docs/stack-format.md, "Spectra"): a
    /// dielectric's eta, a conductor's eta and k, a Lambertian albedo. The RGB fields above then
    /// hold them at the stack's channel wavelengths (a dielectric's eta at the green channel's),
    /// which the RGB estimators read (Stack::at_wavelengths).
    std::optional<Spectrum> eta_spectrum, k_spectrum, albedo_spectrum;
    /// A conductor's named measured metal (data/nk), which sets eta_spectrum and k_spectrum.
    std::string material;
    bool is_spectral() const {
        return eta_spectrum.has_value() || k_spectrum.has_value() || albedo_spectrum.has_value();
    }
    bool operator==(const InterfaceSpec&) const = default;
};

/// A homogeneous medium described by its normal optical depths (docs/physics.md §4).
struct MediumSpec {
    Rgbd tau_a{0.0};  ///< absorption optical depth ≥ 0
    Rgbd tau_s{0.0};  ///< scattering optical depth ≥ 0
    Rgbd g{0.0};      ///< Henyey–Greenstein mean cosine, |g| < 1
    /// Spectral optical depths, where the stack file gives them (as InterfaceSpec's spectra).
    std::optional<Spectrum> tau_a_spectrum, tau_s_spectrum;

    Rgbd tau_t() const { return tau_a + tau_s; }
    bool scatters() const { return tau_s.max() > 0; }
    bool is_empty() const { return tau_a.max() == 0 && tau_s.max() == 0; }
    bool is_spectral() const { return tau_a_spectrum.has_value() || tau_s_spectrum.has_value(); }
    bool operator==(const MediumSpec&) const = default;
};

struct Layer {
    InterfaceSpec interface;
    bool has_medium = false;
    MediumSpec medium;
    bool operator==(const Layer&) const = default;
};

/// The vacuum wavelengths, in nm, at which the three RGB channels are traced where a wavelength
/// matters (thin films; docs/physics.md §9): red, green, blue.
inline constexpr Rgbd kDefaultChannelWavelengthsNm{630.0, 532.0, 465.0};

struct Stack {
    std::string name;
    double ambient_eta = 1.0;
    std::vector<Layer> layers;
    /// The channels' wavelengths in nm, each in [360, 830] (docs/physics.md §9).
    Rgbd wavelengths_nm = kDefaultChannelWavelengthsNm;

    /// Some interface is anisotropic (InterfaceSpec::is_anisotropic).
    bool is_anisotropic() const {
        for (const Layer& l : layers)
            if (l.interface.is_anisotropic()) return true;
        return false;
    }
    const InterfaceSpec& base() const { return layers.back().interface; }
    /// True when light can leave through the bottom (the base is a dielectric).
    bool transmits() const { return !base().is_opaque(); }
    /// Index of the medium just above layer i's interface.
    double eta_above(std::size_t i) const {
        return i == 0 ? ambient_eta : layers[i - 1].interface.eta;
    }
    /// Whether some interface carries a thin film.
    bool has_film() const {
        for (const Layer& l : layers)
            if (l.interface.has_film) return true;
        return false;
    }
    /// Some value is a spectrum (InterfaceSpec::is_spectral, MediumSpec::is_spectral): the
    /// goniophotometer traces it spectrally by default (docs/physics.md §10).
    bool is_spectral() const {
        for (const Layer& l : layers)
            if (l.interface.is_spectral() || (l.has_medium && l.medium.is_spectral())) return true;
        return false;
    }
    /// The stack at the vacuum wavelengths `wavelengths_nm` of its three channels: every RGB value
    /// given as a spectrum is that spectrum at the channel's wavelength, and a dielectric's eta
    /// (one refraction path serves all channels) the spectrum at channel `path_channel`'s. An RGB
    /// value given as numbers is the spectrum that takes the number of the channel whose
    /// wavelength (this stack's own) is nearest: channel c takes the number nearest its new
    /// wavelength, its own on a tie (docs/stack-format.md, "Spectra"). Called on a stack at its
    /// own channel wavelengths (as the reader leaves it): the result's numbers are read at the new
    /// wavelengths, so a second call would read them as that stack's own.
    Stack at_wavelengths(const Rgbd& wavelengths_nm, int path_channel) const;
    bool operator==(const Stack&) const = default;
};

/// Stacks built in code (the study's configurations, the tests): an interface of each type, a layer
/// of an interface, a medium under a layer. Nothing is range-checked here: stack_from_json checks
/// what a file holds.
inline InterfaceSpec dielectric_interface(double eta, double alpha) {
    InterfaceSpec s;
    s.type = InterfaceType::Dielectric;
    s.eta = eta;
    s.alpha = alpha;
    return s;
}
inline InterfaceSpec conductor_interface(const Rgbd& eta, const Rgbd& k, double alpha) {
    InterfaceSpec s;
    s.type = InterfaceType::Conductor;
    s.eta_rgb = eta;
    s.k = k;
    s.alpha = alpha;
    return s;
}
inline InterfaceSpec lambertian_interface(const Rgbd& albedo) {
    InterfaceSpec s;
    s.type = InterfaceType::Lambertian;
    s.albedo = albedo;
    return s;
}
/// An interface made anisotropic: α_x = alpha_x, α_y = alpha_y, its tangent at tangent_deg.
inline InterfaceSpec anisotropic(InterfaceSpec s, double alpha_x, double alpha_y,
                                 double tangent_deg = 0.0) {
    s.alpha = alpha_x;
    s.alpha_y = alpha_y;
    s.tangent_deg = tangent_deg;
    return s;
}
inline Layer layer_of(const InterfaceSpec& interface) {
    Layer l;
    l.interface = interface;
    return l;
}
inline Layer with_medium(Layer layer, const Rgbd& tau_a, const Rgbd& tau_s = Rgbd(0.0),
                         const Rgbd& g = Rgbd(0.0)) {
    layer.has_medium = true;
    layer.medium = MediumSpec{};
    layer.medium.tau_a = tau_a;
    layer.medium.tau_s = tau_s;
    layer.medium.g = g;
    return layer;
}

/// Parses and validates a stack from JSON (format: docs/stack-format.md). `where` names the source
/// (a file) in error messages; `name` defaults to its stem. Throws one InputError naming `where`,
/// the JSON pointer of the field, the value and what is allowed, for: unknown keys (with the
/// allowed keys and the closest one), missing required keys (`layers`, `interface`, `type`, and
/// every key of an interface type, `alpha` included), wrong types, RGB arrays of the wrong length,
/// NaN/inf, an RGB dielectric eta, any number outside its physical range (docs/stack-format.md,
/// "Ranges": dielectric and ambient eta in [1, 5]; conductor eta in [0.01, 10], k in [0, 10]; alpha
/// 0 or in [1e-4, 1]; tau_a in [0, 100], tau_s in [0, 1e4]; g in [-0.99, 0.99]; albedo in [0, 1]),
/// an unknown
/// interface type, an opaque interface that is not last, a medium under the last interface, an
/// empty or missing `layers` or more than 100 layers, an empty name. Every stack it returns lies
/// in those ranges: the estimators of lamina are written (and fuzzed, tests/fuzz) for them.
/// A dielectric or conductor may carry a `film` (thickness_nm a number or a range [min, max] in
/// [0, 10000], eta in [0.01, 5], k in [0, 10]; not in a stack with an anisotropic interface,
/// check_no_film_with_anisotropy); the stack may give `wavelengths_nm` [R, G, B],
/// each in [360, 830].
Stack stack_from_json(const nlohmann::json& j, const std::string& where);

/// A stack may not yet carry a thin film beside an anisotropic interface (neither the
/// goniophotometer nor a model traces both at once): InputError naming `where`, the first film's
/// pointer and the anisotropic interface's. stack_from_json refuses such a stack with it.
void check_no_film_with_anisotropy(const Stack& stack, const std::string& where);

/// Parses the text of a stack file (what load_stack reads); `where` names it in messages. The same
/// InputErrors as load_stack, also for JSON nested deeper than 32 levels.
Stack parse_stack(const std::string& text, const std::string& where);

/// The largest stack file load_stack reads (16 MiB; core/atomic_file.h, read_file_bounded).
inline constexpr std::size_t kMaxStackFileBytes = std::size_t(16) << 20;

/// Reads and parses a stack file. InputError also on a missing or unreadable file, one larger
/// than kMaxStackFileBytes (or without end, as /dev/zero), malformed JSON (with line and column),
/// duplicate keys, and numbers that overflow a double (1e999).
Stack load_stack(const std::filesystem::path& path);

/// The same stack seen from below (z flipped), for light that meets a transmitting stack from
/// its bottom side: the ambient index is the old η below the base, the interfaces come in reverse
/// order (each with the absolute index of what now lies below it, the old index above it, and the
/// same roughness and tangent: the flip is z → −z, which keeps every azimuth), and each medium
/// moves with the region it fills. Isotropic media (HG) and interfaces are unchanged by the flip.
/// Requires stack.transmits() (every interface a dielectric).
Stack flipped_stack(const Stack& stack);

/// Canonical JSON form (every RGB quantity as a 3-array); stack_from_json(stack_to_json(s)) == s.
/// The JSON of a lamina input file (a stack, a study's configurations), strictly: a duplicate key,
/// a NUL byte, nesting past 32 levels or a number beyond a double's range is an InputError
/// naming `where` and the place (a JSON pointer).
nlohmann::json parse_json_strict(const std::string& text, const std::string& where);
nlohmann::json stack_to_json(const Stack& stack);

/// One line describing the stack, e.g. `red plastic: air | dielectric η=1.5 α=0.05 | medium
/// τa=(0.1, 0, 0.9) | lambertian ρ=(0.8, 0.2, 0.1)`; scattering media add τs and g, a slab ends
/// with `(slab: transmits into η=…)`.
std::string describe(const Stack& stack);

}  // namespace lamina
