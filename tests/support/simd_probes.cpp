// Probes of the SIMD lanes (simd_probes.h): each loads plain arrays into the dispatched
// instruction set's vectors, runs one piece of the kernel's lane code on them and stores the
// lanes back. Compiled as the SIMD kernel is (simulator/kernel_simd.cpp: once per instruction set,
// the same lane headers), into a library of the tests only.

#include "support/simd_probes.h"

#include "physics/thin_film.h"
#include "simulator/kernel_simd.h"

#include <algorithm>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "support/simd_probes.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#define LAMINA_LANE_TARGET
#include "core/lane_hwy.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/lambertian.h"
#include "physics/medium.h"
#include "physics/microfacet.h"
#include "physics/microsurface_walk.h"
#include "physics/phase.h"
#include "physics/polarization.h"
#include "simulator/lane_bins.h"
#include "simulator/lane_conductor.h"
#include "simulator/lane_film.h"
#include "simulator/lane_rng.h"
#undef LAMINA_LANE_TARGET

HWY_BEFORE_NAMESPACE();
namespace lamina {
namespace HWY_NAMESPACE {

std::uint32_t PcgDrawsForTest(std::uint64_t seed, std::uint64_t stream, std::uint64_t first,
                              std::uint64_t n_particles, std::uint64_t n_draws, float* out) {
    const std::size_t n_lanes = hn::Lanes(DF());
    std::vector<std::uint64_t> state(n_particles), inc(n_particles);
    SeedParticles(seed, stream, first, n_particles, state.data(), inc.data());
    for (std::uint64_t base = 0; base < n_particles; base += n_lanes) {
        LaneRng rng;
        for (std::size_t l = 0; l < n_lanes; ++l) {
            rng.state[l] = base + l < n_particles ? state[base + l] : 0;
            rng.inc[l] = base + l < n_particles ? inc[base + l] : 1;
        }
        rng.SyncIn();
        for (std::uint64_t i = 0; i < n_draws; ++i) {
            HWY_ALIGN float u[kMaxLanes];
            hn::Store(rng.Uniform(), DF(), u);
            for (std::size_t l = 0; l < n_lanes && base + l < n_particles; ++l)
                out[(base + l) * n_draws + i] = u[l];
        }
    }
    return std::uint32_t(n_lanes);
}

void InvSqrtForTest(const float* x, std::size_t n, float* out) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in[kMaxLanes], y[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l)
            in[l] = base + l < n ? x[base + l] : 1.f;
        hn::Store(VecLane::inv_sqrt(hn::Load(df, in)), df, y);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l)
            out[base + l] = y[l];
    }
}

void CosSin2PiForTest(const float* u, std::size_t n, float* c, float* s) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in[kMaxLanes], out_c[kMaxLanes], out_s[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l)
            in[l] = base + l < n ? u[base + l] : 0.f;
        VF vc, vs;
        CosSin2Pi(hn::Load(df, in), vc, vs);
        hn::Store(vc, df, out_c);
        hn::Store(vs, df, out_s);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l) {
            c[base + l] = out_c[l];
            s[base + l] = out_s[l];
        }
    }
}

void SmithRefractionEscapeForTest(const float* r_i, const float* r_o, std::size_t n, float* out) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in_i[kMaxLanes], in_o[kMaxLanes], res[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l) {
            in_i[l] = base + l < n ? r_i[base + l] : 1.f;
            in_o[l] = base + l < n ? r_o[base + l] : 1.f;
        }
        hn::Store(smith_refraction_escape<VF, VecLane>(hn::Load(df, in_i), hn::Load(df, in_o)), df,
                  res);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l)
            out[base + l] = res[l];
    }
}

void LaneBinsForTest(const HemisphereGrid& grid, const float* d, std::size_t n,
                     std::int64_t* bins) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    const VectorBins g(grid);
    HWY_ALIGN float in[3][kMaxLanes];
    HWY_ALIGN std::int32_t theta_bin[kMaxLanes], phi_bin[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l)
            for (int i = 0; i < 3; ++i)
                in[i][l] = base + l < n ? d[3 * (base + l) + i] : (i == 2 ? 1.f : 0.f);
        const std::uint64_t known =
            LaneBins(g, V3{hn::Load(df, in[0]), hn::Load(df, in[1]), hn::Load(df, in[2])},
                     theta_bin, phi_bin);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l)
            bins[base + l] =
                (known >> l & 1) != 0 ? std::int64_t(theta_bin[l]) * g.n_phi + phi_bin[l] : -1;
    }
}

void FresnelDielectricForTest(const float* cos_theta, std::size_t n, float eta, float* reflectance,
                              float* cos_theta_t) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in[kMaxLanes], r[kMaxLanes], t[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l)
            in[l] = base + l < n ? cos_theta[base + l] : 1.f;
        const FresnelDielectric<VF> fr = fresnel_dielectric_full<VF, VecLane>(
            hn::Load(df, in), hn::Set(df, eta), hn::Set(df, 1.f / eta));
        hn::Store(fr.reflectance, df, r);
        hn::Store(fr.cos_theta_t, df, t);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l) {
            reflectance[base + l] = r[l];
            cos_theta_t[base + l] = t[l];
        }
    }
}

