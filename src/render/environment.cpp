#include "render/environment.h"

#include "core/error.h"
#include "core/math.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace lamina {

Rgbd Environment::background(const Vec3d& d) const {
    if (d.y < 0) return ground + (horizon - ground) * std::max(0.0, 1 + 4 * d.y);
    return horizon + (zenith - horizon) * d.y;
}

Rgbd Environment::radiance(const Vec3d& d) const {
    Rgbd L = background(d);
    for (const CapLight& c : caps)
        if (dot(d, c.direction) >= c.cos_max) L += c.radiance;
    return L;
}

Environment Environment::named(const std::string& name) {
    Environment e;
    auto cap = [](Vec3d dir, double half_angle_deg, Rgbd L) {
        return CapLight{normalize(dir), std::cos(deg_to_rad(half_angle_deg)), L};
    };
    if (name == "studio") {
        // A grey gradient and three lights: key (upper left, front), fill (right), rim (behind).
        e.zenith = Rgbd(0.35);
        e.horizon = Rgbd(0.18);
        e.ground = Rgbd(0.06);
        e.caps = {cap({-0.6, 0.55, 0.6}, 11, Rgbd(14.0)), cap({0.8, 0.15, 0.55}, 18, Rgbd(2.5)),
                  cap({0.2, 0.6, -0.75}, 9, Rgbd(10.0))};
    } else if (name == "uniform") {
        e.zenith = e.horizon = e.ground = Rgbd(1.0);
    } else if (name == "sky") {
        e.zenith = Rgbd(0.25, 0.45, 0.9);
        e.horizon = Rgbd(0.8, 0.85, 0.9);
        e.ground = Rgbd(0.15, 0.12, 0.1);
        e.caps = {cap({-0.3, 0.8, 0.5}, 1.5, Rgbd(900.0, 850.0, 750.0))};
    } else if (name == "dark") {
    } else {
        throw InputError(
            "command line", "--env",
            fmt::format("unknown environment '{}'; known: studio, uniform, sky, dark", name));
    }
    return e;
}

DirectionalLight parse_directional_light(const std::string& text) {
    std::vector<double> v;
    std::stringstream ss(text);
    for (std::string item; std::getline(ss, item, ',');) {
        char* end = nullptr;
        const double x = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(x))
            throw InputError("command line", "--light", fmt::format("'{}' is not a number", item));
        v.push_back(x);
    }
    if (v.size() != 4 && v.size() != 6)
        throw InputError("command line", "--light",
                         "expected x,y,z,E or x,y,z,Er,Eg,Eb (direction towards the light, "
                         "irradiance)");
    // The direction scaled by its largest component first: its length then neither overflows
    // (1e200 components) nor underflows (1e-200).
    const double largest = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
    if (largest == 0) throw InputError("command line", "--light", "the direction is zero");
    const Vec3d d = Vec3d(v[0], v[1], v[2]) / largest;
    const Rgbd E = v.size() == 4 ? Rgbd(v[3]) : Rgbd(v[3], v[4], v[5]);
    if (E.min() < 0 || E.max() > kMaxLightIrradiance)
        throw InputError("command line", "--light",
                         fmt::format("irradiance must be in [0, {:g}] (the image's scale)",
                                     kMaxLightIrradiance));
    return {normalize(d), E};
}

}  // namespace lamina
