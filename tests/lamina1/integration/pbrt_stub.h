#pragma once
// A stand-in for the few pbrt-v4 types a BxDF touches (pbrt-v4's src/pbrt/bxdfs.h and
// util/spectrum.h name them; none of its code is here), so that the worked integration of
// docs/lamina1.md compiles and runs without pbrt. SampledSpectrum holds the three RGB channels
// here, where pbrt holds wavelength samples (see pbrt_bxdf.h for the conversion pbrt makes).
#include <cmath>
#include <optional>

namespace pbrt {

using Float = float;

struct Vector3f {
    Float x = 0, y = 0, z = 0;
};
struct Point2f {
    Float x = 0, y = 0;
};

struct SampledSpectrum {
    Float v[3] = {0, 0, 0};
    Float operator[](int i) const { return v[i]; }
    bool IsZero() const { return v[0] == 0 && v[1] == 0 && v[2] == 0; }
};

enum class TransportMode { Radiance, Importance };

enum BxDFFlags : unsigned {
    Unset = 0,
    Reflection = 1 << 0,
    Transmission = 1 << 1,
    Diffuse = 1 << 2,
    Glossy = 1 << 3,
    Specular = 1 << 4,
};

enum class BxDFReflTransFlags : unsigned { Unset = 0, Reflection = 1, Transmission = 2, All = 3 };

struct BSDFSample {
    SampledSpectrum f;
    Vector3f wi;
    Float pdf = 0;
    BxDFFlags flags = Unset;
};

}  // namespace pbrt