void FresnelConductorForTest(const float* cos_theta, std::size_t n, float eta, float k,
                             float* reflectance) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in[kMaxLanes], r[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l)
            in[l] = base + l < n ? cos_theta[base + l] : 1.f;
        hn::Store(FresnelConductor(hn::Load(df, in), eta, k), df, r);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l)
            reflectance[base + l] = r[l];
    }
}

// Per entry j: tau[j] the same in all three channels of lane j (the probe varies it per lane).
void BeerLambertLanesForTest(const float* tau, const float* inv_mu, std::size_t n, float* out) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float t[kMaxLanes], m[kMaxLanes], r[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l) {
            t[l] = base + l < n ? tau[base + l] : 0.f;
            m[l] = base + l < n ? inv_mu[base + l] : 1.f;
        }
        const VF tau_v = hn::Load(df, t);
        const VF taus[3] = {tau_v, tau_v, tau_v};
        VF transmittance[3];
        beer_lambert_transmittance_lanes<VF, VecLane>(taus, hn::Load(df, m), transmittance);
        hn::Store(transmittance[1], df, r);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l)
            out[base + l] = r[l];
    }
}

void HenyeyGreensteinForTest(const float* g, const float* x, std::size_t n, float* phase,
                             float* cos_theta) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in_g[kMaxLanes], in_x[kMaxLanes], p[kMaxLanes], c[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l) {
            in_g[l] = base + l < n ? g[base + l] : 0.f;
            in_x[l] = base + l < n ? x[base + l] : 0.f;
        }
        const VF vg = hn::Load(df, in_g), vx = hn::Load(df, in_x);
        hn::Store(hg_phase<VF, VecLane>(vx, vg), df, p);
        hn::Store(sample_hg_cos_theta<VF, VecLane>(vg, vx), df, c);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l) {
            phase[base + l] = p[l];
            cos_theta[base + l] = c[l];
        }
    }
}

// The probes' lanes: entry j of the inputs is lane j (vectors of lanes at `base`, n entries in
// all, the tail padded), the outputs as simd_probes.h describes them.
struct LaneIo {
    const DF df;
    std::size_t base = 0, n = 0;
    HWY_INLINE VF Load(const float* x, float pad) const {
        HWY_ALIGN float buf[kMaxLanes];
        for (std::size_t l = 0; l < hn::Lanes(df); ++l)
            buf[l] = base + l < n ? x[base + l] : pad;
        return hn::Load(df, buf);
    }
    HWY_INLINE V3 Load3(const float* x) const {
        HWY_ALIGN float buf[3][kMaxLanes];
        for (std::size_t l = 0; l < hn::Lanes(df); ++l)
            for (int i = 0; i < 3; ++i)
                buf[i][l] = base + l < n ? x[3 * (base + l) + i] : (i == 2 ? 1.f : 0.f);
        return {hn::Load(df, buf[0]), hn::Load(df, buf[1]), hn::Load(df, buf[2])};
    }
    HWY_INLINE void Store(VF v, float* x) const {
        HWY_ALIGN float buf[kMaxLanes];
        hn::Store(v, df, buf);
        for (std::size_t l = 0; l < hn::Lanes(df) && base + l < n; ++l)
            x[base + l] = buf[l];
    }
    HWY_INLINE void Store3(const V3& v, float* x) const {
        HWY_ALIGN float buf[3][kMaxLanes];
        hn::Store(v.x, df, buf[0]);
        hn::Store(v.y, df, buf[1]);
        hn::Store(v.z, df, buf[2]);
        for (std::size_t l = 0; l < hn::Lanes(df) && base + l < n; ++l)
            for (int i = 0; i < 3; ++i)
                x[3 * (base + l) + i] = buf[i][l];
    }
    HWY_INLINE void StoreMask(MF m, std::int32_t* x) const {
        const DI di;
        HWY_ALIGN std::int32_t buf[kMaxLanes];
        hn::Store(hn::IfThenElseZero(hn::RebindMask(di, m), hn::Set(di, 1)), di, buf);
        for (std::size_t l = 0; l < hn::Lanes(df) && base + l < n; ++l)
            x[base + l] = buf[l];
    }
    HWY_INLINE MF Active() const { return hn::FirstN(df, std::min(hn::Lanes(df), n - base)); }
};

