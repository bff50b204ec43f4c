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
        {"ggx-albedo", "E(c, α): a GGX lobe's directional albedo without Fresnel",
         [] { GgxAlbedoTable::get(); }},
        {"tir",
         "τ_TIR(c, α, η): what a rough interface lets out from below, its microfacets refracting",
         [] { TirTable::get(); }},
        {"tir-lobe",
         "τ_TIR of a GGX lobe crossing a smooth interface (Belcour's and the transfer matrices')",
         [] { LobeTirTable::get(); }},
        {"slope-sum", "the density of a sum of independent GGX slopes (lamina-1's lobes)",
         [] { SlopeSumTable::get(); }},
        {"coat-t", "a rough coat's transmittance, Smith's masking",
         [] { CoatTransmittanceTable::get(TransmissionMasking::Smith); }},
        {"coat-t", "a rough coat's transmittance, pbrt's masking",
         [] { CoatTransmittanceTable::get(TransmissionMasking::Pbrt); }},
        {"ms-albedo", "the albedo of a rough microsurface's scattering orders ≥ 2 (the walk)",
         [] { MultipleScatteringAlbedo::get(); }},
    };
}

}  // namespace lamina
