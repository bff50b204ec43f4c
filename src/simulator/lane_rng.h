// The particles' random numbers on SIMD lanes: each lane draws from its particle's own PCG32
// generator (O'Neill 2014), seeded as core/rng.h seeds ParticleRng from one Philox4x32-10
// evaluation (Salmon et al. 2011) keyed by (seed, stream, particle index): the very streams of the
// scalar kernel, both generators evaluated on vectors (Highway has no RNG). The SIMD kernel
// (simulator/kernel_simd.cpp) draws from them; the tests check them bit for bit against Random123
// and pcg-cpp. A per-target header (core/lane_hwy.h).

#include "core/lane_hwy.h"

#include <cstdint>

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_SIMULATOR_LANE_RNG_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_SIMULATOR_LANE_RNG_H
#undef LAMINA_SIMULATOR_LANE_RNG_H
#else
#define LAMINA_SIMULATOR_LANE_RNG_H
#endif

LAMINA_LANE_BEGIN

using D64 = hn::Repartition<std::uint64_t, DF>;
using V64 = hn::Vec<D64>;

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
inline void SeedParticles(std::uint64_t seed, std::uint64_t stream, std::uint64_t first,
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
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL
        return VU{_mm512_rorv_epi32(x.raw, r.raw)};  // AVX-512F rotates by a lane's own count
#else
        const VU left = hn::And(hn::Sub(hn::Set(du, 32u), r), hn::Set(du, 31u));
        return hn::Or(x >> r, x << left);
#endif
    }
    HWY_INLINE VF Uniform() {
        const DF df;
        const DI di;
        return hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(NextU32()))),
                       hn::Set(df, 0x1p-24f));
    }
};

LAMINA_LANE_END

#endif  // LAMINA_SIMULATOR_LANE_RNG_H
