#pragma once
// Procedural lighting built into lamina (no downloads): a studio of round area lights at infinity
// over a soft gradient, or a uniform white environment (the furnace test), plus an optional small
// directional light. World frame: the camera looks along −z from +z, y is up in the image.

#include "core/rgb.h"
#include "core/vec.h"

#include <optional>
#include <string>
#include <vector>

namespace lamina {

/// A round area light at infinity: radiance `radiance` inside the cone of half-angle
/// `half_angle` (radians) about `direction` (unit, towards the light).
struct CapLight {
    Vec3d direction;
    double cos_max = 1;  ///< cos of the half-angle
    Rgbd radiance{0.0};
};

/// A delta directional light: irradiance `irradiance` on a surface facing it.
struct DirectionalLight {
    Vec3d direction;  ///< unit, towards the light
    Rgbd irradiance{0.0};
};

struct Environment {
    /// Background radiance: sky(d) = horizon + (zenith − horizon)·max(0, d.y) below a ground
    /// colour for d.y < 0 (a soft gradient) — or a constant for the uniform environment.
    Rgbd zenith{0.0}, horizon{0.0}, ground{0.0};
    std::vector<CapLight> caps;
    std::optional<DirectionalLight> sun;

    /// Radiance arriving from direction d (unit, towards where the light comes from); caps add.
    Rgbd radiance(const Vec3d& d) const;
    Rgbd background(const Vec3d& d) const;

    /// "studio" (key, fill and rim lights over a grey gradient), "uniform" (radiance 1 from every
    /// direction: the white furnace), "sky" (a blue gradient and a small sun cap), "dark" (no
    /// environment: only --light). InputError otherwise.
    static Environment named(const std::string& name);
};

/// The largest irradiance --light takes: the environments' radiance is of order 1, and a pixel
/// of a sharp lobe (f ~ 10⁶ /sr) lit by it stays far inside float's range in the EXR.
inline constexpr double kMaxLightIrradiance = 1e6;

/// Parses "x,y,z,E" (direction towards the light, irradiance E, or E_r,E_g,E_b) for --light:
/// finite numbers, a non-zero direction (of any scale), 0 ≤ E ≤ kMaxLightIrradiance.
DirectionalLight parse_directional_light(const std::string& text);

}  // namespace lamina
