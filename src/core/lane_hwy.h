// Lanes on Highway vectors: the operations struct of core/lane.h for the lanes of a SIMD vector
// (VecLane), the vector maths it needs that Highway does not provide (a refined 1/√x, cos and sin
// of 2πu together, acos), and the lane types and small helpers every SIMD translation unit
// shares. The lane templates instantiated with VecLane are the SIMD particle kernel's physics
// (simulator/kernel_simd.cpp); the lane tests instantiate them again (tests/support/simd_probes).
//
// A per-target header. A translation unit of vector code is compiled once per instruction set:
// it names itself HWY_TARGET_INCLUDE, includes <hwy/foreach_target.h>, and then includes this
// header and the lane headers it instantiates between `#define LAMINA_LANE_TARGET` and
// `#undef LAMINA_LANE_TARGET`:
//
//   #define LAMINA_LANE_TARGET
//   #include "core/lane_hwy.h"
//   #include "physics/fresnel.h"   // its templates again, in this target's namespace
//   #undef LAMINA_LANE_TARGET
//
// This header points LAMINA_LANE_BEGIN/END at the target's namespace (lamina::HWY_NAMESPACE), so
// it comes after the unit's ordinary includes: a lane header first met after it would put its
// scalar templates there.

#ifndef LAMINA_LANE_TARGET
#error "core/lane_hwy.h is included per SIMD target, with LAMINA_LANE_TARGET defined (see above)"
#endif

#include "core/lane.h"
#include "core/math.h"

#include <cstddef>
#include <cstdint>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

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

#include "core/lane_vec.h"

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_CORE_LANE_HWY_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_CORE_LANE_HWY_H
#undef LAMINA_CORE_LANE_HWY_H
#else
#define LAMINA_CORE_LANE_HWY_H
#endif

LAMINA_LANE_BEGIN

namespace hn = hwy::HWY_NAMESPACE;

// Lanes of floats and their integer and mask companions, full vectors of the instruction set.
using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using MF = hn::Mask<DF>;
using MI = hn::Mask<DI>;
using V3 = LaneVec3<VF>;  // a direction as three vectors (core/lane_vec.h)

/// The most float lanes of any compiled instruction set: the size of a per-lane array.
constexpr std::size_t kMaxLanes = HWY_MAX_BYTES / sizeof(float);

/// 1/√x, a correctly rounded square root and division (each ≤ ½ ulp). Not the hardware's
/// reciprocal square-root estimate refined by a Newton step: its bits differ between CPU vendors
/// (Intel's and AMD's rsqrtps), so the same instruction set would trace different tables on
/// different machines; it costs about 1.5 % of the kernel's speed (docs/performance.md).
HWY_INLINE VF InvSqrt(VF x) {
    const DF df;
    return hn::Div(hn::Set(df, 1.f), hn::Sqrt(x));
}

/// cos and sin of 2π u for u ∈ [0, 1) (a uniform azimuth), both at once. 2πu = (π/4)(j + f) with
/// j = ⌊8u⌋ and f = 8u − j, exact in float (u has 24 bits); the octant's angle a ∈ [0, π/4] goes
/// through the minimax polynomials of the Cephes library's sinf/cosf (Moshier 1992, "Methods and
/// Programs for Mathematical Functions"; errors below 1 ulp on [−π/4, π/4]), and the octant's
/// symmetries give cos and sin of the whole angle. One reduction for both instead of two.
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

/// Acos's error bound, radians: Abramowitz & Stegun 1964, Eq. 4.4.46 has |ε| ≤ 2·10^-8 on [0, 1];
/// in float the error is that of the rounding, at most 4.3e-7 rad (measured on 4·10^6 points of
/// [−1, 1] against the double acos; the float operations bound it by about 5e-7: ulp-level square
/// root, polynomial and product, π − r rounded once).
constexpr double kAcosErrorBound = 5e-7;

/// acos(x), x ∈ [−1, 1]: Abramowitz & Stegun 1964, Eq. 4.4.46, with acos(−x) = π − acos(x);
/// within kAcosErrorBound.
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

