// The batched SIMD particle kernel (kernel_simd.h): trace_particle (goniophotometer.cpp) on SIMD
// vectors, particles as lanes. The physics is not here: every event is a lane template of
// src/physics (core/lane.h) that the scalar kernel instantiates at one lane and this kernel on its
// vectors — the interface events (dielectric.h dielectric_event, conductor.h conductor_event,
// lambertian.h lambertian_event, with the Fresnel factors, the Smith masking and the visible
// normals they use), the microsurface walk (microsurface_walk.h) and the medium step (medium.h:
// Beer–Lambert, free flights and Henyey–Greenstein scattering by spectral MIS). This file holds
// the lane management: the lane operations of core/lane.h on Highway vectors (VecLane), the
// vector random number generator, the queue and refills of lanes, the grouping of lanes by layer,
// the tallies and the budget sums.
//
// Layout. A block's particles run through a fixed set of lanes; a lane whose particle ends (exit,
// absorption, cut-off) takes the block's next particle, so all lanes stay busy until the block's
// tail. Per iteration every live lane does one step: an interface event followed, for lanes that
// continue, by the crossing of the medium behind it (Beer–Lambert for absorbing media), or — for a
// lane inside a scattering medium — one free flight with its scattering event. Interfaces are
// evaluated layer by layer under the mask of the lanes that sit at that layer, with the layer's
// parameters broadcast; no lane-dependent branches. What a lane does per step is exactly what
// trace_particle does per loop (the same templates, the same budget bookkeeping, the same event
// count), so the two kernels estimate the same tables (tests/simulator: every exact-solution test
// runs on both, and a two-sample chi-square test compares them; tests/physics/lanes_test.cpp and
// tests/simulator/kernel_simd_test.cpp compare each template's instantiations).
//
// Multiple scattering on the microsurfaces (physics/microsurface_walk.h). At a rough interface
// the lanes of the event walk from facet to facet together: while any of them walks, every lane of
// the vector draws its numbers, and the event ends when each has escaped, met its facet cap or a
// degeneracy. The event counts once, as in trace_particle.
//
// Random numbers. Each lane draws from the particle's own PCG32 generator (O'Neill 2014), seeded
// as in core/rng.h from one Philox4x32-10 evaluation (Salmon et al. 2011) keyed by (seed, stream,
// particle index): the very streams of the scalar kernel. Both generators are evaluated here on
// vectors (Highway has no RNG); tests check them bit for bit against Random123 and pcg-cpp. Every
// lane draws whenever some lane of its step needs a number, used or not: a particle's draws are
// then not those of the scalar kernel, but each is still a fresh uniform number independent of
// the particle's past.
//
// Reproducibility. A block is traced in a fixed order by one thread; exits go to the integer
// tallies and the budget to the block's double sums in a fixed lane order: the output depends on
// the block only, never on the thread count. It may differ between instruction sets (the vector
// math rounds differently), so it is reproducible for a given kernel and machine.

#include "simulator/kernel_simd.h"

#include "core/error.h"
#include "core/math.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

// Lane state is kept in structs of vectors, which the sizeless vector types of SVE cannot be
// members of: Arm builds use NEON. The scalar fallback target has one lane, too few for the 64-bit
// halves of the generators; EMU128 (portable C++, four lanes) stands in for it.
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128)
#endif
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "simulator/kernel_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

// The lane headers (core/lane.h) once more, their templates compiled for this instruction set.
#undef LAMINA_LANE_BEGIN
#undef LAMINA_LANE_END
#define LAMINA_LANE_BEGIN   \
    HWY_BEFORE_NAMESPACE(); \
    namespace lamina {      \
    namespace HWY_NAMESPACE {
#define LAMINA_LANE_END \
    }                   \
    }                   \
    HWY_AFTER_NAMESPACE();
#define LAMINA_LANE_TARGET
#include "core/lane_vec.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/lambertian.h"
#include "physics/medium.h"
#include "physics/microfacet.h"
#include "physics/microsurface_walk.h"
#include "physics/phase.h"
#include "physics/polarization.h"
#include "physics/smith_masking.h"
#undef LAMINA_LANE_TARGET

HWY_BEFORE_NAMESPACE();
namespace lamina {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using D64 = hn::Repartition<std::uint64_t, DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using V64 = hn::Vec<D64>;
using MF = hn::Mask<DF>;
using MI = hn::Mask<DI>;

constexpr std::size_t kMaxLanes = HWY_MAX_BYTES / sizeof(float);

// ---- Random numbers ---------------------------------------------------------------------------

// 32 × 32 → 64-bit products of u32 lanes: low and high words (Philox's mulhilo).
HWY_INLINE void MulHiLo32(VU a, VU b, VU& lo, VU& hi) {
    const DU du;
    const D64 d64;
    lo = a * b;
    const V64 even = hn::MulEven(a, b);
    const V64 odd = hn::MulEven(hn::BitCast(du, hn::ShiftRight<32>(hn::BitCast(d64, a))),
                                hn::BitCast(du, hn::ShiftRight<32>(hn::BitCast(d64, b))));
    hi = hn::OddEven(hn::BitCast(du, odd), hn::BitCast(du, hn::ShiftRight<32>(even)));
}

// Philox4x32-10 (Salmon et al. 2011, §4.2; the constants of Random123's philox.h) on lanes, for
// kN counter vectors at once: their rounds interleave, so the multiplications' latencies overlap
// (one vector's ten rounds are one dependent chain).
template <int kN>
HWY_INLINE void Philox4x32(VU (&c)[kN][4], std::uint32_t k0, std::uint32_t k1) {
    const DU du;
    const VU m0 = hn::Set(du, 0xD2511F53u), m1 = hn::Set(du, 0xCD9E8D57u);
    for (int round = 0; round < 10; ++round) {
        const VU key0 = hn::Set(du, k0), key1 = hn::Set(du, k1);
        for (int j = 0; j < kN; ++j) {
            VU lo0, hi0, lo1, hi1;
            MulHiLo32(m0, c[j][0], lo0, hi0);
            MulHiLo32(m1, c[j][2], lo1, hi1);
            const VU n0 = hn::Xor(hn::Xor(hi1, c[j][1]), key0);
            const VU n2 = hn::Xor(hn::Xor(hi0, c[j][3]), key1);
            c[j][0] = n0;
            c[j][1] = lo1;
            c[j][2] = n2;
            c[j][3] = lo0;
        }
        k0 += 0x9E3779B9u;  // the Weyl key schedule
        k1 += 0xBB67AE85u;
    }
}

constexpr std::uint64_t kPcgMultiplier = 6364136223846793005ull;

// The PCG32 generator (pcg-cpp's pcg32: 64-bit LCG state, XSH-RR output of the previous state) of
// particle p, seeded as ParticleRng(seed, stream, p) seeds it; four vectors of particles at a time.
void SeedParticles(std::uint64_t seed, std::uint64_t stream, std::uint64_t first,
                   std::uint64_t count, std::uint64_t* state, std::uint64_t* inc) {
    constexpr int kVectors = 4;
    const DU du;
    const std::size_t n = hn::Lanes(du);
    HWY_ALIGN std::uint32_t idx_lo[kMaxLanes], idx_hi[kMaxLanes], out[kVectors][4][kMaxLanes];
    for (std::uint64_t base = 0; base < count; base += kVectors * n) {
        VU c[kVectors][4];
        for (int j = 0; j < kVectors; ++j) {
            for (std::size_t l = 0; l < n; ++l) {
                const std::uint64_t p = first + base + j * n + l;
                idx_lo[l] = std::uint32_t(p);
                idx_hi[l] = std::uint32_t(p >> 32);
            }
            c[j][0] = hn::Load(du, idx_lo);
            c[j][1] = hn::Load(du, idx_hi);
            c[j][2] = hn::Set(du, std::uint32_t(stream));
            c[j][3] = hn::Set(du, std::uint32_t(stream >> 32));
        }
        Philox4x32(c, std::uint32_t(seed), std::uint32_t(seed >> 32));
        for (int j = 0; j < kVectors; ++j)
            for (int w = 0; w < 4; ++w)
                hn::Store(c[j][w], du, out[j][w]);
        for (int j = 0; j < kVectors; ++j)
            for (std::size_t l = 0; l < n && base + j * n + l < count; ++l) {
                const std::uint64_t initstate = (std::uint64_t(out[j][1][l]) << 32) | out[j][0][l];
                const std::uint64_t sequence = (std::uint64_t(out[j][3][l]) << 32) | out[j][2][l];
                const std::uint64_t increment = (sequence << 1) | 1u;
                state[base + j * n + l] = (initstate + increment) * kPcgMultiplier + increment;
                inc[base + j * n + l] = increment;
            }
    }
}

// x · kPcgMultiplier mod 2^64 from 32 × 32 → 64-bit products (64-bit lane products are not on
// every target).
HWY_INLINE V64 MulPcg(V64 x) {
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL
    return hn::Mul(x, hn::Set(D64(), kPcgMultiplier));  // AVX-512DQ has 64-bit lane products
#else
    const DU du;
    const VU x32 = hn::BitCast(du, x);
    const VU m_lo = hn::Set(du, std::uint32_t(kPcgMultiplier));
    const VU m_hi = hn::Set(du, std::uint32_t(kPcgMultiplier >> 32));
    const V64 lo_lo = hn::MulEven(x32, m_lo);
    const V64 cross =
        hn::Add(hn::MulEven(hn::BitCast(du, hn::ShiftRight<32>(x)), m_lo), hn::MulEven(x32, m_hi));
    return hn::Add(lo_lo, hn::ShiftLeft<32>(cross));
#endif
}

// The lanes' generators; one call draws one uniform float per lane, as ParticleRng::uniform_float.
// The generators live in vectors; state[]/inc[] are where lanes are given new particles (Sync
// out, patch, Sync in).
struct LaneRng {
    HWY_ALIGN std::uint64_t state[kMaxLanes];
    HWY_ALIGN std::uint64_t inc[kMaxLanes];
    V64 state_v[2], inc_v[2];