void InterfaceEventsForTest(int kind, const float* params, const std::int32_t* flags,
                            const float* wi, const float* u, std::size_t n, float* wo,
                            float* shadowing, float* fresnel, std::int32_t* reflected,
                            std::int32_t* degenerate) {
    const DF df;
    LaneIo io{df};
    io.n = n;
    for (io.base = 0; io.base < n; io.base += hn::Lanes(df)) {
        const V3 w = io.Load3(wi);
        const VF uc = io.Load(u, 0.f), u1 = io.Load(u + n, 0.f), u2 = io.Load(u + 2 * n, 0.f);
        const MF active = io.Active();
        InterfaceEventLanes<VF, MF> e;
        if (kind == 0) {  // dielectric: params eta, alpha; flags the event shape
            const DielectricEventShape shape{flags[0] != 0, flags[1] != 0, flags[2] != 0,
                                             flags[3] != 0};
            e = dielectric_event<VF, VecLane>(
                hn::Set(df, params[0]), hn::Set(df, 1.f / params[0]),
                ggx_isotropic_lanes<VF, VecLane>(hn::Set(df, params[1])), shape, w, uc, u1, u2,
                active);
        } else if (kind ==
                   1) {  // conductor: params alpha, eta[3], k[3]; flags smooth, uncorrelated
            ConductorInterface<float> iface{Rgbf(params[1], params[2], params[3]),
                                            Rgbf(params[4], params[5], params[6]), params[0]};
            VF f[3];
            e = conductor_event<VF, VecLane>(
                ggx_isotropic_lanes<VF, VecLane>(hn::Set(df, params[0])), flags[0] != 0,
                flags[1] != 0, w, u1, u2, active, ConductorFresnel{iface}, f);
            for (int c = 0; c < 3; ++c)
                io.Store(f[c], fresnel + c * n);
        } else {  // Lambertian
            e.wo = lambertian_event<VF, VecLane>(w.z, u1, u2);
            e.shadowing = hn::Set(df, 1.f);
            e.reflected = active;
            e.degenerate = hn::And(active, hn::Eq(w.z, hn::Zero(df)));
        }
        io.Store3(e.wo, wo);
        io.Store(e.shadowing, shadowing);
        io.StoreMask(e.reflected, reflected);
        io.StoreMask(e.degenerate, degenerate);
    }
}

// InterfaceEventsForTest on pairs of vectors (VecLane2): the lanes of io.base in
// the first vector, the next vector's worth in the second.
void InterfaceEventPairsForTest(int kind, const float* params, const std::int32_t* flags,
                                const float* wi, const float* u, std::size_t n, float* wo,
                                float* shadowing, float* fresnel, std::int32_t* reflected,
                                std::int32_t* degenerate) {
    const DF df;
    LaneIo io[2] = {{df}, {df}};
    io[0].n = io[1].n = n;
    const std::size_t lanes = hn::Lanes(df);
    for (std::size_t base = 0; base < n; base += 2 * lanes) {
        io[0].base = base;
        io[1].base = std::min(base + lanes, n);
        auto pair = [&](const float* a, float pad) {
            return VF2{io[0].Load(a, pad), io[1].Load(a, pad)};
        };
        const LaneVec3<VF2> w = Pair(io[0].Load3(wi), io[1].Load3(wi));
        const VF2 uc = pair(u, 0.f), u1 = pair(u + n, 0.f), u2 = pair(u + 2 * n, 0.f);
        const MF2 active{io[0].Active(), io[1].Active()};
        InterfaceEventLanes<VF2, MF2> e;
        if (kind == 0) {
            const DielectricEventShape shape{flags[0] != 0, flags[1] != 0, flags[2] != 0,
                                             flags[3] != 0};
            const VF alpha = hn::Set(df, params[1]);
            e = dielectric_event<VF2, VecLane2>(
                VecLane2::constant(params[0]), VecLane2::constant(1.f / params[0]),
                ggx_isotropic_lanes<VF2, VecLane2>(VF2{alpha, alpha}), shape, w, uc, u1, u2,
                active);
        } else if (kind == 1) {
            ConductorInterface<float> iface{Rgbf(params[1], params[2], params[3]),
                                            Rgbf(params[4], params[5], params[6]), params[0]};
            const VF alpha = hn::Set(df, params[0]);
            VF2 f[3];
            e = conductor_event<VF2, VecLane2>(
                ggx_isotropic_lanes<VF2, VecLane2>(VF2{alpha, alpha}), flags[0] != 0, flags[1] != 0,
                w, u1, u2, active, ConductorFresnel{iface}, f);
            for (int c = 0; c < 3; ++c) {
                io[0].Store(f[c].a, fresnel + c * n);
                io[1].Store(f[c].b, fresnel + c * n);
            }
        } else {
            e.wo = lambertian_event<VF2, VecLane2>(w.z, u1, u2);
            e.shadowing = VecLane2::constant(1);
            e.reflected = active;
            const VF zero = hn::Zero(df);
            e.degenerate = {hn::And(active.a, hn::Eq(w.z.a, zero)),
                            hn::And(active.b, hn::Eq(w.z.b, zero))};
        }
        io[0].Store3(First(e.wo), wo);
        io[1].Store3(Second(e.wo), wo);
        io[0].Store(e.shadowing.a, shadowing);
        io[1].Store(e.shadowing.b, shadowing);
        io[0].StoreMask(e.reflected.a, reflected);
        io[1].StoreMask(e.reflected.b, reflected);
        io[0].StoreMask(e.degenerate.a, degenerate);
        io[1].StoreMask(e.degenerate.b, degenerate);
    }
}

