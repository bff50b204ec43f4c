#include "layers/compiled_stack.h"

#include "core/math.h"

namespace lamina {

FilmOptics stack_film_optics(const Stack& stack, std::size_t layer) {
    const InterfaceSpec& spec = stack.layers[layer].interface;
    FilmOptics f;
    f.eta_film = {spec.film.eta, spec.film.k};
    f.eta_above = stack.eta_above(layer);
    for (int c = 0; c < 3; ++c) {
        f.eta_below[c] = spec.type == InterfaceType::Conductor
                             ? std::complex<double>(spec.eta_rgb[c], spec.k[c])
                             : std::complex<double>(spec.eta);
        f.wavelength_nm[c] = stack.wavelengths_nm[c];
    }
    f.thickness_min_nm = spec.film.thickness_nm;
    f.thickness_max_nm = spec.film.thickness_max_nm;
    return f;
}

template <typename Real>
CompiledStack<Real> compile_stack(const Stack& stack, const TransportSettings& settings) {
    CompiledStack<Real> out;
    out.eta_above = Real(stack.ambient_eta);
    out.transmits = stack.transmits();
    const bool multiple = settings.microsurface == Microsurface::Multiple;
    out.multiple_scattering = multiple;
    out.max_microsurface_order = settings.max_microsurface_order;
    out.polarization = settings.polarization;
    for (std::size_t i = 0; i < stack.layers.size(); ++i) {
        const Layer& layer = stack.layers[i];
        const InterfaceSpec& spec = layer.interface;
        // Relative indices against the medium above (docs/physics.md §2), formed in double.
        const double eta_above = stack.eta_above(i);
        CompiledLayer<Real> t;
        t.type = spec.type;
        // α_y and the tangent (physics/microfacet.h); `on` only where α_y ≠ α_x in Real.
        const GgxAnisotropy<Real> anisotropy = GgxAnisotropy<Real>::make(
            Real(spec.alpha), Real(spec.alpha_b()), deg_to_rad(spec.tangent_deg));
        switch (spec.type) {
            case InterfaceType::Dielectric:
                t.dielectric = {Real(spec.eta / eta_above), Real(spec.alpha)};
                t.dielectric.transmission_masking = settings.transmission_masking;
                t.dielectric.anisotropy = anisotropy;
                // An index-matched interface is a pass-through, unless a film sits on it (a
                // free-standing film: air | film | air).
                if (multiple && t.dielectric.is_index_matched() && !spec.has_film)
                    t.dielectric.alpha = Real(0);
                t.delta =
                    t.dielectric.is_smooth() || (t.dielectric.is_index_matched() && !spec.has_film);
                t.multiple = multiple && !t.delta;
                t.eta_below = Real(spec.eta);
                break;
            case InterfaceType::Conductor:
                t.conductor = {Rgb<Real>(spec.eta_rgb / eta_above), Rgb<Real>(spec.k / eta_above),
                               Real(spec.alpha)};
                t.conductor.anisotropy = anisotropy;
                t.delta = t.conductor.is_smooth();
                t.multiple = multiple && !t.delta;
                if (!t.conductor.is_grey()) out.polarization_channels = 3;
                t.eta_below = Real(eta_above);  // no region below an opaque base
                break;
            case InterfaceType::Lambertian:
                t.lambertian = {Rgb<Real>(spec.albedo)};
                t.eta_below = Real(eta_above);
                break;
        }
        if (spec.has_film) {
            t.has_film = out.has_film = true;
            out.polarization_channels = 3;
            t.film = stack_film_optics(stack, i);
        }
        if (layer.has_medium) {
            const MediumSpec& m = layer.medium;
            CompiledMedium<Real>& md = t.medium;
            md.tau_a = Rgb<Real>(m.tau_a);
            md.tau_s = Rgb<Real>(m.tau_s);
            md.tau_t = Rgb<Real>(m.tau_t());
            md.g = Rgb<Real>(m.g);
            md.absorbs = m.tau_a.max() > 0;
            md.scatters = m.tau_s.max() > 0;
            md.uniform_g = m.g[0] == m.g[1] && m.g[1] == m.g[2];
            md.uniform_tau_t = md.tau_t[0] == md.tau_t[1] && md.tau_t[1] == md.tau_t[2];
            for (int c = 0; c < 3; ++c)
                md.single_scattering_albedo[c] =
                    md.tau_t[c] > 0 ? Real(m.tau_s[c] / m.tau_t()[c]) : Real(0);
        }
        if (anisotropy.on && spec.type != InterfaceType::Lambertian && spec.alpha > 0)
            out.anisotropic = true;
        out.layers.push_back(t);
    }
    return out;
}

template CompiledStack<float> compile_stack<float>(const Stack&, const TransportSettings&);
template CompiledStack<double> compile_stack<double>(const Stack&, const TransportSettings&);

}  // namespace lamina