    HWY_INLINE void SyncIn() {
        const D64 d64;
        const std::size_t n64 = hn::Lanes(d64);
        for (int h = 0; h < 2; ++h) {
            state_v[h] = hn::Load(d64, state + h * n64);
            inc_v[h] = hn::Load(d64, inc + h * n64);
        }
    }
    HWY_INLINE void SyncOut() {
        const D64 d64;
        const std::size_t n64 = hn::Lanes(d64);
        for (int h = 0; h < 2; ++h)
            hn::Store(state_v[h], d64, state + h * n64);
    }

    HWY_INLINE VU NextU32() {
        const DU du;
        V64 xs[2], rot[2];
        for (int h = 0; h < 2; ++h) {
            const V64 old = state_v[h];
            state_v[h] = hn::Add(MulPcg(old), inc_v[h]);
            // XSH-RR: xorshift by 18, keep bits 27..58, rotate by the top 5 bits.
            xs[h] = hn::ShiftRight<27>(hn::Xor(old, hn::ShiftRight<18>(old)));
            rot[h] = hn::ShiftRight<59>(old);
        }
        // The low words of the 64-bit lanes, in lane order.
        const VU x = hn::ConcatEven(du, hn::BitCast(du, xs[1]), hn::BitCast(du, xs[0]));
        const VU r = hn::ConcatEven(du, hn::BitCast(du, rot[1]), hn::BitCast(du, rot[0]));
        const VU left = hn::And(hn::Sub(hn::Set(du, 32u), r), hn::Set(du, 31u));
        return hn::Or(x >> r, x << left);
    }
    HWY_INLINE VF Uniform() {
        const DF df;
        const DI di;
        return hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(NextU32()))),
                       hn::Set(df, 0x1p-24f));
    }
};

// ---- Vector geometry ---------------------------------------------------------------------------

using V3 = LaneVec3<VF>;  // core/lane.h

// 1/√x from the hardware estimate refined by one Newton step (y ← y (3 − x y²)/2): ≤ 2^-22
// relative error whatever the estimate's precision (≥ 12 bits on every target), a fraction of the
// cost of a square root and a division.
HWY_INLINE VF InvSqrt(VF x) {
    const DF df;
    const VF y = hn::ApproximateReciprocalSqrt(x);
    const VF half_x_y2 = hn::Mul(hn::Mul(hn::Set(df, 0.5f), x), hn::Mul(y, y));
    return hn::Mul(y, hn::Sub(hn::Set(df, 1.5f), half_x_y2));
}
HWY_INLINE V3 Select(MF m, const V3& a, const V3& b) {
    return {hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)};
}

// cos and sin of 2π u for u ∈ [0, 1) (a uniform azimuth), both at once. 2πu = (π/4)(j + f) with
// j = ⌊8u⌋ and f = 8u − j, exact in float (u has 24 bits); the octant's angle a ∈ [0, π/4] goes
// through the minimax polynomials of the Cephes library's sinf/cosf (Moshier 1992, "Methods and
// Programs for Mathematical Functions"; errors below 1 ulp on [−π/4, π/4]), and the octant's
// symmetries give cos and sin of the whole angle. One reduction for both instead of two.
HWY_INLINE void CosSin2Pi(VF u, VF& c, VF& s) {
    const DF df;
    const DI di;
    const VF t = hn::Mul(u, hn::Set(df, 8.f));
    const VF j_f = hn::Floor(t);
    const VI j = hn::ConvertTo(di, j_f);
    const VF f = hn::Sub(t, j_f);
    const auto odd = hn::RebindMask(df, hn::Ne(hn::And(j, hn::Set(di, 1)), hn::Zero(di)));
    const VF a = hn::Mul(hn::IfThenElse(odd, hn::Sub(hn::Set(df, 1.f), f), f),
                         hn::Set(df, 0.25f * kPi<float>));
    const VF z = hn::Mul(a, a);
    VF sin_a = hn::MulAdd(z, hn::Set(df, -1.9515295891e-4f), hn::Set(df, 8.3321608736e-3f));
    sin_a = hn::MulAdd(z, sin_a, hn::Set(df, -1.6666654611e-1f));
    sin_a = hn::MulAdd(hn::Mul(z, a), sin_a, a);
    VF cos_a =
        hn::MulAdd(z, hn::Set(df, 2.443315711809948e-5f), hn::Set(df, -1.388731625493765e-3f));
    cos_a = hn::MulAdd(z, cos_a, hn::Set(df, 4.166664568298827e-2f));
    cos_a = hn::MulAdd(hn::Mul(z, z), cos_a, hn::NegMulAdd(hn::Set(df, 0.5f), z, hn::Set(df, 1.f)));
    // Octants 1, 2, 5, 6 swap sin and cos; cos < 0 in octants 2–5, sin < 0 in octants 4–7.
    const auto swap = hn::RebindMask(
        df, hn::Ne(hn::And(hn::Add(j, hn::Set(di, 1)), hn::Set(di, 2)), hn::Zero(di)));
    const auto cos_negative = hn::RebindMask(
        df, hn::Ne(hn::And(hn::Add(j, hn::Set(di, 2)), hn::Set(di, 4)), hn::Zero(di)));
    const auto sin_negative = hn::RebindMask(df, hn::Ne(hn::And(j, hn::Set(di, 4)), hn::Zero(di)));
    const VF c_abs = hn::IfThenElse(swap, sin_a, cos_a);
    const VF s_abs = hn::IfThenElse(swap, cos_a, sin_a);
    c = hn::IfThenElse(cos_negative, hn::Neg(c_abs), c_abs);
    s = hn::IfThenElse(sin_negative, hn::Neg(s_abs), s_abs);
}

// The operations of core/lane.h on vectors: the physics templates written over a lane type
// (core/beta_function.h, physics/microfacet.h smith_refraction_escape) instantiated on lanes.
// Highway's contrib math functions: Log ≤ 4 ulp, Log1p ≤ 2 ulp, Exp ≤ 1 ulp (hwy/contrib/math).
struct VecLane {
    using Value = VF;
    using Mask = MF;
    static HWY_INLINE VF constant(double x) { return hn::Set(DF(), float(x)); }
    static HWY_INLINE VF min(VF a, VF b) { return hn::Min(a, b); }
    static HWY_INLINE VF max(VF a, VF b) { return hn::Max(a, b); }
    static HWY_INLINE VF sqrt(VF x) { return hn::Sqrt(x); }
    static HWY_INLINE VF log(VF x) { return hn::Log(DF(), x); }
    static HWY_INLINE VF log1p(VF x) { return hn::Log1p(DF(), x); }
    static HWY_INLINE VF exp(VF x) { return hn::Exp(DF(), x); }
    static HWY_INLINE VF select(MF m, VF a, VF b) { return hn::IfThenElse(m, a, b); }
    static HWY_INLINE MF less(VF a, VF b) { return hn::Lt(a, b); }
    static HWY_INLINE VF abs(VF x) { return hn::Abs(x); }
    static HWY_INLINE VF copysign(VF a, VF b) { return hn::CopySign(a, b); }
    static HWY_INLINE VF mul_add(VF a, VF b, VF c) { return hn::MulAdd(a, b, c); }
    static HWY_INLINE VF neg_mul_add(VF a, VF b, VF c) { return hn::NegMulAdd(a, b, c); }
    static HWY_INLINE VF inv_sqrt(VF x) { return InvSqrt(x); }
    static HWY_INLINE void cos_sin_2pi(VF u, VF& c, VF& s) { CosSin2Pi(u, c, s); }
    static HWY_INLINE MF both(MF m, MF n) { return hn::And(m, n); }
    static HWY_INLINE MF either(MF m, MF n) { return hn::Or(m, n); }
    static HWY_INLINE MF negate(MF m) { return hn::Not(m); }
    static HWY_INLINE bool none(MF m) { return hn::AllFalse(DF(), m); }
    static constexpr double kBetaArgumentMax = Lane<float>::kBetaArgumentMax;
    static constexpr bool kSinglePrecision = true;
};

// fresnel.h fresnel_conductor (real-arithmetic complex Fresnel, the same template), cos θ in
// [0, 1].
HWY_INLINE VF FresnelConductor(VF cos_theta, float eta, float k) {
    const DF df;
    return fresnel_conductor<VF, VecLane>(cos_theta, hn::Set(df, eta), hn::Set(df, k));
}

