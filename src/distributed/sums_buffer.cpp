#include "distributed/sums_buffer.h"

#include "core/check.h"

namespace lamina {

std::size_t flat_sums_size(std::size_t bins, std::size_t stokes) {
    return bins * 6 + std::size_t(kBudgetTerms + 2) * 3 + 2 + stokes * kStokesSums;
}

std::vector<Fixed128> flatten_sums(const std::vector<IncidenceSums>& sums) {
    std::vector<Fixed128> flat;
    std::size_t total = 0;
    for (const IncidenceSums& s : sums)
        total += flat_sums_size(s.bins.size(), s.stokes.size());
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
    }
    LAMINA_CHECK(at == flat.size());
}

void add_flat_sums(const Fixed128* from, Fixed128* into, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i)
        into[i] += from[i];
}

}  // namespace lamina
