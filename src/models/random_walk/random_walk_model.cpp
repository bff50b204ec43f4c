#include "models/random_walk/random_walk_model.h"

#include "core/setting.h"

#include <bit>
#include <string>
#include <type_traits>

namespace lamina {

namespace {
std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
}  // namespace

std::uint64_t query_stream(const Vec3d& wi, const Vec3d& wo) {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (double x : {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z})
        h = mix64(h ^ std::bit_cast<std::uint64_t>(x));
    return h;
}

RandomWalkModel::RandomWalkModel(const Stack& stack, std::uint64_t samples, std::uint64_t seed,
                                 const TransportSettings& transport)
    : walker_(stack, transport), samples_(samples), seed_(seed) {
    if (stack.transmits())
        flipped_ = std::make_unique<RandomWalkStack>(flipped_stack(stack), transport);
}

Support RandomWalkModel::support() const {
    return {true, walker_.transmits(), walker_.transmits() ? "" : "opaque base: no BTDF"};
}

RandomWalkEstimate RandomWalkModel::estimate(const Vec3d& wi, const Vec3d& wo) const {
    return walker_.eval(wi, wo, samples_, seed_, query_stream(wi, wo));
}

RandomWalkPdf RandomWalkModel::pdf_estimate(const Vec3d& wi, const Vec3d& wo) const {
    return walker_.pdf(wi, wo, samples_, seed_, ~query_stream(wi, wo));
}

Rgbd RandomWalkModel::eval(const Vec3d& wi, const Vec3d& wo) const {
    return estimate(wi, wo).f;
}

std::vector<DeltaLobe> RandomWalkModel::delta_lobes(const Vec3d& wi) const {
    std::vector<DeltaLobe> out;
    for (const auto& d : walker_.delta_lobes(wi))
        out.push_back({d.direction, d.energy});
    return out;
}

namespace {

std::string option_key(const SettingInfo& info) {
    return option_name(info.name).substr(2);
}

// Calls visit(info, member) for each transport setting that takes named values: an enum or an
// on/off switch.
template <typename Transport, typename Visit>
void named_transport_settings(Transport& t, Visit&& visit) {
    TransportSettings::fields(t, [&](const SettingInfo& info, auto& member) {
        using T = std::decay_t<decltype(member)>;
        if constexpr (std::is_enum_v<T> || std::is_same_v<T, bool>) visit(info, member);
    });
}

// The values a named setting takes, as text.
template <typename T>
std::vector<std::string> named_values(const T& member) {
    std::vector<std::string> out;
    if constexpr (std::is_same_v<T, bool>) {
        out = {SettingCodec<bool>::to_text(true), SettingCodec<bool>::to_text(false)};
    } else {
        for (const auto& n : enum_names(member))
            out.push_back(n.text);
    }
    return out;
}

}  // namespace

std::vector<OptionSpec> random_walk_options() {
    std::vector<OptionSpec> specs = {
        {"samples",
         {"16", "64", "256", "1024", "4096", "16384", "65536"},
         "1024",
         "random walks per query (the noise falls as 1/sqrt(samples))"},
        {"seed", {"1", "2", "3", "4", "5", "6", "7", "8"}, "1", "seed of the walks"}};
    const TransportSettings defaults;
    named_transport_settings(defaults, [&](const SettingInfo& info, const auto& member) {
        using T = std::decay_t<decltype(member)>;
        specs.push_back(
            {option_key(info), named_values(member), SettingCodec<T>::to_text(member), info.help});
    });
    return specs;
}

std::vector<std::string> random_walk_assignments(const TransportSettings& transport) {
    std::vector<std::string> out;
    named_transport_settings(transport, [&](const SettingInfo& info, const auto& member) {
        using T = std::decay_t<decltype(member)>;
        out.push_back(option_key(info) + "=" + SettingCodec<T>::to_text(member));
    });
    return out;
}

std::unique_ptr<Model> make_random_walk(const Stack& stack, const ModelOptions& options) {
    TransportSettings transport;
    named_transport_settings(transport, [&](const SettingInfo& info, auto& member) {
        using T = std::decay_t<decltype(member)>;
        const std::string key = option_key(info);
        member = SettingCodec<T>::from_text(option_value(options, key), info, "model option", key);
    });
    return std::make_unique<RandomWalkModel>(stack, std::stoull(option_value(options, "samples")),
                                             std::stoull(option_value(options, "seed")), transport);
}

}  // namespace lamina