// ---- Lane state ---------------------------------------------------------------------------------

enum LossTerm { kLossMedium = 0, kLossBase = 1, kLossMicro = 2, kLossCutOff = 3, kLossTerms = 4 };

// Why a lane's particle ended this step.
enum Finish : std::int32_t { kGoesOn = 0, kReflected = 1, kTransmitted = 2, kEnded = 3 };

// The state of the lanes' particles, kept in vectors from step to step.
struct LaneVectors {
    V3 d;
    VF w[3];
    VF depth;  // inside a scattering medium: 0 at its top, 1 at its bottom
    // Flux lost per budget term, summed in float over the lane's recent steps (whatever particle
    // each step belonged to) and moved into double sums every kFlushSteps (8) steps: a few
    // particles' worth of float additions at most, rounding-level like the particle's own float
    // arithmetic.
    VF loss[kLossTerms][3];
    VF exit_sum[4][3];  // the same for R, R², T, T² of the particles that left
    VI events_done;     // events of the lane's ended particles
    VI k;               // at an interface: its index; in a medium: its layer
    VI in_medium, events, live, finish;
    bool touched[kLossTerms] = {};  // loss terms some lane may have booked in this block
    // Polarized runs: the lanes' polarization (physics/polarization.h); pol.flux points at w.
    PolarizationLanes<VF> pol;

    // Multiplies the flux of the lanes in m by `factor` (per channel) and books what is taken
    // under `term`.
    HWY_INLINE void Keep(MF m, int term, const VF factor[3]) {
        touched[term] = true;
        for (int c = 0; c < 3; ++c) {
            const VF kept = hn::Mul(w[c], factor[c]);
            loss[term][c] = hn::Add(loss[term][c], hn::IfThenElseZero(m, hn::Sub(w[c], kept)));
            w[c] = hn::IfThenElse(m, kept, w[c]);
        }
    }
    HWY_INLINE void Keep(MF m, int term, VF factor) {
        const VF f[3] = {factor, factor, factor};
        Keep(m, term, f);
    }
    HWY_INLINE MF Black() const {
        const DF df;
        const VF zero = hn::Zero(df);
        return hn::And(hn::And(hn::Eq(w[0], zero), hn::Eq(w[1], zero)), hn::Eq(w[2], zero));
    }
    HWY_INLINE void End(MF m, Finish why) {
        const DI di;
        finish = hn::IfThenElse(hn::RebindMask(di, m), hn::Set(di, why), finish);
    }
};

HWY_INLINE MF LaneIs(VI v, std::int32_t value) {
    const DF df;
    const DI di;
    return hn::RebindMask(df, hn::Eq(v, hn::Set(di, value)));
}

// Bit l set where lane l of m holds.
HWY_INLINE std::uint64_t MaskBits(MF m) {
    const DF df;
    std::uint8_t bytes[(kMaxLanes + 7) / 8] = {};
    hn::StoreMaskBits(df, m, bytes);
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < (hn::Lanes(df) + 7) / 8; ++i)
        bits |= std::uint64_t(bytes[i]) << (8 * i);
    return bits;
}

// ---- Interface events (goniophotometer.cpp trace_particle, `apply`) ----------------------------

// A rough or smooth dielectric (dielectric.h dielectric_event, the template the scalar kernel
// instantiates at one lane): the particle arrives along d (wi = −d). Polarized (kPolarized): the
// event's polarized form on the lanes' states; where the channels' states differ, its reweighting
// of the channels is booked with the base, as trace_particle does.
template <bool kPolarized>
HWY_INLINE void DielectricEvent(const DielectricInterface<float>& iface, MF m, LaneVectors& v,
                                VF uc, VF u1, VF u2, MF& degenerate) {
    const DF df;
    const V3 wi = {hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)};
    const InterfaceEventLanes<VF, MF> e = dielectric_event<VF, VecLane, kPolarized>(
        hn::Set(df, iface.eta), hn::Set(df, iface.inv_eta()), hn::Set(df, iface.alpha),
        iface.event_shape(), wi, uc, u1, u2, m, kPolarized ? &v.pol : nullptr);
    degenerate = hn::Or(degenerate, e.degenerate);
    const MF ok = hn::AndNot(e.degenerate, m);
    if constexpr (kPolarized)
        if (v.pol.channels == 3) v.Keep(ok, kLossBase, v.pol.factor);
    if (!iface.is_smooth()) v.Keep(ok, kLossMicro, e.shadowing);
    v.d = Select(ok, e.wo, v.d);
}

// The conductor's Fresnel factors per channel at the facet cosine (fresnel.h fresnel_conductor,
// the same template); channels with the same index share the computation.
struct ConductorFresnel {
    const ConductorInterface<float>& iface;
    HWY_INLINE void operator()(VF cos_theta, VF* factors) const {
        for (int c = 0; c < 3; ++c) {
            const bool same =
                c > 0 && iface.eta[c] == iface.eta[c - 1] && iface.k[c] == iface.k[c - 1];
            factors[c] =
                same ? factors[c - 1] : FresnelConductor(cos_theta, iface.eta[c], iface.k[c]);
        }
    }
};

// The conductor's reflection Mueller matrices per channel (polarization.h
// fresnel_conductor_mueller, the same template); channels with the same index share them.
struct ConductorMueller {
    const ConductorInterface<float>& iface;
    HWY_INLINE void operator()(VF cos_theta, InterfaceMueller<VF>* m) const {
        const DF df;
        for (int c = 0; c < 3; ++c) {
            const bool same =
                c > 0 && iface.eta[c] == iface.eta[c - 1] && iface.k[c] == iface.k[c - 1];
            m[c] = same ? m[c - 1]
                        : fresnel_conductor_mueller<VF, VecLane>(
                              cos_theta, hn::Set(df, iface.eta[c]), hn::Set(df, iface.k[c]));
        }
    }
};

// A rough or smooth conductor (conductor.h conductor_event, the same template): light from above
// only. Polarized: the Fresnel factors are the reflected fractions of the lanes' states.
template <bool kPolarized>
HWY_INLINE void ConductorEvent(const ConductorInterface<float>& iface, MF m, LaneVectors& v, VF u1,
                               VF u2, MF& degenerate) {
    const DF df;
    const V3 wi = {hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)};
    VF fresnel[3];
    InterfaceEventLanes<VF, MF> e;
    if constexpr (kPolarized)
        e = conductor_event<VF, VecLane>(
            hn::Set(df, iface.alpha), iface.is_smooth(), iface.uncorrelated_shadowing, wi, u1, u2,
            m, ConductorFresnel{iface}, fresnel, &v.pol, ConductorMueller{iface});
    else
        e = conductor_event<VF, VecLane>(hn::Set(df, iface.alpha), iface.is_smooth(),
                                         iface.uncorrelated_shadowing, wi, u1, u2, m,
                                         ConductorFresnel{iface}, fresnel);
    degenerate = hn::Or(degenerate, e.degenerate);
    const MF ok = hn::AndNot(e.degenerate, m);
    v.Keep(ok, kLossBase, fresnel);
    if (!iface.is_smooth()) v.Keep(ok, kLossMicro, e.shadowing);
    v.d = Select(ok, e.wo, v.d);
}

// A rough interface with multiple scattering on its microsurface (physics/microsurface_walk.h
// microsurface_walk, the template the scalar kernel instantiates at one lane): the lanes of m walk
// from facet to facet, every lane of the vector drawing its numbers while any walks, until each
// has escaped (its new direction; a conductor's exit carries its Fresnel factors, the rest
// absorbed by the base), met its facet cap (its flux lost to the microsurface) or a degeneracy
// (lost and counted, as a failed sample), as trace_particle books the walk. `weighted`: the exit's
// weight is booked on a dielectric too (polarized, the channels' states differing).
template <typename Facet>
HWY_INLINE void MicrosurfaceWalkEvent(float alpha, bool two_sided, const Facet& facet, MF m,
                                      LaneVectors& v, LaneRng& rng, int max_order, MF& degenerate,
                                      bool weighted = false) {
    const DF df;
    const VF zero = hn::Zero(df);
    const V3 wi = {hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)};
    auto draw = [&] { return rng.Uniform(); };
    const MicrosurfaceWalkLanes<VF, MF> walk = microsurface_walk<VF, VecLane>(
        hn::Set(df, alpha), wi, m, two_sided, facet, draw, max_order);
    degenerate = hn::Or(degenerate, walk.degenerate);
    if (!two_sided || weighted) v.Keep(walk.escaped, kLossBase, walk.weight);
    v.Keep(walk.capped, kLossMicro, zero);
    v.d = Select(walk.escaped, walk.wo, v.d);
}

template <bool kPolarized>
HWY_INLINE void DielectricWalkEvent(const DielectricInterface<float>& iface, MF m, LaneVectors& v,
                                    LaneRng& rng, int max_order, MF& degenerate) {
    const DF df;
    auto draw = [&] { return rng.Uniform(); };
    const MicrosurfaceDielectricFacet<VF, VecLane, decltype(draw), kPolarized> facet{
        hn::Set(df, iface.eta), hn::Set(df, iface.inv_eta()), draw, kPolarized ? &v.pol : nullptr};
    MicrosurfaceWalkEvent(iface.alpha, true, facet, m, v, rng, max_order, degenerate,
                          kPolarized && v.pol.channels == 3);
}