void FresnelMuellerForTest(int kind, const float* cos_theta, std::size_t n, float eta, float k,
                           float* out) {
    const DF df;
    LaneIo io{df};
    io.n = n;
    const std::size_t stride = kind == 0 ? 9 : 4;
    for (io.base = 0; io.base < n; io.base += hn::Lanes(df)) {
        const VF c = io.Load(cos_theta, 1.f);
        VF v[9];
        if (kind == 0) {
            const DielectricMueller<VF> m = fresnel_dielectric_mueller<VF, VecLane>(
                c, hn::Set(df, eta), hn::Set(df, 1.f / eta));
            const VF all[9] = {m.reflection.a,   m.reflection.b,   m.reflection.c,
                               m.reflection.d,   m.transmission.a, m.transmission.b,
                               m.transmission.c, m.transmission.d, m.cos_theta_t};
            std::copy(all, all + 9, v);
        } else {
            const InterfaceMueller<VF> m =
                fresnel_conductor_mueller<VF, VecLane>(c, hn::Set(df, eta), hn::Set(df, k));
            v[0] = m.a, v[1] = m.b, v[2] = m.c, v[3] = m.d;
        }
        HWY_ALIGN float buf[kMaxLanes];
        for (std::size_t e = 0; e < stride; ++e) {
            hn::Store(v[e], df, buf);
            for (std::size_t l = 0; l < hn::Lanes(df) && io.base + l < n; ++l)
                out[(io.base + l) * stride + e] = buf[l];
        }
    }
}

void PolarizedEventsForTest(int kind, const float* params, const std::int32_t* flags,
                            const float* wi, const float* u, const float* x, const float* stokes,
                            const float* flux, int channels, std::size_t n, float* wo,
                            float* shadowing, std::int32_t* reflected, std::int32_t* degenerate,
                            float* x_out, float* stokes_out, float* factor) {
    const DF df;
    LaneIo io{df};
    io.n = n;
    // Strided per-lane inputs and outputs: element e of lane j at [stride·j + e].
    auto load = [&](const float* a, std::size_t stride, std::size_t e, float pad) {
        HWY_ALIGN float buf[kMaxLanes];
        for (std::size_t l = 0; l < hn::Lanes(df); ++l)
            buf[l] = io.base + l < n ? a[stride * (io.base + l) + e] : pad;
        return hn::Load(df, buf);
    };
    auto store = [&](VF v, float* a, std::size_t stride, std::size_t e) {
        HWY_ALIGN float buf[kMaxLanes];
        hn::Store(v, df, buf);
        for (std::size_t l = 0; l < hn::Lanes(df) && io.base + l < n; ++l)
            a[stride * (io.base + l) + e] = buf[l];
    };
    for (io.base = 0; io.base < n; io.base += hn::Lanes(df)) {
        const V3 w = io.Load3(wi);
        const VF uc = io.Load(u, 0.f), u1 = io.Load(u + n, 0.f), u2 = io.Load(u + 2 * n, 0.f);
        const MF active = io.Active();
        PolarizationLanes<VF> pol;
        pol.channels = channels;
        pol.stokes.x = {load(x, 3, 0, 0.f), load(x, 3, 1, 1.f), load(x, 3, 2, 0.f)};
        for (int c = 0; c < 3; ++c) {
            pol.stokes.q[c] = load(stokes, 9, std::size_t(3 * c), 0.f);
            pol.stokes.u[c] = load(stokes, 9, std::size_t(3 * c + 1), 0.f);
            pol.stokes.v[c] = load(stokes, 9, std::size_t(3 * c + 2), 0.f);
        }
        const VF flux_v[3] = {load(flux, 3, 0, 1.f), load(flux, 3, 1, 1.f), load(flux, 3, 2, 1.f)};
        pol.flux = flux_v;
        InterfaceEventLanes<VF, MF> e;
        if (kind == 0) {
            const DielectricEventShape shape{flags[0] != 0, flags[1] != 0, flags[2] != 0,
                                             flags[3] != 0};
            e = dielectric_event<VF, VecLane, true>(
                hn::Set(df, params[0]), hn::Set(df, 1.f / params[0]),
                ggx_isotropic_lanes<VF, VecLane>(hn::Set(df, params[1])), shape, w, uc, u1, u2,
                active, &pol);
        } else {
            ConductorInterface<float> iface{Rgbf(params[1], params[2], params[3]),
                                            Rgbf(params[4], params[5], params[6]), params[0]};
            VF f[3];
            e = conductor_event<VF, VecLane>(
                ggx_isotropic_lanes<VF, VecLane>(hn::Set(df, params[0])), flags[0] != 0,
                flags[1] != 0, w, u1, u2, active, ConductorFresnel{iface}, f, &pol,
                ConductorMueller{iface});
        }
        io.Store3(e.wo, wo);
        io.Store(e.shadowing, shadowing);
        io.StoreMask(e.reflected, reflected);
        io.StoreMask(e.degenerate, degenerate);
        store(pol.stokes.x.x, x_out, 3, 0);
        store(pol.stokes.x.y, x_out, 3, 1);
        store(pol.stokes.x.z, x_out, 3, 2);
        for (int c = 0; c < 3; ++c) {
            store(pol.stokes.q[c], stokes_out, 9, std::size_t(3 * c));
            store(pol.stokes.u[c], stokes_out, 9, std::size_t(3 * c + 1));
            store(pol.stokes.v[c], stokes_out, 9, std::size_t(3 * c + 2));
            store(pol.factor[c], factor, 3, std::size_t(c));
        }
    }
}

