#include "models/random_walk_model.h"

#include "models/factories.h"

#include <bit>
#include <string>

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
                                 TransmissionMasking masking,
                                 RandomWalkStack::Microsurface microsurface)
    : walker_(stack, 10'000, masking, microsurface), samples_(samples), seed_(seed) {
    if (stack.transmits())
        flipped_ =
            std::make_unique<RandomWalkStack>(flipped_stack(stack), 10'000, masking, microsurface);
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

std::vector<OptionSpec> random_walk_options() {
    return {{"samples",
             {"16", "64", "256", "1024", "4096", "16384", "65536"},
             "1024",
             "random walks per query (the noise falls as 1/sqrt(samples))"},
            {"seed", {"1", "2", "3", "4", "5", "6", "7", "8"}, "1", "seed of the walks"},
            {"transmission-masking",
             {"smith", "pbrt"},
             "smith",
             "masking of light refracted by a rough dielectric: the Smith microsurface's "
             "B(1+Λi, 1+Λo), or pbrt-v4's 1/(1+Λi+Λo)"},
            {"microsurface",
             {"single", "multiple"},
             "single",
             "rough interfaces: single-scattering microfacet BSDFs, or the microsurface random "
             "walk of Heitz et al. 2016 (multiple scattering, nothing lost)"}};
}

std::unique_ptr<Model> make_random_walk(const Stack& stack, const ModelOptions& options) {
    return std::make_unique<RandomWalkModel>(
        stack, std::stoull(option_value(options, "samples")),
        std::stoull(option_value(options, "seed")),
        parse_transmission_masking(option_value(options, "transmission-masking"), "model option",
                                   "transmission-masking"),
        option_value(options, "microsurface") == "multiple"
            ? RandomWalkStack::Microsurface::Multiple
            : RandomWalkStack::Microsurface::Single);
}

}  // namespace lamina