template <bool kPolarized>
HWY_INLINE void ConductorWalkEvent(const ConductorInterface<float>& iface, MF m, LaneVectors& v,
                                   LaneRng& rng, int max_order, MF& degenerate) {
    const ConductorFresnel fresnel{iface};
    if constexpr (kPolarized) {
        const ConductorMueller mueller{iface};
        const MicrosurfaceConductorFacet<VF, VecLane, ConductorFresnel, ConductorMueller> facet{
            fresnel, &v.pol, &mueller};
        MicrosurfaceWalkEvent(iface.alpha, false, facet, m, v, rng, max_order, degenerate);
    } else {
        const MicrosurfaceConductorFacet<VF, VecLane, ConductorFresnel> facet{fresnel};
        MicrosurfaceWalkEvent(iface.alpha, false, facet, m, v, rng, max_order, degenerate);
    }
}

// Lambertian (lambertian.h lambertian_event, the same template): cosine-distributed on wi's side,
// weight = albedo; it depolarizes (polarized runs).
template <bool kPolarized>
HWY_INLINE void LambertianEvent(const LambertianInterface<float>& iface, MF m, LaneVectors& v,
                                VF u1, VF u2, MF& degenerate) {
    const DF df;
    const MF bad = hn::And(m, hn::Eq(v.d.z, hn::Zero(df)));
    degenerate = hn::Or(degenerate, bad);
    const MF ok = hn::AndNot(bad, m);
    const V3 wo = lambertian_event<VF, VecLane>(hn::Neg(v.d.z), u1, u2);
    const VF albedo[3] = {hn::Set(df, iface.albedo[0]), hn::Set(df, iface.albedo[1]),
                          hn::Set(df, iface.albedo[2])};
    v.Keep(ok, kLossBase, albedo);
    v.d = Select(ok, wo, v.d);
    if constexpr (kPolarized) stokes_depolarize<VF, VecLane>(v.pol.stokes, 3, ok);
}

// ---- Media (physics/medium.h, the templates the scalar kernel instantiates at one lane) -------

// One scattering-medium step for the lanes in m (inside layer `layer`'s medium): a free flight,
// then either the crossing to the next interface or a scattering event (which depolarizes). The
// lanes draw their numbers as the template asks for them (every lane draws while any needs them).
template <bool kPolarized>
HWY_INLINE void ScatteringStep(const CompiledMedium<float>& med, MF m, LaneVectors& v,
                               LaneRng& rng) {
    const DF df;
    const DI di;
    auto uniform = [&] { return rng.Uniform(); };
    const MediumFlightLanes<VF, MF> flight =
        medium_free_flight<VF, VecLane>(med, v.d, v.w, v.depth, uniform);
    const MF leaves = hn::And(m, flight.leaves);
    const MF scatters = hn::AndNot(flight.leaves, m);
    V3 d_new = v.d;
    VF phase[3];
    if (medium_scatter<VF, VecLane>(med, v.d, flight.p, scatters, uniform, d_new, phase)) {
        VF factor[3];
        for (int c = 0; c < 3; ++c)
            factor[c] =
                hn::IfThenElse(scatters, hn::Mul(flight.factor[c], phase[c]), flight.factor[c]);
        v.Keep(m, kLossMedium, factor);
        v.depth = hn::IfThenElse(scatters, flight.depth, v.depth);
        v.d = Select(scatters, d_new, v.d);
        // A scattering event depolarizes (docs/physics.md §8).
        if constexpr (kPolarized) stokes_depolarize<VF, VecLane>(v.pol.stokes, 3, scatters);
        v.events = hn::IfThenElse(hn::RebindMask(di, scatters), hn::Add(v.events, hn::Set(di, 1)),
                                  v.events);
    } else {
        v.Keep(m, kLossMedium, flight.factor);
    }
    // Leaving lanes arrive at the interface above (k) or below (k + 1).
    const MI leave_i = hn::RebindMask(di, leaves);
    const MI down = hn::RebindMask(di, hn::Lt(v.d.z, hn::Zero(df)));
    v.k = hn::IfThenElse(hn::And(leave_i, down), hn::Add(v.k, hn::Set(di, 1)), v.k);
    v.in_medium = hn::IfThenElseZero(hn::Not(leave_i), v.in_medium);
}

// ---- Binning: on vectors where provably the grid's bin, else the grid's rule per exit ---------

// acos(x), x ∈ [−1, 1]: Abramowitz & Stegun 1964, Eq. 4.4.46 (|ε| ≤ 2·10^-8 on [0, 1]) with
// acos(−x) = π − acos(x). In float its error is that of the rounding, at most 4.3e-7 rad
// (measured on 4·10^6 points of [−1, 1] against the double acos; the float operations bound it by
// about 5e-7: ulp-level square root, polynomial and product, π − r rounded once).
constexpr double kAcosErrorBound = 5e-7;
HWY_INLINE VF Acos(VF x) {
    const DF df;
    const VF a = hn::Abs(x);
    VF p = hn::MulAdd(hn::Set(df, -0.0012624911f), a, hn::Set(df, 0.0066700901f));
    p = hn::MulAdd(p, a, hn::Set(df, -0.0170881256f));
    p = hn::MulAdd(p, a, hn::Set(df, 0.0308918810f));
    p = hn::MulAdd(p, a, hn::Set(df, -0.0501743046f));
    p = hn::MulAdd(p, a, hn::Set(df, 0.0889789874f));
    p = hn::MulAdd(p, a, hn::Set(df, -0.2145988016f));
    p = hn::MulAdd(p, a, hn::Set(df, 1.5707963050f));
    const VF r = hn::Mul(hn::Sqrt(hn::ZeroIfNegative(hn::Sub(hn::Set(df, 1.f), a))), p);
    return hn::IfThenElse(hn::Lt(x, hn::Zero(df)), hn::Sub(hn::Set(df, kPi<float>), r), r);
}

// The grid's bins on vectors. HemisphereGrid::bin_of's rule puts x = cos θ (or the folded cos φ,
// x/r in double) in bin b when edge[b] ≥ x > edge[b + 1], edge[b] = cos(b Δ): the bin of the
// angle acos(x), floor(acos(x)/Δ) clamped to [0, n − 1], wherever acos(x) is not within the edges'
// double rounding (~1e-16) of a multiple of Δ. The lanes compute the angle in float, t = Acos(x)/Δ
// in bins, with an error below η bins; where t − η and t + η fall in the same bin, that bin is
// bin_of's. The error bound η:
//   θ: x = min(|z|, 1) is bin_of's own; Acos's kAcosErrorBound, and t's own rounding (n ulps);
//   φ: x/r in float is within 2^-23 ≈ 1.2e-7 of bin_of's double x/r (two roundings in x² + y²,
//      halved by the square root, one in the square root and one in the quotient; 2e-7 is
//      used). To land more than η beyond an edge φe the float angle must move the cosine by at
//      least sin φe · η Δφ, and an inner edge has sin φe ≥ sin Δφ; the rest as for θ.
// Both get a factor of 4 of safety. A lane whose bin is not certain (in practice 1 exit in 10³ on
// the default grid) or whose r is below 1e-15 (x² + y² subnormal; bin_of's r = 0 is bin 0) takes
// bin_of itself; tests/simulator/kernel_simd_test.cpp checks the lanes against bin_of at and near
// every edge of several grids.
struct VectorBins {
    int n_theta, n_phi;
    float to_theta, to_phi;    // bins per radian
    float eta_theta, eta_phi;  // the error bounds, in bins
    explicit VectorBins(const HemisphereGrid& grid)
        : n_theta(grid.n_theta()),
          n_phi(grid.n_phi()),
          to_theta(float(grid.n_theta() / (0.5 * kPi<double>))),
          to_phi(float(grid.n_phi() / kPi<double>)) {
        const double ulp = 0x1p-23;  // a float's relative spacing, at most
        const double d_phi = kPi<double> / n_phi;
        eta_theta = float(4 * (kAcosErrorBound * to_theta + n_theta * ulp));
        eta_phi = float(
            4 * ((kAcosErrorBound + 2e-7 / std::sin(std::min(d_phi, kPi<double> / 2))) * to_phi +
                 n_phi * ulp));
    }
};