void MediumStepForTest(const CompiledMedium<float>& med, const float* d, const float* w,
                       const float* depth, const float* u, std::size_t n, std::int32_t* leaves,
                       float* factor, float* depth_out, float* d_out, float* phase,
                       std::int32_t* draws) {
    const DF df;
    LaneIo io{df};
    io.n = n;
    for (io.base = 0; io.base < n; io.base += hn::Lanes(df)) {
        const V3 dv = io.Load3(d);
        const VF wv[3] = {io.Load(w, 1.f), io.Load(w + n, 1.f), io.Load(w + 2 * n, 1.f)};
        int k = 0;  // the uniforms: u[k·n + j] is lane j's k-th draw
        auto uniform = [&] { return io.Load(u + std::size_t(k++) * n, 0.5f); };
        const MediumFlightLanes<VF, MF> flight =
            medium_free_flight<VF, VecLane>(med, dv, wv, io.Load(depth, 0.5f), uniform);
        const MF scatters = hn::AndNot(flight.leaves, io.Active());
        V3 d_new = dv;
        VF ph[3];
        medium_scatter<VF, VecLane>(med, dv, flight.p, scatters, uniform, d_new, ph);
        io.StoreMask(flight.leaves, leaves);
        for (int c = 0; c < 3; ++c) {
            io.Store(flight.factor[c], factor + c * n);
            io.Store(ph[c], phase + c * n);
        }
        io.Store(flight.depth, depth_out);
        io.Store3(d_new, d_out);
        for (std::size_t l = 0; l < hn::Lanes(df) && io.base + l < n; ++l)
            draws[io.base + l] = k;
    }
}

void GgxLanesForTest(float alpha, const float* w, const float* u1, const float* u2, std::size_t n,
                     float* lambda, float* wm) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    HWY_ALIGN float in[5][kMaxLanes], out[4][kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        for (std::size_t l = 0; l < n_lanes; ++l) {
            const bool real = base + l < n;
            for (int i = 0; i < 3; ++i)
                in[i][l] = real ? w[3 * (base + l) + i] : (i == 2 ? 1.f : 0.f);
            in[3][l] = real ? u1[base + l] : 0.f;
            in[4][l] = real ? u2[base + l] : 0.f;
        }
        const V3 wv = {hn::Load(df, in[0]), hn::Load(df, in[1]), hn::Load(df, in[2])};
        const VF a = hn::Set(df, alpha);
        const GgxLanes<VF> g = ggx_isotropic_lanes<VF, VecLane>(a);
        hn::Store(ggx_lambda<VF, VecLane>(g, wv.x, wv.y, wv.z), df, out[0]);
        const V3 m = ggx_sample_visible_normal_complete<VF, VecLane>(g, wv, hn::Load(df, in[3]),
                                                                     hn::Load(df, in[4]));
        hn::Store(m.x, df, out[1]);
        hn::Store(m.y, df, out[2]);
        hn::Store(m.z, df, out[3]);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l) {
            lambda[base + l] = out[0][l];
            for (int i = 0; i < 3; ++i)
                wm[3 * (base + l) + i] = out[1 + i][l];
        }
    }
}

