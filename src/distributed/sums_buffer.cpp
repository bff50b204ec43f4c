#include "distributed/sums_buffer.h"

#include "core/check.h"

namespace lamina {

std::size_t flat_sums_size(std::size_t bins, std::size_t stokes) {
    return bins * 6 + std::size_t(kBudgetTerms + 2) * 3 + 2 + stokes * kStokesSums;
}

namespace {
/// The spectral sums of a spectral run (IncidenceSums), after the others.
std::size_t spectral_size(const IncidenceSums& s) {
    return (s.spectral_bins.size() + s.xyz_bins.size()) * 6 +
           (s.spectral_budget.size() + 1) * std::size_t(kBudgetTerms + 2) * 3;
}
}  // namespace

std::vector<Fixed128> flatten_sums(const std::vector<IncidenceSums>& sums) {
    std::vector<Fixed128> flat;
    std::size_t total = 0;
    for (const IncidenceSums& s : sums)
        total += flat_sums_size(s.bins.size(), s.stokes.size()) +
                 (s.spectral_bins.empty() ? 0 : spectral_size(s));
    flat.reserve(total);
    for (const IncidenceSums& s : sums) {
        for (const auto& bin : s.bins)
            flat.insert(flat.end(), bin.begin(), bin.end());
        for (const auto& row : s.budget)
            flat.insert(flat.end(), row.begin(), row.end());
        flat.push_back(Fixed128(s.events));
        flat.push_back(Fixed128(s.degenerate));
        for (const auto& entry : s.stokes)
            flat.insert(flat.end(), entry.begin(), entry.end());
        if (s.spectral_bins.empty()) continue;
        for (const auto* bins : {&s.spectral_bins, &s.xyz_bins})
            for (const auto& bin : *bins)
                flat.insert(flat.end(), bin.begin(), bin.end());
        for (const auto& budget : s.spectral_budget)
            for (const auto& row : budget)
                flat.insert(flat.end(), row.begin(), row.end());
        for (const auto& row : s.xyz_budget)
            flat.insert(flat.end(), row.begin(), row.end());
    }
    return flat;
}

void unflatten_sums(const std::vector<Fixed128>& flat, std::vector<IncidenceSums>& sums) {
    std::size_t at = 0;
    for (IncidenceSums& s : sums) {
        LAMINA_CHECK(at + flat_sums_size(s.bins.size(), s.stokes.size()) <= flat.size());
        for (auto& bin : s.bins)
            for (Fixed128& x : bin)
                x = flat[at++];
        for (auto& row : s.budget)
            for (Fixed128& x : row)
                x = flat[at++];
        s.events = std::uint64_t(flat[at++]);
        s.degenerate = std::uint64_t(flat[at++]);
        for (auto& entry : s.stokes)
            for (Fixed128& x : entry)
                x = flat[at++];
        if (s.spectral_bins.empty()) continue;
        LAMINA_CHECK(at + spectral_size(s) <= flat.size());
        for (auto* bins : {&s.spectral_bins, &s.xyz_bins})
            for (auto& bin : *bins)
                for (Fixed128& x : bin)
                    x = flat[at++];
        for (auto& budget : s.spectral_budget)
            for (auto& row : budget)
                for (Fixed128& x : row)
                    x = flat[at++];
        for (auto& row : s.xyz_budget)
            for (Fixed128& x : row)
                x = flat[at++];
    }
    LAMINA_CHECK(at == flat.size());
}

void add_flat_sums(const Fixed128* from, Fixed128* into, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i)
        into[i] += from[i];
}

}  // namespace lamina