// The θ and φ bins of the lanes' directions d (unit vectors), stored per lane; bit l of the
// result is set where lane l's pair is certainly bin_of's (VectorBins says when).
HWY_INLINE std::uint64_t LaneBins(const VectorBins& g, const V3& d, std::int32_t* theta_bin,
                                  std::int32_t* phi_bin) {
    const DF df;
    const DI di;
    const VF one = hn::Set(df, 1.f);
    const VF cos_theta = hn::Min(hn::Abs(d.z), one);
    const VF r = hn::Sqrt(hn::MulAdd(d.x, d.x, hn::Mul(d.y, d.y)));
    const MF resolved = hn::Gt(r, hn::Set(df, 1e-15f));
    const VF cos_phi =
        hn::Min(hn::Max(hn::Div(d.x, hn::IfThenElse(resolved, r, one)), hn::Set(df, -1.f)), one);
    // The bin of t − η and whether t + η shares it; truncation is the floor here (t ≥ 0), and
    // a negative t − η is clamped to bin 0 as floor would be.
    auto bin = [&](VF t, float eta, int n, std::int32_t* out) {
        const VI last = hn::Set(di, n - 1);
        const VI lo =
            hn::Min(hn::Max(hn::ConvertTo(di, hn::Sub(t, hn::Set(df, eta))), hn::Zero(di)), last);
        const VI hi =
            hn::Min(hn::Max(hn::ConvertTo(di, hn::Add(t, hn::Set(df, eta))), hn::Zero(di)), last);
        hn::Store(lo, di, out);
        return hn::RebindMask(df, hn::Eq(lo, hi));
    };
    const MF theta_known =
        bin(hn::Mul(Acos(cos_theta), hn::Set(df, g.to_theta)), g.eta_theta, g.n_theta, theta_bin);
    const MF phi_known =
        bin(hn::Mul(Acos(cos_phi), hn::Set(df, g.to_phi)), g.eta_phi, g.n_phi, phi_bin);
    return MaskBits(hn::And(resolved, hn::And(theta_known, phi_known)));
}

// ---- The block ----

using DD = hn::Repartition<double, DF>;
using DL = hn::RebindToSigned<DD>;
using VD = hn::Vec<DD>;
using VL = hn::Vec<DL>;

// A particle past its first event, waiting for a lane.
struct Waiting {
    float d[3], w[3], depth;
    std::int32_t k, in_medium, events;
    std::uint64_t state, inc;
};
using Queue = std::vector<Waiting>;
// Its polarization (polarized runs), kept beside the queue: the frame's x axis and (q, u, v) per
// channel.
struct WaitingPolarization {
    float x[3], q[3], u[3], v[3];
};

struct Scratch {
    std::vector<std::uint64_t> state, inc;
    Queue queue;
    std::vector<WaitingPolarization> queue_pol;
    void resize(std::size_t n) {
        state.resize(n);
        inc.resize(n);
        queue.reserve(n);
    }
};

// The lanes' polarization into per-lane arrays and back (the queue's refills).
struct PolarizationArrays {
    HWY_ALIGN float x[3][kMaxLanes], q[3][kMaxLanes], u[3][kMaxLanes], v[3][kMaxLanes];
    HWY_INLINE void Store(const StokesLanes<VF>& s) {
        const DF df;
        hn::Store(s.x.x, df, x[0]);
        hn::Store(s.x.y, df, x[1]);
        hn::Store(s.x.z, df, x[2]);
        for (int c = 0; c < 3; ++c) {
            hn::Store(s.q[c], df, q[c]);
            hn::Store(s.u[c], df, u[c]);
            hn::Store(s.v[c], df, v[c]);
        }
    }
    HWY_INLINE void Load(MF m, StokesLanes<VF>& s) const {
        const DF df;
        s.x = Select(m, V3{hn::Load(df, x[0]), hn::Load(df, x[1]), hn::Load(df, x[2])}, s.x);
        for (int c = 0; c < 3; ++c) {
            s.q[c] = hn::IfThenElse(m, hn::Load(df, q[c]), s.q[c]);
            s.u[c] = hn::IfThenElse(m, hn::Load(df, u[c]), s.u[c]);
            s.v[c] = hn::IfThenElse(m, hn::Load(df, v[c]), s.v[c]);
        }
    }
    WaitingPolarization Lane(std::size_t l) const {
        WaitingPolarization w;
        for (int i = 0; i < 3; ++i) {
            w.x[i] = x[i][l];
            w.q[i] = q[i][l];
            w.u[i] = u[i][l];
            w.v[i] = v[i][l];
        }
        return w;
    }
    void SetLane(std::size_t l, const WaitingPolarization& w) {
        for (int i = 0; i < 3; ++i) {
            x[i][l] = w.x[i];
            q[i][l] = w.q[i];
            u[i][l] = w.u[i];
            v[i][l] = w.v[i];
        }
    }
};

constexpr int kFlushSteps = 8;  // steps between moves of the lanes' float sums to double

// Per-lane double sums of what ended particles carry (budget terms, R and T with their squares)
// and their event counts; reduced in lane order at the end of the block.
struct LaneSums {
    static constexpr int kTerms = kLossTerms + 4;  // losses, then R, R², T, T² (per channel)
    VD sum[kTerms][3][2];
    VL events[2];

    HWY_INLINE void zero() {
        const DD dd;
        const DL dl;
        for (auto& term : sum)
            for (auto& channel : term)
                channel[0] = channel[1] = hn::Zero(dd);
        events[0] = events[1] = hn::Zero(dl);
    }
    // Adds x (zero in lanes that must not count) to sum[t][c], in double.
    HWY_INLINE void add(int t, int c, VF x, bool squared = false) {
        const DD dd;
        const hn::Half<DF> dfh;
        VD lo = hn::PromoteTo(dd, hn::LowerHalf(dfh, x));
        VD hi = hn::PromoteTo(dd, hn::UpperHalf(dfh, x));
        if (squared) {
            lo = hn::Mul(lo, lo);
            hi = hn::Mul(hi, hi);
        }
        sum[t][c][0] = hn::Add(sum[t][c][0], lo);
        sum[t][c][1] = hn::Add(sum[t][c][1], hi);
    }
    HWY_INLINE void add_events(VI e) {
        const DL dl;
        const hn::Half<DI> dih;
        events[0] = hn::Add(events[0], hn::PromoteTo(dl, hn::LowerHalf(dih, e)));
        events[1] = hn::Add(events[1], hn::PromoteTo(dl, hn::UpperHalf(dih, e)));
    }
    // Lane order, fixed: the block's sums do not depend on anything but the block.
    void reduce(BlockBudget& block, std::uint64_t& events_total) const {
        const DD dd;
        const DL dl;
        const std::size_t half = hn::Lanes(dd);
        HWY_ALIGN double buf[kMaxLanes];
        HWY_ALIGN std::int64_t ibuf[kMaxLanes];
        auto total = [&](const VD(&v)[2]) {
            hn::Store(v[0], dd, buf);
            hn::Store(v[1], dd, buf + half);
            double t = 0;
            for (std::size_t l = 0; l < 2 * half; ++l)
                t += buf[l];
            return t;
        };
        for (int c = 0; c < 3; ++c) {
            for (int t = 0; t < kLossTerms; ++t)
                block.term[int(BudgetTerm::AbsorbedMedium) + t][c] += total(sum[t][c]);
            block.term[int(BudgetTerm::Reflected)][c] += total(sum[kLossTerms][c]);
            block.reflected_sq[c] += total(sum[kLossTerms + 1][c]);
            block.term[int(BudgetTerm::Transmitted)][c] += total(sum[kLossTerms + 2][c]);
            block.transmitted_sq[c] += total(sum[kLossTerms + 3][c]);
        }
        hn::Store(events[0], dl, ibuf);
        hn::Store(events[1], dl, ibuf + half);
        for (std::size_t l = 0; l < 2 * half; ++l)
            events_total += std::uint64_t(ibuf[l]);
    }
};

