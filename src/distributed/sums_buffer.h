#pragma once
// The integer sums of a simulation as one flat array of 128-bit integers, the form in which they
// travel between processes (communicator.h). Element-wise addition of two flat arrays is
// IncidenceSums::add of the sums they hold, so any exact reduction of the arrays is exact.
//
// Layout per incidence, in order: bins (6 integers per bin: Σ flux r, g, b, Σ flux² r, g, b),
// budget rows (3 per row), events, degenerate, then the Stokes tallies when there are any
// (kStokesSums per bin).

#include "simulator/goniophotometer.h"

#include <cstddef>
#include <vector>

namespace lamina {

/// Integers per incidence of `bins` bins (both sides together, as IncidenceSums::bins), and
/// `stokes` entries of Stokes tallies (0 or bins).
std::size_t flat_sums_size(std::size_t bins, std::size_t stokes = 0);

std::vector<Fixed128> flatten_sums(const std::vector<IncidenceSums>& sums);

/// Writes `flat` back into `sums`, which must already have the shape `flat` was made from
/// (CHECKed: the incidence count and bin counts).
void unflatten_sums(const std::vector<Fixed128>& flat, std::vector<IncidenceSums>& sums);

/// Element-wise `into[i] += from[i]` over `count` integers (the reduction's operation).
void add_flat_sums(const Fixed128* from, Fixed128* into, std::size_t count);

}  // namespace lamina