void MicrosurfaceWalkForTest(const float* wi, std::size_t n, float alpha, bool dielectric,
                             const float* eta, const float* k, int max_order, std::uint64_t seed,
                             float* wo, float* weight, int* order, int* outcome) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    std::vector<std::uint64_t> state(n), inc(n);
    SeedParticles(seed, 0, 0, n, state.data(), inc.data());
    DielectricInterface<float> di_face;
    di_face.eta = eta[0];
    di_face.alpha = alpha;
    ConductorInterface<float> co_face;
    co_face.eta = Rgbf(eta[0], eta[1], eta[2]);
    co_face.k = Rgbf(k[0], k[1], k[2]);
    co_face.alpha = alpha;
    HWY_ALIGN float in[3][kMaxLanes], out[7][kMaxLanes];
    HWY_ALIGN std::int32_t why[kMaxLanes];
    for (std::size_t base = 0; base < n; base += n_lanes) {
        LaneRng rng;
        for (std::size_t l = 0; l < n_lanes; ++l) {
            const bool real = base + l < n;
            rng.state[l] = real ? state[base + l] : 0;
            rng.inc[l] = real ? inc[base + l] : 1;
            for (int i = 0; i < 3; ++i)
                in[i][l] = real ? wi[3 * (base + l) + i] : (i == 2 ? 1.f : 0.f);
        }
        rng.SyncIn();
        const MF m = hn::FirstN(df, std::min(n_lanes, n - base));
        auto draw = [&] { return rng.Uniform(); };
        const V3 wi_v = {hn::Load(df, in[0]), hn::Load(df, in[1]), hn::Load(df, in[2])};
        MicrosurfaceWalkLanes<VF, MF> r;
        if (dielectric) {
            const MicrosurfaceDielectricFacet<VF, VecLane, decltype(draw)> facet{
                hn::Set(df, di_face.eta), hn::Set(df, di_face.inv_eta()), draw};
            r = microsurface_walk<VF, VecLane>(ggx_isotropic_lanes<VF, VecLane>(hn::Set(df, alpha)),
                                               wi_v, m, true, facet, draw, max_order);
        } else {
            auto fresnel = [&](VF cos_w_m, VF* factors) {
                for (int c = 0; c < 3; ++c)
                    factors[c] = FresnelConductor(cos_w_m, co_face.eta[c], co_face.k[c]);
            };
            const MicrosurfaceConductorFacet<VF, VecLane, decltype(fresnel)> facet{fresnel};
            r = microsurface_walk<VF, VecLane>(ggx_isotropic_lanes<VF, VecLane>(hn::Set(df, alpha)),
                                               wi_v, m, false, facet, draw, max_order);
        }
        hn::Store(r.wo.x, df, out[0]);
        hn::Store(r.wo.y, df, out[1]);
        hn::Store(r.wo.z, df, out[2]);
        for (int c = 0; c < 3; ++c)
            hn::Store(r.weight[c], df, out[3 + c]);
        hn::Store(r.order, df, out[6]);
        const DI di;
        const VI outcome_v = hn::IfThenElse(
            hn::RebindMask(di, r.degenerate), hn::Set(di, 2),
            hn::IfThenElse(hn::RebindMask(di, r.capped), hn::Set(di, 1), hn::Zero(di)));
        hn::Store(outcome_v, di, why);
        for (std::size_t l = 0; l < n_lanes && base + l < n; ++l) {
            const std::size_t p = base + l;
            for (int i = 0; i < 3; ++i) {
                wo[3 * p + i] = out[i][l];
                weight[3 * p + i] = out[3 + i][l];
            }
            order[p] = int(out[6][l]);
            outcome[p] = why[l];
        }
    }
}

