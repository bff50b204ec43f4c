// A conductor's Fresnel factors on SIMD lanes, per channel: the functors that
// physics/conductor.h conductor_event and physics/microsurface_walk.h's conductor facet call at a
// facet's cosine, for the interface's indices broadcast to the lanes. The SIMD kernel
// (simulator/kernel_simd.cpp) and the lane tests hand them to the event templates. A per-target
// header (core/lane_hwy.h); ConductorInterface (physics/conductor.h) must already be included as an
// ordinary header.

#include "core/lane_hwy.h"
#include "physics/fresnel.h"
#include "physics/polarization.h"

#include <type_traits>

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_SIMULATOR_LANE_CONDUCTOR_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_SIMULATOR_LANE_CONDUCTOR_H
#undef LAMINA_SIMULATOR_LANE_CONDUCTOR_H
#else
#define LAMINA_SIMULATOR_LANE_CONDUCTOR_H
#endif

LAMINA_LANE_BEGIN

// fresnel.h fresnel_conductor (real-arithmetic complex Fresnel, the same template), cos θ in
// [0, 1].
HWY_INLINE VF FresnelConductor(VF cos_theta, float eta, float k) {
    const DF df;
    return fresnel_conductor<VF, VecLane>(cos_theta, hn::Set(df, eta), hn::Set(df, k));
}

// The operations struct of the lanes of T: a vector's (VecLane) or a pair's (VecLane2, the
// kernel's two lane sets at one event).
template <typename T>
using VecLaneOf = std::conditional_t<std::is_same_v<T, VF2>, VecLane2, VecLane>;

// The conductor's Fresnel factors per channel at the facet cosine (fresnel.h fresnel_conductor,
// the same template) on a vector or a pair of vectors; channels with the same index share the
// computation.
struct ConductorFresnel {
    const ConductorInterface<float>& iface;
    template <typename T, typename L = VecLaneOf<T>>
    HWY_INLINE void operator()(T cos_theta, T* factors) const {
        for (int c = 0; c < 3; ++c) {
            const bool same =
                c > 0 && iface.eta[c] == iface.eta[c - 1] && iface.k[c] == iface.k[c - 1];
            factors[c] = same ? factors[c - 1]
                              : fresnel_conductor<T, L>(cos_theta, L::constant(iface.eta[c]),
                                                        L::constant(iface.k[c]));
        }
    }
};

// The conductor's reflection Mueller matrices per channel (polarization.h
// fresnel_conductor_mueller, the same template) on a vector or a pair of vectors; channels with
// the same index share them.
struct ConductorMueller {
    const ConductorInterface<float>& iface;
    template <typename T, typename L = VecLaneOf<T>>
    HWY_INLINE void operator()(T cos_theta, InterfaceMueller<T>* m) const {
        for (int c = 0; c < 3; ++c) {
            const bool same =
                c > 0 && iface.eta[c] == iface.eta[c - 1] && iface.k[c] == iface.k[c - 1];
            m[c] = same ? m[c - 1]
                        : fresnel_conductor_mueller<T, L>(cos_theta, L::constant(iface.eta[c]),
                                                          L::constant(iface.k[c]));
        }
    }
};

// The same for indices that differ between the lanes (a spectral run's lanes, each at its own
// wavelengths): per channel a lane value of η and k.
struct LaneConductorFresnel {
    VF eta[3], k[3];
    HWY_INLINE void operator()(VF cos_theta, VF* factors) const {
        for (int c = 0; c < 3; ++c)
            factors[c] = fresnel_conductor<VF, VecLane>(cos_theta, eta[c], k[c]);
    }
};
struct LaneConductorMueller {
    VF eta[3], k[3];
    HWY_INLINE void operator()(VF cos_theta, InterfaceMueller<VF>* m) const {
        for (int c = 0; c < 3; ++c)
            m[c] = fresnel_conductor_mueller<VF, VecLane>(cos_theta, eta[c], k[c]);
    }
};

LAMINA_LANE_END

#endif  // LAMINA_SIMULATOR_LANE_CONDUCTOR_H
