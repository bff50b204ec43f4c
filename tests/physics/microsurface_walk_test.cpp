// The microsurface walk's suspension (physics/microsurface_walk.h: `suspend` and
// MicrosurfaceWalkResume, what the SIMD kernel uses to let a few lanes' long walks wait while the
// others go on): a walk suspended at any pass and resumed is the walk run through, number for
// number, given the one number the resumed walk's first pass draws and does not use. Checked at
// one lane on a rough dielectric (light from above and from below) and a rough coloured
// conductor, over many walks of many orders.
#include "physics/microsurface_walk.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <random>
#include <vector>

namespace lamina {
namespace {

using L = Lane<float>;

// A fixed sequence of uniform numbers, read in order; `dummy` numbers are handed out first
// (the resumed walk's unused draw).
struct Sequence {
    const std::vector<float>& u;
    std::size_t next = 0;
    int dummy = 0;
    float operator()() {
        if (dummy > 0) {
            --dummy;
            return 0.5f;
        }
        return u[next++ % u.size()];
    }
};

// Runs the walk through (`suspend_at` < 0) or suspended at its suspend_at-th question and
// resumed; returns the final lanes and how many numbers of the sequence were used.
template <typename MakeFacet>
MicrosurfaceWalkLanes<float, bool> walk(const GGX<float>& ggx, const LaneVec3<float>& wi,
                                        bool two_sided, const std::vector<float>& u, int suspend_at,
                                        MakeFacet&& make_facet, std::size_t& used,
                                        bool& was_suspended) {
    Sequence seq{u};
    auto draw = [&] { return seq(); };
    const auto facet = make_facet(draw);
    int asked = 0;
    auto suspend = [&](bool) { return asked++ == suspend_at; };
    MicrosurfaceWalkLanes<float, bool> r =
        microsurface_walk<float, L>(ggx.lanes<false>(), wi, true, two_sided, facet, draw, 100,
                                    MicrosurfaceNoVisit{}, nullptr, suspend);
    was_suspended = r.suspended;
    if (r.suspended) {
        const MicrosurfaceWalkResume<float, bool> resume{
            true, r.h, r.side, r.order, {r.weight[0], r.weight[1], r.weight[2]}};
        const LaneVec3<float> wi_now = {-r.wo.x, -r.wo.y, -r.wo.z};
        seq.dummy = 1;
        r = microsurface_walk<float, L>(ggx.lanes<false>(), wi_now, true, two_sided, facet, draw,
                                        100, MicrosurfaceNoVisit{}, &resume);
        EXPECT_FALSE(r.suspended);
    }
    used = seq.next;
    return r;
}

template <typename MakeFacet>
void expect_resumes_exactly(const GGX<float>& ggx, bool two_sided, MakeFacet&& make_facet) {
    std::mt19937 gen(20261206);
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    int suspended_walks = 0, long_walks = 0;
    for (int n = 0; n < 4000; ++n) {
        std::vector<float> u(400);
        for (float& x : u)
            x = uniform(gen);
        const float cos_i = 0.05f + 0.9f * uniform(gen), phi = 6.2831853f * uniform(gen);
        const float sin_i = std::sqrt(1 - cos_i * cos_i), z = two_sided && n % 2 ? -cos_i : cos_i;
        const LaneVec3<float> wi = {sin_i * std::cos(phi), sin_i * std::sin(phi), z};
        std::size_t used_through = 0;
        bool unused = false;
        const auto through = walk(ggx, wi, two_sided, u, -1, make_facet, used_through, unused);
        if (through.order > 2) ++long_walks;
        for (int at : {0, 1, 2, 5}) {
            std::size_t used = 0;
            bool suspended = false;
            const auto r = walk(ggx, wi, two_sided, u, at, make_facet, used, suspended);
            suspended_walks += suspended ? 1 : 0;
            EXPECT_EQ(r.escaped, through.escaped) << n << " " << at;
            EXPECT_EQ(r.capped, through.capped) << n << " " << at;
            EXPECT_EQ(r.degenerate, through.degenerate) << n << " " << at;
            EXPECT_EQ(r.order, through.order) << n << " " << at;
            EXPECT_EQ(r.wo.x, through.wo.x) << n << " " << at;
            EXPECT_EQ(r.wo.y, through.wo.y) << n << " " << at;
            EXPECT_EQ(r.wo.z, through.wo.z) << n << " " << at;
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(r.weight[c], through.weight[c]) << n << " " << at;
            EXPECT_EQ(used, used_through) << n << " " << at;
        }
    }
    // The check has teeth: many walks were suspended, some of them long ones.
    EXPECT_GT(suspended_walks, 1000);
    EXPECT_GT(long_walks, 100);
}

TEST(MicrosurfaceWalk, SuspendedAndResumedIsTheWalkRunThroughDielectric) {
    const GGX<float> ggx{0.6f};
    expect_resumes_exactly(ggx, true, [](auto& draw) {
        using Draw = std::remove_reference_t<decltype(draw)>;
        return MicrosurfaceDielectricFacet<float, L, Draw>{1.5f, 1 / 1.5f, draw};
    });
}

TEST(MicrosurfaceWalk, SuspendedAndResumedIsTheWalkRunThroughConductor) {
    const GGX<float> ggx{0.8f};
    static const auto factors = [](float cos_w_m, float* out) {
        out[0] = 0.9f;
        out[1] = 0.5f + 0.4f * cos_w_m;
        out[2] = 0.3f;
    };
    expect_resumes_exactly(ggx, false, [](auto&) {
        return MicrosurfaceConductorFacet<float, L, decltype(factors)>{factors};
    });
}

}  // namespace
}  // namespace lamina