// FilmReflection over entries in chunks of a vector's lanes, the lanes of `skip` (bit l of
// entry l's chunk) left inactive: per entry the polarized a, b, c, d of each channel, then the
// unpolarized factor of each channel (15 floats).
std::uint32_t FilmReflectionForTest(const FilmOptics* const* films, const float* cos_theta,
                                    const double* thickness_nm, std::size_t n, std::uint64_t skip,
                                    float* out) {
    const DF df;
    const std::size_t n_lanes = hn::Lanes(df);
    for (std::size_t base = 0; base < n; base += n_lanes) {
        const std::size_t count = std::min(n_lanes, n - base);
        HWY_ALIGN float c[kMaxLanes] = {};
        HWY_ALIGN const FilmOptics* f[kMaxLanes];
        HWY_ALIGN double t[kMaxLanes];
        HWY_ALIGN std::int32_t on[kMaxLanes];
        for (std::size_t l = 0; l < n_lanes; ++l) {
            const std::size_t j = base + std::min(l, count - 1);
            c[l] = cos_theta[j];
            f[l] = films[j];
            t[l] = thickness_nm[j];
            on[l] = l < count && (skip >> l & 1) == 0 ? 1 : 0;
        }
        const MF active = hn::RebindMask(df, hn::Ne(hn::Load(DI(), on), hn::Zero(DI())));
        const FilmReflection reflection{f, t};
        InterfaceMueller<VF> m[3];
        VF factors[3];
        reflection(hn::Load(df, c), m, active);
        reflection(hn::Load(df, c), factors, active);
        HWY_ALIGN float e[3][5][kMaxLanes];
        for (int ch = 0; ch < 3; ++ch) {
            hn::Store(m[ch].a, df, e[ch][0]);
            hn::Store(m[ch].b, df, e[ch][1]);
            hn::Store(m[ch].c, df, e[ch][2]);
            hn::Store(m[ch].d, df, e[ch][3]);
            hn::Store(factors[ch], df, e[ch][4]);
        }
        for (std::size_t l = 0; l < count; ++l) {
            for (int ch = 0; ch < 3; ++ch)
                for (int k = 0; k < 4; ++k)
                    out[(base + l) * 15 + std::size_t(ch * 4 + k)] = e[ch][k][l];
            for (int ch = 0; ch < 3; ++ch)
                out[(base + l) * 15 + 12 + std::size_t(ch)] = e[ch][4][l];
        }
    }
    return std::uint32_t(n_lanes);
}

}  // namespace HWY_NAMESPACE
}  // namespace lamina
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace lamina {

// A probe runs on the instruction set the kernel would (LAMINA_SIMD_TARGET applied first).
#define LAMINA_PROBE_DISPATCH(FUNC) (select_simd_target(), HWY_DYNAMIC_DISPATCH(FUNC))

HWY_EXPORT(PcgDrawsForTest);
HWY_EXPORT(CosSin2PiForTest);
HWY_EXPORT(InvSqrtForTest);
HWY_EXPORT(SmithRefractionEscapeForTest);
HWY_EXPORT(LaneBinsForTest);
HWY_EXPORT(FresnelDielectricForTest);
HWY_EXPORT(FresnelConductorForTest);
HWY_EXPORT(HenyeyGreensteinForTest);
HWY_EXPORT(BeerLambertLanesForTest);
HWY_EXPORT(MicrosurfaceWalkForTest);
HWY_EXPORT(GgxLanesForTest);
HWY_EXPORT(InterfaceEventsForTest);
HWY_EXPORT(InterfaceEventPairsForTest);
HWY_EXPORT(MediumStepForTest);
HWY_EXPORT(FilmReflectionForTest);
HWY_EXPORT(FresnelMuellerForTest);
HWY_EXPORT(PolarizedEventsForTest);

std::vector<float> simd_particle_uniforms(std::uint64_t seed, std::uint64_t stream,
                                          std::uint64_t first, std::uint64_t n_particles,
                                          std::uint64_t n_draws) {
    std::vector<float> out(n_particles * n_draws);
    LAMINA_PROBE_DISPATCH(PcgDrawsForTest)(seed, stream, first, n_particles, n_draws, out.data());
    return out;
}

void simd_cos_sin_2pi(const std::vector<float>& u, std::vector<float>& c, std::vector<float>& s) {
    c.resize(u.size());
    s.resize(u.size());
    LAMINA_PROBE_DISPATCH(CosSin2PiForTest)(u.data(), u.size(), c.data(), s.data());
}

std::vector<float> simd_inv_sqrt(const std::vector<float>& x) {
    std::vector<float> out(x.size());
    LAMINA_PROBE_DISPATCH(InvSqrtForTest)(x.data(), x.size(), out.data());
    return out;
}

std::vector<std::int64_t> simd_lane_bins(const HemisphereGrid& grid, const std::vector<float>& d) {
    select_simd_target();
    std::vector<std::int64_t> bins(d.size() / 3);
    LAMINA_PROBE_DISPATCH(LaneBinsForTest)(grid, d.data(), bins.size(), bins.data());
    return bins;
}

std::vector<float> simd_smith_refraction_escape(const std::vector<float>& r_i,
                                                const std::vector<float>& r_o) {
    select_simd_target();
    std::vector<float> out(r_i.size());
    LAMINA_PROBE_DISPATCH(SmithRefractionEscapeForTest)
    (r_i.data(), r_o.data(), r_i.size(), out.data());
    return out;
}

void simd_fresnel_dielectric(const std::vector<float>& cos_theta, float eta,
                             std::vector<float>& reflectance, std::vector<float>& cos_theta_t) {
    select_simd_target();
    reflectance.resize(cos_theta.size());
    cos_theta_t.resize(cos_theta.size());
    LAMINA_PROBE_DISPATCH(FresnelDielectricForTest)
    (cos_theta.data(), cos_theta.size(), eta, reflectance.data(), cos_theta_t.data());
}

std::vector<float> simd_beer_lambert_lanes(const std::vector<float>& tau,
                                           const std::vector<float>& inv_mu) {
    select_simd_target();
    std::vector<float> out(tau.size());
    LAMINA_PROBE_DISPATCH(BeerLambertLanesForTest)
    (tau.data(), inv_mu.data(), tau.size(), out.data());
    return out;
}

std::vector<float> simd_fresnel_conductor(const std::vector<float>& cos_theta, float eta, float k) {
    select_simd_target();
    std::vector<float> out(cos_theta.size());
    LAMINA_PROBE_DISPATCH(FresnelConductorForTest)
    (cos_theta.data(), cos_theta.size(), eta, k, out.data());
    return out;
}

void simd_henyey_greenstein(const std::vector<float>& g, const std::vector<float>& x,
                            std::vector<float>& phase, std::vector<float>& cos_theta) {
    select_simd_target();
    phase.resize(g.size());
    cos_theta.resize(g.size());
    LAMINA_PROBE_DISPATCH(HenyeyGreensteinForTest)
    (g.data(), x.data(), g.size(), phase.data(), cos_theta.data());
}

void simd_ggx_lanes(float alpha, const std::vector<float>& w, const std::vector<float>& u1,
                    const std::vector<float>& u2, std::vector<float>& lambda,
                    std::vector<float>& wm) {
    select_simd_target();
    lambda.resize(u1.size());
    wm.resize(3 * u1.size());
    LAMINA_PROBE_DISPATCH(GgxLanesForTest)
    (alpha, w.data(), u1.data(), u2.data(), u1.size(), lambda.data(), wm.data());
}

SimdEventResult simd_interface_events(int kind, const std::vector<float>& params,
                                      const std::vector<std::int32_t>& flags,
                                      const std::vector<float>& wi, const std::vector<float>& u,
                                      bool on_pairs) {
    select_simd_target();
    const std::size_t n = wi.size() / 3;
    SimdEventResult r;
    r.wo.resize(3 * n);
    r.shadowing.resize(n);
    r.fresnel.assign(3 * n, 1.f);
    r.reflected.resize(n);
    r.degenerate.resize(n);
    const auto probe = on_pairs ? LAMINA_PROBE_DISPATCH(InterfaceEventPairsForTest)
                                : LAMINA_PROBE_DISPATCH(InterfaceEventsForTest);
    probe(kind, params.data(), flags.data(), wi.data(), u.data(), n, r.wo.data(),
          r.shadowing.data(), r.fresnel.data(), r.reflected.data(), r.degenerate.data());
    return r;
}

SimdMediumResult simd_medium_step(const CompiledMedium<float>& medium, const std::vector<float>& d,
                                  const std::vector<float>& w, const std::vector<float>& depth,
                                  const std::vector<float>& u) {
    select_simd_target();
    const std::size_t n = depth.size();
    SimdMediumResult r;
    r.leaves.resize(n);
    r.factor.resize(3 * n);
    r.depth.resize(n);
    r.d.resize(3 * n);
    r.phase.resize(3 * n);
    r.draws.resize(n);
    LAMINA_PROBE_DISPATCH(MediumStepForTest)
    (medium, d.data(), w.data(), depth.data(), u.data(), n, r.leaves.data(), r.factor.data(),
     r.depth.data(), r.d.data(), r.phase.data(), r.draws.data());
    return r;
}

std::vector<float> simd_fresnel_mueller(int kind, const std::vector<float>& cos_theta, float eta,
                                        float k) {
    select_simd_target();
    std::vector<float> out(cos_theta.size() * (kind == 0 ? 9 : 4));
    LAMINA_PROBE_DISPATCH(FresnelMuellerForTest)
    (kind, cos_theta.data(), cos_theta.size(), eta, k, out.data());
    return out;
}

std::vector<float> simd_film_reflection(const std::vector<const FilmOptics*>& films,
                                        const std::vector<float>& cos_theta,
                                        const std::vector<double>& thickness_nm, std::uint64_t skip,
                                        std::size_t& n_lanes) {
    select_simd_target();
    std::vector<float> out(cos_theta.size() * 15);
    n_lanes = LAMINA_PROBE_DISPATCH(FilmReflectionForTest)(
        films.data(), cos_theta.data(), thickness_nm.data(), cos_theta.size(), skip, out.data());
    return out;
}

SimdPolarizedEventResult simd_polarized_interface_events(
    int kind, const std::vector<float>& params, const std::vector<std::int32_t>& flags,
    const std::vector<float>& wi, const std::vector<float>& u, const std::vector<float>& x,
    const std::vector<float>& stokes, const std::vector<float>& flux, int channels) {
    select_simd_target();
    const std::size_t n = wi.size() / 3;
    SimdPolarizedEventResult r;
    r.event.wo.resize(3 * n);
    r.event.shadowing.resize(n);
    r.event.reflected.resize(n);
    r.event.degenerate.resize(n);
    r.x.resize(3 * n);
    r.stokes.resize(9 * n);
    r.factor.resize(3 * n);
    LAMINA_PROBE_DISPATCH(PolarizedEventsForTest)
    (kind, params.data(), flags.data(), wi.data(), u.data(), x.data(), stokes.data(), flux.data(),
     channels, n, r.event.wo.data(), r.event.shadowing.data(), r.event.reflected.data(),
     r.event.degenerate.data(), r.x.data(), r.stokes.data(), r.factor.data());
    return r;
}

SimdWalkResult simd_microsurface_walk(const std::vector<float>& wi, float alpha, bool dielectric,
                                      const float eta[3], const float k[3], int max_order,
                                      std::uint64_t seed) {
    select_simd_target();
    const std::size_t n = wi.size() / 3;
    SimdWalkResult r;
    r.wo.resize(3 * n);
    r.weight.resize(3 * n);
    r.order.resize(n);
    r.outcome.resize(n);
    LAMINA_PROBE_DISPATCH(MicrosurfaceWalkForTest)
    (wi.data(), n, alpha, dielectric, eta, k, max_order, seed, r.wo.data(), r.weight.data(),
     r.order.data(), r.outcome.data());
    return r;
}

}  // namespace lamina
#endif