/// The operations of core/lane.h that every element type's vectors share (Highway's own),
/// for the descriptor D; VecLane (floats) and VecLaneD (doubles) add their special functions.
template <class D>
struct VecLaneOps {
    using Value = hn::Vec<D>;
    using Mask = hn::Mask<D>;
    using V = Value;
    using M = Mask;
    static HWY_INLINE V constant(double x) { return hn::Set(D(), hn::TFromD<D>(x)); }
    static HWY_INLINE V min(V a, V b) { return hn::Min(a, b); }
    static HWY_INLINE V max(V a, V b) { return hn::Max(a, b); }
    static HWY_INLINE V sqrt(V x) { return hn::Sqrt(x); }
    static HWY_INLINE V exp(V x) { return hn::Exp(D(), x); }
    static HWY_INLINE V select(M m, V a, V b) { return hn::IfThenElse(m, a, b); }
    static HWY_INLINE M less(V a, V b) { return hn::Lt(a, b); }
    static HWY_INLINE V abs(V x) { return hn::Abs(x); }
    static HWY_INLINE V copysign(V a, V b) { return hn::CopySign(a, b); }
    static HWY_INLINE V mul_add(V a, V b, V c) { return hn::MulAdd(a, b, c); }
    static HWY_INLINE V neg_mul_add(V a, V b, V c) { return hn::NegMulAdd(a, b, c); }
    static HWY_INLINE M both(M m, M n) { return hn::And(m, n); }
    static HWY_INLINE M either(M m, M n) { return hn::Or(m, n); }
    static HWY_INLINE M negate(M m) { return hn::Not(m); }
    static HWY_INLINE bool none(M m) { return hn::AllFalse(D(), m); }
};

/// The operations of core/lane.h on vectors: the lane templates (core/beta_function.h, the
/// physics headers) instantiated on the lanes of VF. Highway's contrib math functions: Log
/// ≤ 4 ulp, Log1p ≤ 2 ulp, Exp ≤ 1 ulp (hwy/contrib/math).
struct VecLane : VecLaneOps<DF> {
    static HWY_INLINE VF log(VF x) { return hn::Log(DF(), x); }
    static HWY_INLINE VF log1p(VF x) { return hn::Log1p(DF(), x); }
    static HWY_INLINE VF inv_sqrt(VF x) { return InvSqrt(x); }
    static HWY_INLINE void cos_sin_2pi(VF u, VF& c, VF& s) { CosSin2Pi(u, c, s); }
    static constexpr double kBetaArgumentMax = Lane<float>::kBetaArgumentMax;
    static constexpr bool kSinglePrecision = true;
};

/// Two vectors of float lanes as one lane value: the lane templates instantiated on VecLane2 run
/// every operation on both vectors, the two operations side by side. A template's operations form
/// long dependent chains (a rough dielectric's event: a visible normal, then its Fresnel factor,
/// then the chosen direction, then its masking), during which one vector leaves the processor's
/// units idle; two independent vectors in one instruction stream fill them (measured in
/// docs/performance.md). The pair is the SIMD kernel's two lane sets (kernel_simd.cpp) at one
/// event.
struct VF2 {
    VF a, b;
};
struct MF2 {
    MF a, b;
};
HWY_INLINE VF2 operator+(VF2 x, VF2 y) {
    return {hn::Add(x.a, y.a), hn::Add(x.b, y.b)};
}
HWY_INLINE VF2 operator-(VF2 x, VF2 y) {
    return {hn::Sub(x.a, y.a), hn::Sub(x.b, y.b)};
}
HWY_INLINE VF2 operator*(VF2 x, VF2 y) {
    return {hn::Mul(x.a, y.a), hn::Mul(x.b, y.b)};
}
HWY_INLINE VF2 operator/(VF2 x, VF2 y) {
    return {hn::Div(x.a, y.a), hn::Div(x.b, y.b)};
}

