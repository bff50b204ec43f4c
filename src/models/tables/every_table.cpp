#include "models/tables/every_table.h"

#include "models/tables/coat_transmittance.h"
#include "models/tables/fgd_table.h"
#include "models/tables/multiple_scattering_albedo.h"
#include "models/tables/slope_sum_table.h"
#include "models/tables/tir_table.h"

namespace lamina {

std::vector<CachedTable> every_cached_table() {
    return {
        {"fgd", "FGD(c, α, η, κ): the directional albedo of one GGX reflection",
         [] { FgdTable::get(); }},
        {"ggx-albedo", "a GGX conductor's directional albedo", [] { GgxAlbedoTable::get(); }},
        {"tir", "the fraction of light a rough interface reflects back below it (TIR)",
         [] { TirTable::get(); }},
        {"tir-lobe", "the same fraction with its lobe's spread", [] { LobeTirTable::get(); }},
        {"slope-sum", "the slope sums of lamina-1's lobes", [] { SlopeSumTable::get(); }},
        {"coat-t", "a rough coat's transmittance, Smith's masking",
         [] { CoatTransmittanceTable::get(TransmissionMasking::Smith); }},
        {"coat-t", "a rough coat's transmittance, pbrt's masking",
         [] { CoatTransmittanceTable::get(TransmissionMasking::Pbrt); }},
        {"ms-albedo", "the microsurfaces' multiple-scattering albedo (the walk)",
         [] { MultipleScatteringAlbedo::get(); }},
    };
}

}  // namespace lamina
