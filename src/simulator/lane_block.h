// The SIMD kernel's storage for a block of particles (simulator/kernel_simd.cpp): the queue of
// the particles waiting after their first event, with their generators, and the per-lane double
// sums of what ended particles carry, reduced in lane order. A per-target header
// (core/lane_hwy.h); BlockBudget (simulator/tally.h) must already be included as an ordinary
// header.

#include "core/lane_hwy.h"
#include "simulator/lane_events.h"

#include <cstdint>
#include <vector>

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_SIMULATOR_LANE_BLOCK_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_SIMULATOR_LANE_BLOCK_H
#undef LAMINA_SIMULATOR_LANE_BLOCK_H
#else
#define LAMINA_SIMULATOR_LANE_BLOCK_H
#endif

LAMINA_LANE_BEGIN

using DD = hn::Repartition<double, DF>;
using DL = hn::RebindToSigned<DD>;
using VD = hn::Vec<DD>;
using VL = hn::Vec<DL>;

// The queue of particles past their first event (FirstEvents), one array per field: the
// waiting lanes' fields are compressed into it on vectors, and the main loop's fresh lanes expand
// them out of it on vectors (in lane order: the queue's order is the particles' order).
// Floats: the direction (3), the flux (3), the optical depth, then (polarized runs) the
// polarization frame's x axis and (q, u, v) per channel (12); integers: the next interface, in
// medium, the events so far; and the generator. Every array has kMaxLanes entries to spare, for
// stores of whole vectors.
constexpr int kQueueFloats = 7, kQueuePolarizationFloats = 12, kQueueInts = 3;
struct QueueArrays {
    std::vector<float> f[kQueueFloats + kQueuePolarizationFloats];
    std::vector<std::int32_t> i[kQueueInts];
    std::vector<std::uint64_t> state, inc;
    std::size_t size = 0;
    void reserve(std::size_t n, bool polarized) {
        const std::size_t padded = n + kMaxLanes;
        for (int a = 0; a < kQueueFloats + (polarized ? kQueuePolarizationFloats : 0); ++a)
            if (f[a].size() < padded) f[a].resize(padded);
        for (auto& a : i)
            if (a.size() < padded) a.resize(padded);
        if (state.size() < padded) {
            state.resize(padded);
            inc.resize(padded);
        }
    }
};
// Its spectral lane (spectral runs), kept beside the queue: LaneVectors' at, group, secondaries.
struct WaitingSpectral {
    std::int32_t at, group, secondaries;
};

struct Scratch {
    std::vector<std::uint64_t> state, inc;
    QueueArrays queue;
    std::vector<WaitingSpectral> queue_spectral;
    void resize(std::size_t n, bool polarized) {
        state.resize(n);
        inc.resize(n);
        queue.reserve(n, polarized);
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

LAMINA_LANE_END

#endif  // LAMINA_SIMULATOR_LANE_BLOCK_H