/// The operations of core/lane.h on pairs of vectors: VecLane's, on each vector.
struct VecLane2 {
    using Value = VF2;
    using Mask = MF2;
    using V = VF2;
    using M = MF2;
    template <typename F>
    static HWY_INLINE V each(V x, F f) {
        return {f(x.a), f(x.b)};
    }
    static HWY_INLINE V constant(double x) {
        const VF c = VecLane::constant(x);
        return {c, c};
    }
    static HWY_INLINE V min(V a, V b) { return {hn::Min(a.a, b.a), hn::Min(a.b, b.b)}; }
    static HWY_INLINE V max(V a, V b) { return {hn::Max(a.a, b.a), hn::Max(a.b, b.b)}; }
    static HWY_INLINE V sqrt(V x) {
        return each(x, [](VF y) { return VecLane::sqrt(y); });
    }
    static HWY_INLINE V exp(V x) {
        return each(x, [](VF y) { return VecLane::exp(y); });
    }
    static HWY_INLINE V log(V x) {
        return each(x, [](VF y) { return VecLane::log(y); });
    }
    static HWY_INLINE V log1p(V x) {
        return each(x, [](VF y) { return VecLane::log1p(y); });
    }
    static HWY_INLINE V abs(V x) {
        return each(x, [](VF y) { return VecLane::abs(y); });
    }
    static HWY_INLINE V inv_sqrt(V x) {
        return each(x, [](VF y) { return VecLane::inv_sqrt(y); });
    }
    static HWY_INLINE V select(M m, V a, V b) {
        return {hn::IfThenElse(m.a, a.a, b.a), hn::IfThenElse(m.b, a.b, b.b)};
    }
    static HWY_INLINE M less(V a, V b) { return {hn::Lt(a.a, b.a), hn::Lt(a.b, b.b)}; }
    static HWY_INLINE V copysign(V a, V b) {
        return {hn::CopySign(a.a, b.a), hn::CopySign(a.b, b.b)};
    }
    static HWY_INLINE V mul_add(V a, V b, V c) {
        return {hn::MulAdd(a.a, b.a, c.a), hn::MulAdd(a.b, b.b, c.b)};
    }
    static HWY_INLINE V neg_mul_add(V a, V b, V c) {
        return {hn::NegMulAdd(a.a, b.a, c.a), hn::NegMulAdd(a.b, b.b, c.b)};
    }
    static HWY_INLINE M both(M m, M n) { return {hn::And(m.a, n.a), hn::And(m.b, n.b)}; }
    static HWY_INLINE M either(M m, M n) { return {hn::Or(m.a, n.a), hn::Or(m.b, n.b)}; }
    static HWY_INLINE M negate(M m) { return {hn::Not(m.a), hn::Not(m.b)}; }
    static HWY_INLINE bool none(M m) { return hn::AllFalse(DF(), hn::Or(m.a, m.b)); }
    static HWY_INLINE void cos_sin_2pi(V u, V& c, V& s) {
        CosSin2Pi(u.a, c.a, s.a);
        CosSin2Pi(u.b, c.b, s.b);
    }
    static constexpr double kBetaArgumentMax = VecLane::kBetaArgumentMax;
    static constexpr bool kSinglePrecision = true;
};

/// A direction of the pair's lanes, from each vector's; and each vector's back.
HWY_INLINE LaneVec3<VF2> Pair(const V3& a, const V3& b) {
    return {{a.x, b.x}, {a.y, b.y}, {a.z, b.z}};
}
HWY_INLINE V3 First(const LaneVec3<VF2>& p) {
    return {p.x.a, p.y.a, p.z.a};
}
HWY_INLINE V3 Second(const LaneVec3<VF2>& p) {
    return {p.x.b, p.y.b, p.z.b};
}

// Lanes of doubles, half as many as of floats in a vector of the same width: the few formulas
// the kernel evaluates in double (a thin film's Airy sums, physics/thin_film_airy.h).
using DD = hn::ScalableTag<double>;
using VD = hn::Vec<DD>;
using MD = hn::Mask<DD>;

/// The operations of core/lane.h on vectors of doubles, for the lane templates evaluated in
/// double. Highway's contrib math functions: Exp ≤ 1 ulp, Cos and Sin ≤ 3 ulp on
/// [−39000, 39000] (hwy/contrib/math).
struct VecLaneD : VecLaneOps<DD> {
    static HWY_INLINE void cos_sin(VD x, VD& c, VD& s) {
        c = hn::Cos(DD(), x);
        s = hn::Sin(DD(), x);
    }
    static constexpr bool kSinglePrecision = false;
};

/// a where the mask m holds, else b (lane_select without the operations struct).
HWY_INLINE V3 Select(MF m, const V3& a, const V3& b) {
    return {hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)};
}

/// The mask of the lanes of v that equal `value`, as a float mask.
HWY_INLINE MF LaneIs(VI v, std::int32_t value) {
    const DF df;
    const DI di;
    return hn::RebindMask(df, hn::Eq(v, hn::Set(di, value)));
}

/// Bit l set where lane l of m holds.
HWY_INLINE std::uint64_t MaskBits(MF m) {
    const DF df;
    std::uint8_t bytes[(kMaxLanes + 7) / 8] = {};
    hn::StoreMaskBits(df, m, bytes);
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < (hn::Lanes(df) + 7) / 8; ++i)
        bits |= std::uint64_t(bytes[i]) << (8 * i);
    return bits;
}

LAMINA_LANE_END

#endif  // LAMINA_CORE_LANE_HWY_H
