#pragma once
// Reproducible random numbers for particle tracing.
//
// Every particle owns an independent generator derived from (seed, stream, particle index) by one
// call of the counter-based Philox4x32-10 (Salmon et al. 2011, "Parallel random numbers: as easy as
// 1, 2, 3", SC'11; Random123 library). The four 32-bit words seed a PCG32 generator (O'Neill 2014,
// pcg-cpp) used for the particle's draws: a particle's numbers depend only on its index, never on
// which thread traced it, which makes every table bitwise reproducible for any thread count.

#include <Random123/philox.h>
#include <pcg_random.hpp>

#include <cstdint>

namespace lamina {

class ParticleRng {
  public:
    /// `stream` separates independent experiments sharing a seed (e.g. incidences, noise-floor
    /// halves); `index` is the particle's number within the stream.
    ParticleRng(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
        using Philox = r123::Philox4x32;
        const Philox::ctr_type counter = {{std::uint32_t(index), std::uint32_t(index >> 32),
                                           std::uint32_t(stream), std::uint32_t(stream >> 32)}};
        const Philox::key_type key = {{std::uint32_t(seed), std::uint32_t(seed >> 32)}};
        const Philox::ctr_type r = Philox()(counter, key);
        const std::uint64_t state = (std::uint64_t(r[1]) << 32) | r[0];
        const std::uint64_t sequence = (std::uint64_t(r[3]) << 32) | r[2];
        gen_ = pcg32(state, sequence);
    }

    std::uint32_t next_u32() { return gen_(); }

    /// Uniform in [0, 1) with 24 random bits: every value is exactly representable in float.
    float uniform_float() { return float(gen_() >> 8) * 0x1p-24f; }

    /// Uniform in [0, 1) with 53 random bits.
    double uniform_double() {
        const std::uint64_t hi = gen_(), lo = gen_();
        return double(((hi << 32) | lo) >> 11) * 0x1p-53;
    }

    template <typename T>
    T uniform() {
        if constexpr (sizeof(T) == sizeof(float))
            return uniform_float();
        else
            return uniform_double();
    }

  private:
    pcg32 gen_;
};

}  // namespace lamina
