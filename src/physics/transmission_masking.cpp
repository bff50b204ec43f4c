#include "core/error.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

namespace lamina {

const char* transmission_masking_name(TransmissionMasking masking) {
    return masking == TransmissionMasking::Pbrt ? "pbrt" : "smith";
}

TransmissionMasking parse_transmission_masking(const std::string& text, const std::string& where,
                                               const std::string& field) {
    if (text == "smith") return TransmissionMasking::Smith;
    if (text == "pbrt") return TransmissionMasking::Pbrt;
    throw InputError(where, field,
                     fmt::format("'{}' is not a transmission masking: use smith (the Smith "
                                 "microsurface's B(1 + Λi, 1 + Λo), the default) or pbrt "
                                 "(1/(1 + Λi + Λo), as pbrt-v4)",
                                 text));
}

}  // namespace lamina