// Written once for both: kPolarized = false is the unpolarized kernel, with none of it.
template <bool kPolarized>
void TraceBlock(const BlockJob& job, Tally& tally, BlockBudget& block) {
    const DF df;
    const DI di;
    const std::size_t n_lanes = hn::Lanes(df);
    const CompiledStack<float>& stack = *job.stack;
    const HemisphereGrid& grid = *job.grid;
    const int n_layers = int(stack.layers.size());
    const VF zero = hn::Zero(df), one = hn::Set(df, 1.f);

    thread_local Scratch scratch;
    scratch.resize(job.count);
    SeedParticles(job.seed, job.stream, job.first, job.count, scratch.state.data(),
                  scratch.inc.data());

    LaneSums sums;
    sums.zero();
    std::uint64_t degenerate = 0;
    bool left[2] = {false, false};  // some particle was reflected / transmitted in this block

    // Moves a lane set's float sums into the double ones.
    auto flush = [&](LaneVectors& v) {
        for (int c = 0; c < 3; ++c) {
            for (int t = 0; t < kLossTerms; ++t)
                if (v.touched[t]) {
                    sums.add(t, c, v.loss[t][c]);
                    v.loss[t][c] = zero;
                }
            for (int e = 0; e < 4; ++e)
                if (left[e / 2]) {
                    sums.add(kLossTerms + e, c, v.exit_sum[e][c]);
                    v.exit_sum[e][c] = zero;
                }
        }
    };
    auto clear = [&](LaneVectors& v) {
        v.d = {zero, zero, zero};
        v.depth = zero;
        for (int c = 0; c < 3; ++c)
            v.w[c] = zero;
        for (auto& term : v.loss)
            for (auto& channel : term)
                channel = zero;
        for (auto& term : v.exit_sum)
            for (auto& channel : term)
                channel = zero;
        v.k = v.in_medium = v.events = v.events_done = v.live = v.finish = hn::Zero(di);
        if constexpr (kPolarized) {
            v.pol.stokes = stokes_incident<VF, VecLane>(
                {hn::Set(df, -job.wi.x), hn::Set(df, -job.wi.y), hn::Set(df, -job.wi.z)},
                job.incident_stokes);
            v.pol.channels = stack.polarization_channels;
            v.pol.flux = v.w;
        }
    };

    // ---- One interface event of the lanes in `going`, all at interface `group` ----
    auto interface_step = [&](LaneVectors& v, LaneRng& rng, int group, MF going) {
        v.events =
            hn::IfThenElse(hn::RebindMask(di, going), hn::Add(v.events, hn::Set(di, 1)), v.events);
        MF degenerate_event = hn::FirstN(df, 0);  // all false
        const CompiledLayer<float>& layer = stack.layers[group];
        const bool dielectric = layer.type == InterfaceType::Dielectric;
        switch (layer.type) {
            case InterfaceType::Dielectric: {
                if (layer.multiple) {
                    DielectricWalkEvent<kPolarized>(layer.dielectric, going, v, rng,
                                                    stack.max_microsurface_order, degenerate_event);
                    break;
                }
                const VF uc = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
                DielectricEvent<kPolarized>(layer.dielectric, going, v, uc, u1, u2,
                                            degenerate_event);
                break;
            }
            case InterfaceType::Conductor: {
                if (layer.multiple) {
                    ConductorWalkEvent<kPolarized>(layer.conductor, going, v, rng,
                                                   stack.max_microsurface_order, degenerate_event);
                    break;
                }
                const VF u1 = rng.Uniform(), u2 = rng.Uniform();
                ConductorEvent<kPolarized>(layer.conductor, going, v, u1, u2, degenerate_event);
                break;
            }
            case InterfaceType::Lambertian: {
                const VF u1 = rng.Uniform(), u2 = rng.Uniform();
                LambertianEvent<kPolarized>(layer.lambertian, going, v, u1, u2, degenerate_event);
                break;
            }
        }
        // A failed sample loses the flux to the microsurface; an exactly grazing new direction is
        // lost to the microsurface (dielectric) or the base (opaque), as in trace_particle.
        const MF grazing = hn::AndNot(degenerate_event, hn::And(going, hn::Eq(v.d.z, zero)));
        const MF lost = hn::Or(degenerate_event, grazing);
        v.Keep(dielectric ? lost : degenerate_event, kLossMicro, zero);
        if (!dielectric) v.Keep(grazing, kLossBase, zero);
        degenerate += hn::CountTrue(df, lost);
        const MF black = hn::And(going, v.Black());
        const MF ends = hn::Or(black, lost);
        v.End(ends, kEnded);
        const MF continues = hn::AndNot(ends, going);

        // Exits, then the medium behind: below the interface going down, above it going up.
        const MF up = hn::Gt(v.d.z, zero);
        const MF goes_up = hn::And(continues, up), goes_down = hn::AndNot(up, continues);
        MF moves_up = goes_up, moves_down = goes_down;
        if (group == 0) {
            v.End(goes_up, kReflected);
            moves_up = hn::FirstN(df, 0);
        }
        if (group == n_layers - 1) {
            v.End(goes_down, kTransmitted);
            moves_down = hn::FirstN(df, 0);
        }
        for (int side = 0; side < 2; ++side) {
            const MF moving = side == 0 ? moves_up : moves_down;
            const int medium_layer = side == 0 ? group - 1 : group;
            const int k_next = side == 0 ? group - 1 : group + 1;
            if (hn::AllFalse(df, moving)) continue;
            const CompiledMedium<float>& med = stack.layers[medium_layer].medium;
            if (med.scatters) {
                // Enters the medium: its free flights are later steps.
                const auto mi = hn::RebindMask(di, moving);
                v.in_medium = hn::IfThenElse(mi, hn::Set(di, 1), v.in_medium);
                v.k = hn::IfThenElse(mi, hn::Set(di, medium_layer), v.k);
                v.depth = hn::IfThenElse(moving, hn::Set(df, side == 0 ? 1.f : 0.f), v.depth);
                continue;
            }
            if (med.absorbs) {
                // Pure absorption: Beer–Lambert along the straight path (physics/medium.h).
                VF transmittance[3];
                beer_lambert_transmittance<VF, VecLane>(med.tau_a, hn::Div(one, hn::Abs(v.d.z)),
                                                        transmittance);
                v.Keep(moving, kLossMedium, transmittance);
                v.End(hn::And(moving, v.Black()), kEnded);
            }
            v.k = hn::IfThenElse(hn::RebindMask(di, moving), hn::Set(di, k_next), v.k);
        }
    };

    // ---- Particles that ended in a step: sums on vectors, exits binned and tallied in lane
    // order; on_lane(l) then runs for every ended lane, in lane order ----
    HWY_ALIGN std::int32_t finish[kMaxLanes];
    HWY_ALIGN float w_out[3][kMaxLanes];
    HWY_ALIGN std::int32_t theta_bin[kMaxLanes], phi_bin[kMaxLanes];
    const VectorBins vector_bins(grid);
    HWY_ALIGN float d_out[3][kMaxLanes];
    // Polarized runs with Stokes tallies: the exits' Stokes vectors in their bin frames.
    [[maybe_unused]] HWY_ALIGN float stokes_out[3][4][kMaxLanes];
    const bool stokes_tallies = kPolarized && job.stokes_tallies;
    auto end_particles = [&](LaneVectors& v, MF ended, auto&& on_lane) {
        const MF reflected = LaneIs(v.finish, kReflected);
        const MF transmitted = LaneIs(v.finish, kTransmitted);
        for (int side = 0; side < 2; ++side) {
            const MF leaves = side == 0 ? reflected : transmitted;
            if (hn::AllFalse(df, leaves)) continue;
            left[side] = true;
            for (int c = 0; c < 3; ++c) {
                const VF w_out_c = hn::IfThenElseZero(leaves, v.w[c]);
                v.exit_sum[2 * side][c] = hn::Add(v.exit_sum[2 * side][c], w_out_c);
                v.exit_sum[2 * side + 1][c] =
                    hn::MulAdd(w_out_c, w_out_c, v.exit_sum[2 * side + 1][c]);
            }
        }
        v.events_done =
            hn::Add(v.events_done, hn::IfThenElseZero(hn::RebindMask(di, ended), v.events));
        const MF exits = hn::Or(reflected, transmitted);
        hn::Store(v.finish, di, finish);
        std::uint64_t known_bins = 0;
        if (!hn::AllFalse(df, exits)) {
            known_bins = LaneBins(vector_bins, v.d, theta_bin, phi_bin);
            if ((MaskBits(exits) & ~known_bins) != 0) {
                hn::Store(v.d.x, df, d_out[0]);
                hn::Store(v.d.y, df, d_out[1]);
                hn::Store(v.d.z, df, d_out[2]);
            }
            for (int c = 0; c < 3; ++c)
                hn::Store(v.w[c], df, w_out[c]);
            if constexpr (kPolarized)
                if (stokes_tallies) {
                    VF stokes[3][4];
                    stokes_in_bin_frame<VF, VecLane>(v.pol.stokes, v.d, v.w, v.pol.channels, exits,
                                                     stokes);
                    for (int c = 0; c < 3; ++c)
                        for (int k = 0; k < 4; ++k)
                            hn::Store(stokes[c][k], df, stokes_out[c][k]);
                    hn::Store(v.d.y, df, d_out[1]);
                }
        }
        // Over the set bits of the mask: which lanes ended is random, a branch per lane would be
        // mispredicted half of the time.
        for (std::uint64_t ended_bits = MaskBits(ended); ended_bits != 0;
             ended_bits &= ended_bits - 1) {
            const std::size_t l = std::size_t(std::countr_zero(ended_bits));
            const std::int32_t why = finish[l];
            if (why != kEnded) {
                const Rgbf w(w_out[0][l], w_out[1][l], w_out[2][l]);
                const std::size_t bin =
                    (known_bins >> l & 1) != 0
                        ? std::size_t(theta_bin[l]) * std::size_t(vector_bins.n_phi) +
                              std::size_t(phi_bin[l])
                        : grid.bin_of(Vec3f(d_out[0][l], d_out[1][l], d_out[2][l]));
                tally.exit((why == kTransmitted ? grid.size() : 0) + bin, w);
                if constexpr (kPolarized)
                    if (stokes_tallies) {
                        float s[3][4];
                        for (int c = 0; c < 3; ++c)
                            for (int k = 0; k < 4; ++k)
                                s[c][k] = stokes_out[c][k][l];
                        tally.exit_stokes((why == kTransmitted ? grid.size() : 0) + bin,
                                          d_out[1][l] < 0 ? 1 : 0, s);
                    }
            }
            on_lane(l);
        }
    };

    // ---- First events, on full vectors ----
    // Every particle starts with the same event (interface 0 met from above), so the block's
    // particles take it in order, all lanes busy; the survivors wait in a queue, in particle
    // order. The main loop then hands out particles that are past their first event: the fresh
    // particles of a two-interface stack join the others in phase (at the lower interface)
    // instead of idling for a step.
    Queue& queue = scratch.queue;
    queue.clear();
    [[maybe_unused]] std::vector<WaitingPolarization>& queue_pol = scratch.queue_pol;
    if constexpr (kPolarized) queue_pol.clear();
    [[maybe_unused]] PolarizationArrays staged_pol;  // the lanes' states, staged or stored
    {
        LaneVectors p;
        clear(p);
        [[maybe_unused]] const StokesLanes<VF> incident = p.pol.stokes;
        LaneRng prng;
        HWY_ALIGN float qd[3][kMaxLanes], qw[3][kMaxLanes], qdepth[kMaxLanes];
        HWY_ALIGN std::int32_t qk[kMaxLanes], qin[kMaxLanes], qevents[kMaxLanes];
        std::uint64_t chunks = 0;
        for (std::uint64_t base = 0; base < job.count; base += n_lanes) {
            const std::size_t n = std::size_t(std::min<std::uint64_t>(n_lanes, job.count - base));
            for (std::size_t l = 0; l < n_lanes; ++l) {
                prng.state[l] = l < n ? scratch.state[base + l] : 0;
                prng.inc[l] = l < n ? scratch.inc[base + l] : 1;
            }
            prng.SyncIn();
            const MF going = hn::FirstN(df, n);
            p.d = {hn::Set(df, -job.wi.x), hn::Set(df, -job.wi.y), hn::Set(df, -job.wi.z)};
            for (int c = 0; c < 3; ++c)
                p.w[c] = hn::IfThenElseZero(going, one);
            p.k = p.in_medium = p.events = p.finish = hn::Zero(di);
            p.depth = zero;
            if constexpr (kPolarized) p.pol.stokes = incident;
            interface_step(p, prng, 0, going);
            const MF ended = hn::RebindMask(df, hn::Ne(p.finish, hn::Zero(di)));
            if (!hn::AllFalse(df, ended)) end_particles(p, ended, [](std::size_t) {});
            prng.SyncOut();
            const MF waits = hn::AndNot(ended, going);
            hn::Store(p.d.x, df, qd[0]);
            hn::Store(p.d.y, df, qd[1]);
            hn::Store(p.d.z, df, qd[2]);
            for (int c = 0; c < 3; ++c)
                hn::Store(p.w[c], df, qw[c]);
            hn::Store(p.depth, df, qdepth);
            hn::Store(p.k, di, qk);
            hn::Store(p.in_medium, di, qin);
            hn::Store(p.events, di, qevents);
            if constexpr (kPolarized) staged_pol.Store(p.pol.stokes);
            for (std::uint64_t bits = MaskBits(waits); bits != 0; bits &= bits - 1) {
                const std::size_t l = std::size_t(std::countr_zero(bits));
                if constexpr (kPolarized) queue_pol.push_back(staged_pol.Lane(l));
                queue.push_back({{qd[0][l], qd[1][l], qd[2][l]},
                                 {qw[0][l], qw[1][l], qw[2][l]},
                                 qdepth[l],
                                 qk[l],
                                 qin[l],
                                 qevents[l],
                                 prng.state[l],
                                 prng.inc[l]});
            }
            if (++chunks % kFlushSteps == 0) flush(p);
        }
        flush(p);
        sums.add_events(p.events_done);
    }

    // ---- The main loop ----
    LaneRng rng;
    HWY_ALIGN float sd[3][kMaxLanes], sw[3][kMaxLanes], sdepth[kMaxLanes];
    HWY_ALIGN std::int32_t sk[kMaxLanes], s_in[kMaxLanes], sevents[kMaxLanes], live[kMaxLanes];
    std::size_t next = 0;  // the queue's next particle
    // Stages the queue's next particle for lane l, or retires the lane when none is left.
    auto take_particle = [&](std::size_t l) {
        if (next < queue.size()) {
            if constexpr (kPolarized) staged_pol.SetLane(l, queue_pol[next]);
            const Waiting& q = queue[next++];
            for (int i = 0; i < 3; ++i) {
                sd[i][l] = q.d[i];
                sw[i][l] = q.w[i];
            }
            sdepth[l] = q.depth;
            sk[l] = q.k;
            s_in[l] = q.in_medium;
            sevents[l] = q.events;
            rng.state[l] = q.state;
            rng.inc[l] = q.inc;
            live[l] = 1;
        } else {
            for (int i = 0; i < 3; ++i)
                sw[i][l] = 0.f;
            sd[2][l] = -1.f;
            sdepth[l] = 0.f;
            sk[l] = s_in[l] = sevents[l] = 0;
            rng.state[l] = 0;
            rng.inc[l] = 1;
            live[l] = 0;
        }
    };
    LaneVectors v;
    clear(v);
    // The staged particles into the lanes of `fresh`.
    auto restart = [&](MF fresh) {
        const auto fresh_i = hn::RebindMask(di, fresh);
        v.d = Select(fresh, V3{hn::Load(df, sd[0]), hn::Load(df, sd[1]), hn::Load(df, sd[2])}, v.d);
        for (int c = 0; c < 3; ++c)
            v.w[c] = hn::IfThenElse(fresh, hn::Load(df, sw[c]), v.w[c]);
        v.depth = hn::IfThenElse(fresh, hn::Load(df, sdepth), v.depth);
        v.k = hn::IfThenElse(fresh_i, hn::Load(di, sk), v.k);
        v.in_medium = hn::IfThenElse(fresh_i, hn::Load(di, s_in), v.in_medium);
        v.events = hn::IfThenElse(fresh_i, hn::Load(di, sevents), v.events);
        v.live = hn::IfThenElse(fresh_i, hn::Load(di, live), v.live);
        if constexpr (kPolarized) staged_pol.Load(fresh, v.pol.stokes);
    };
    for (std::size_t l = 0; l < n_lanes; ++l)
        take_particle(l);
    rng.SyncIn();
    restart(hn::FirstN(df, n_lanes));

    int steps_since_flush = 0;
    while (true) {
        if (++steps_since_flush == kFlushSteps) {
            flush(v);
            steps_since_flush = 0;
        }
        v.finish = hn::Zero(di);
        const MF live_mask = hn::RebindMask(df, hn::Ne(v.live, hn::Zero(di)));
        if (hn::AllFalse(df, live_mask)) break;
        // One group of lanes steps: those at one interface, or those inside one scattering
        // medium, whichever group is largest (ties to the first). The lanes of a two-interface
        // stack then alternate between its interfaces in phase, so each step runs one
        // interface's code on nearly full vectors.
        const MF in_med = hn::And(live_mask, hn::RebindMask(df, hn::Ne(v.in_medium, hn::Zero(di))));
        const MF at_interface = hn::AndNot(in_med, live_mask);
        int group = 0;
        bool group_is_medium = false;
        std::size_t group_size = 0;
        for (int j = 0; j < n_layers; ++j) {
            const std::size_t at_j = hn::CountTrue(df, hn::And(at_interface, LaneIs(v.k, j)));
            if (at_j > group_size) {
                group = j;
                group_size = at_j;
            }
        }
        if (!hn::AllFalse(df, in_med))
            for (int j = 0; j < n_layers; ++j) {
                if (!stack.layers[j].medium.scatters) continue;
                const std::size_t in_j = hn::CountTrue(df, hn::And(in_med, LaneIs(v.k, j)));
                if (in_j > group_size) {
                    group = j;
                    group_is_medium = true;
                    group_size = in_j;
                }
            }
        const MF stepped = hn::And(group_is_medium ? in_med : at_interface, LaneIs(v.k, group));

        // Cut-off (trace_particle: checked before every event).
        const MF cut =
            hn::And(stepped, hn::RebindMask(df, hn::Gt(v.events, hn::Set(di, job.max_events - 1))));
        if (!hn::AllFalse(df, cut)) v.Keep(cut, kLossCutOff, zero);
        v.End(cut, kEnded);
        const MF going = hn::AndNot(cut, stepped);

        if (group_is_medium) {
            // ---- A scattering-medium step ----
            ScatteringStep<kPolarized>(stack.layers[group].medium, going, v, rng);
            v.End(hn::And(going, v.Black()), kEnded);
        } else {
            interface_step(v, rng, group, going);
        }
        const MF ended = hn::RebindMask(df, hn::Ne(v.finish, hn::Zero(di)));
        if (hn::AllFalse(df, ended)) continue;
        rng.SyncOut();
        end_particles(v, ended, take_particle);
        rng.SyncIn();
        restart(ended);
    }
    flush(v);
    sums.add_events(v.events_done);
    sums.reduce(block, tally.sums.events);
    tally.sums.degenerate += degenerate;
}

void TraceBlockSimd(const BlockJob& job, Tally& tally, BlockBudget& block) {
    if (job.stack->polarization)
        TraceBlock<true>(job, tally, block);
    else
        TraceBlock<false>(job, tally, block);
}

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

// Lane tests of the interface events and the medium step (tests/physics/lanes_test.cpp): each
// entry j of the inputs is one lane; the outputs as the header kernel_simd.h describes them.
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
            e = dielectric_event<VF, VecLane>(hn::Set(df, params[0]), hn::Set(df, 1.f / params[0]),
                                              hn::Set(df, params[1]), shape, w, uc, u1, u2, active);
        } else if (kind ==
                   1) {  // conductor: params alpha, eta[3], k[3]; flags smooth, uncorrelated
            ConductorInterface<float> iface{Rgbf(params[1], params[2], params[3]),
                                            Rgbf(params[4], params[5], params[6]), params[0]};
            VF f[3];
            e = conductor_event<VF, VecLane>(hn::Set(df, params[0]), flags[0] != 0, flags[1] != 0,
                                             w, u1, u2, active, ConductorFresnel{iface}, f);
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
                hn::Set(df, params[0]), hn::Set(df, 1.f / params[0]), hn::Set(df, params[1]), shape,
                w, uc, u1, u2, active, &pol);
        } else {
            ConductorInterface<float> iface{Rgbf(params[1], params[2], params[3]),
                                            Rgbf(params[4], params[5], params[6]), params[0]};
            VF f[3];
            e = conductor_event<VF, VecLane>(hn::Set(df, params[0]), flags[0] != 0, flags[1] != 0,
                                             w, u1, u2, active, ConductorFresnel{iface}, f, &pol,
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
        hn::Store(ggx_lambda<VF, VecLane>(hn::Mul(a, a), wv.x, wv.y, wv.z), df, out[0]);
        const V3 m = ggx_sample_visible_normal_complete<VF, VecLane>(a, wv, hn::Load(df, in[3]),
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
            r = microsurface_walk<VF, VecLane>(hn::Set(df, alpha), wi_v, m, true, facet, draw,
                                               max_order);
        } else {
            auto fresnel = [&](VF cos_w_m, VF* factors) {
                for (int c = 0; c < 3; ++c)
                    factors[c] = FresnelConductor(cos_w_m, co_face.eta[c], co_face.k[c]);
            };
            const MicrosurfaceConductorFacet<VF, VecLane, decltype(fresnel)> facet{fresnel};
            r = microsurface_walk<VF, VecLane>(hn::Set(df, alpha), wi_v, m, false, facet, draw,
                                               max_order);
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

}  // namespace HWY_NAMESPACE
}  // namespace lamina
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace lamina {

HWY_EXPORT(TraceBlockSimd);
HWY_EXPORT(PcgDrawsForTest);
HWY_EXPORT(CosSin2PiForTest);
HWY_EXPORT(SmithRefractionEscapeForTest);
HWY_EXPORT(LaneBinsForTest);
HWY_EXPORT(FresnelDielectricForTest);
HWY_EXPORT(FresnelConductorForTest);
HWY_EXPORT(HenyeyGreensteinForTest);
HWY_EXPORT(MicrosurfaceWalkForTest);
HWY_EXPORT(GgxLanesForTest);
HWY_EXPORT(InterfaceEventsForTest);
HWY_EXPORT(MediumStepForTest);
HWY_EXPORT(FresnelMuellerForTest);
HWY_EXPORT(PolarizedEventsForTest);

void trace_block_simd(const BlockJob& job, Tally& tally, BlockBudget& block) {
    HWY_DYNAMIC_DISPATCH(TraceBlockSimd)(job, tally, block);
}

void select_simd_target() {
    static const bool done = [] {
        const char* wanted = std::getenv("LAMINA_SIMD_TARGET");
        if (wanted == nullptr || *wanted == '\0') return true;
        std::string names;
        // Targets are bits, better ones lower: keep the wanted one and those below it.
        for (std::int64_t targets = HWY_TARGETS; targets != 0; targets &= targets - 1) {
            const std::int64_t bit = targets & -targets;
            if (std::string(hwy::TargetName(bit)) == wanted) {
                if ((hwy::SupportedTargets() & bit) == 0)
                    throw InputError("environment", "LAMINA_SIMD_TARGET",
                                     fmt::format("this CPU does not support {}", wanted));
                hwy::DisableTargets(HWY_TARGETS & (bit - 1));
                return true;
            }
            names += fmt::format("{}{}", names.empty() ? "" : ", ", hwy::TargetName(bit));
        }
        throw InputError(
            "environment", "LAMINA_SIMD_TARGET",
            fmt::format("'{}' is not an instruction set of this build ({})", wanted, names));
    }();
    (void)done;
}

const char* simd_target_name() {
    select_simd_target();
    // Dynamic dispatch picks the best target that is both compiled and supported: the lowest bit.
    const std::int64_t targets = hwy::SupportedTargets() & HWY_TARGETS;
    return hwy::TargetName(targets & -targets);
}

std::vector<float> simd_particle_uniforms(std::uint64_t seed, std::uint64_t stream,
                                          std::uint64_t first, std::uint64_t n_particles,
                                          std::uint64_t n_draws) {
    std::vector<float> out(n_particles * n_draws);
    HWY_DYNAMIC_DISPATCH(PcgDrawsForTest)(seed, stream, first, n_particles, n_draws, out.data());
    return out;
}

void simd_cos_sin_2pi(const std::vector<float>& u, std::vector<float>& c, std::vector<float>& s) {
    c.resize(u.size());
    s.resize(u.size());
    HWY_DYNAMIC_DISPATCH(CosSin2PiForTest)(u.data(), u.size(), c.data(), s.data());
}

std::vector<std::int64_t> simd_lane_bins(const HemisphereGrid& grid, const std::vector<float>& d) {
    select_simd_target();
    std::vector<std::int64_t> bins(d.size() / 3);
    HWY_DYNAMIC_DISPATCH(LaneBinsForTest)(grid, d.data(), bins.size(), bins.data());
    return bins;
}

std::vector<float> simd_smith_refraction_escape(const std::vector<float>& r_i,
                                                const std::vector<float>& r_o) {
    select_simd_target();
    std::vector<float> out(r_i.size());
    HWY_DYNAMIC_DISPATCH(SmithRefractionEscapeForTest)
    (r_i.data(), r_o.data(), r_i.size(), out.data());
    return out;
}

void simd_fresnel_dielectric(const std::vector<float>& cos_theta, float eta,
                             std::vector<float>& reflectance, std::vector<float>& cos_theta_t) {
    select_simd_target();
    reflectance.resize(cos_theta.size());
    cos_theta_t.resize(cos_theta.size());
    HWY_DYNAMIC_DISPATCH(FresnelDielectricForTest)
    (cos_theta.data(), cos_theta.size(), eta, reflectance.data(), cos_theta_t.data());
}

std::vector<float> simd_fresnel_conductor(const std::vector<float>& cos_theta, float eta, float k) {
    select_simd_target();
    std::vector<float> out(cos_theta.size());
    HWY_DYNAMIC_DISPATCH(FresnelConductorForTest)
    (cos_theta.data(), cos_theta.size(), eta, k, out.data());
    return out;
}

void simd_henyey_greenstein(const std::vector<float>& g, const std::vector<float>& x,
                            std::vector<float>& phase, std::vector<float>& cos_theta) {
    select_simd_target();
    phase.resize(g.size());
    cos_theta.resize(g.size());
    HWY_DYNAMIC_DISPATCH(HenyeyGreensteinForTest)
    (g.data(), x.data(), g.size(), phase.data(), cos_theta.data());
}

void simd_ggx_lanes(float alpha, const std::vector<float>& w, const std::vector<float>& u1,
                    const std::vector<float>& u2, std::vector<float>& lambda,
                    std::vector<float>& wm) {
    select_simd_target();
    lambda.resize(u1.size());
    wm.resize(3 * u1.size());
    HWY_DYNAMIC_DISPATCH(GgxLanesForTest)
    (alpha, w.data(), u1.data(), u2.data(), u1.size(), lambda.data(), wm.data());
}

SimdEventResult simd_interface_events(int kind, const std::vector<float>& params,
                                      const std::vector<std::int32_t>& flags,
                                      const std::vector<float>& wi, const std::vector<float>& u) {
    select_simd_target();
    const std::size_t n = wi.size() / 3;
    SimdEventResult r;
    r.wo.resize(3 * n);
    r.shadowing.resize(n);
    r.fresnel.assign(3 * n, 1.f);
    r.reflected.resize(n);
    r.degenerate.resize(n);
    HWY_DYNAMIC_DISPATCH(InterfaceEventsForTest)
    (kind, params.data(), flags.data(), wi.data(), u.data(), n, r.wo.data(), r.shadowing.data(),
     r.fresnel.data(), r.reflected.data(), r.degenerate.data());
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
    HWY_DYNAMIC_DISPATCH(MediumStepForTest)
    (medium, d.data(), w.data(), depth.data(), u.data(), n, r.leaves.data(), r.factor.data(),
     r.depth.data(), r.d.data(), r.phase.data(), r.draws.data());
    return r;
}

std::vector<float> simd_fresnel_mueller(int kind, const std::vector<float>& cos_theta, float eta,
                                        float k) {
    select_simd_target();
    std::vector<float> out(cos_theta.size() * (kind == 0 ? 9 : 4));
    HWY_DYNAMIC_DISPATCH(FresnelMuellerForTest)
    (kind, cos_theta.data(), cos_theta.size(), eta, k, out.data());
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
    HWY_DYNAMIC_DISPATCH(PolarizedEventsForTest)
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
    HWY_DYNAMIC_DISPATCH(MicrosurfaceWalkForTest)
    (wi.data(), n, alpha, dielectric, eta, k, max_order, seed, r.wo.data(), r.weight.data(),
     r.order.data(), r.outcome.data());
    return r;
}

}  // namespace lamina
#endif
