#pragma once
// The study's reference for one (configuration, incidence): the goniophotometer run as two
// independent halves (different seeds), stored once on disk and reused by every later run
// (resumable studies). The reference is the halves' average; the metrics between the halves give
// the noise floor.

#include "core/grid.h"
#include "core/rgb.h"
#include "layers/stack.h"
#include "simulator/goniophotometer.h"
#include "study/metrics.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

struct ReferenceKey {
    std::string config_id;
    Stack stack;
    /// The goniophotometer's settings of the piece: one incidence, the particles of both halves
    /// together, the seed of the first half, the grid, the kernel (its description, with the SIMD
    /// instruction set, is part of the key, since tables are bitwise reproducible per kernel
    /// description only) and the transport. The threads are not part of the key. With
    /// settings.stokes_tallies (a polarized reference, not spectral) the piece carries the Stokes
    /// vectors too (ReferencePiece::stokes): they do not change its tables, so the key's text does
    /// not say it, and a piece without them is computed again for a key that asks for them.
    SimulationSettings settings;

    double theta_i_deg() const { return settings.theta_i_deg.front(); }
    double phi_i_deg() const { return settings.phi_i_deg; }
    /// The grid the piece is tabulated on: settings.grid, unfolded for an anisotropic stack or
    /// φi ≠ 0 (simulation_grid).
    HemisphereGrid grid() const { return simulation_grid(stack, settings); }

    /// A canonical text of every field, lamina's version and the digest of the reference's code
    /// (kReferenceSourceDigest: src/core, physics, layers and simulator, so that a kernel whose
    /// numbers changed is never served a table the old code cached), and its 64-bit FNV-1a hash.
    /// The settings a key has always held are written in a fixed form; the others as " | name
    /// value" where they differ from what the reference did before they existed
    /// (settings_key_text), so that caches made then stay valid. The refraction masking is
    /// written only where it changes the table (single scattering, a rough dielectric in the
    /// stack) and it is `smith`: caches made before the setting, with the pbrt form, are reused
    /// for `pbrt` only.
    std::string canonical() const;
    std::string file_name() const;
};

struct ReferencePiece {
    bool has_transmission = false;
    /// [side][bin of ReferenceKey::grid()]: the average of the halves and its standard error, as
    /// stored (float32).
    std::array<std::vector<Rgbd>, 2> f, se;
    /// [side][bin]: the Stokes components S1, S2, S3 (1/sr, per channel) of the light leaving into
    /// the bin for unpolarized incident light and their standard errors (simulator/mueller.h
    /// unpolarized_stokes; the average of the halves, S as float32 and its standard errors as
    /// float16, as stored); empty unless the key's settings have stokes_tallies.
    std::array<std::vector<std::array<Rgbd, 3>>, 2> stokes, stokes_se;
    EnergyBudget budget;                              ///< average of the halves
    std::array<std::array<LobeMetrics, 3>, 2> floor;  ///< [side][channel]
    double seconds = 0;
};

/// Loads the piece for `key` from `cache_dir` if it is there and intact (its stored key equals
/// `key`, its sizes match); otherwise simulates it (threads: 0 = all), stores it atomically and
/// returns it. `on_progress` receives particle counts while simulating. `computed` tells which.
ReferencePiece reference_piece(const std::filesystem::path& cache_dir, const ReferenceKey& key,
                               int threads, const std::function<void(std::uint64_t)>& on_progress,
                               bool* computed = nullptr);

/// The pieces of reference_piece, for callers that compute and store in different places (a
/// study spread over processes, study/distributed_reference.h):
/// the piece for `key` if `cache_dir` holds it intact, else empty;
std::optional<ReferencePiece> load_reference_piece(const std::filesystem::path& cache_dir,
                                                   const ReferenceKey& key);
/// simulates the piece and returns the bytes its cache file holds (no file is touched);
std::string compute_reference_piece(const ReferenceKey& key, int threads,
                                    const std::function<void(std::uint64_t)>& on_progress);
/// stores those bytes into `cache_dir` atomically and returns the piece as a later run reads it
/// back. InputError if the bytes are not a piece of `key`.
ReferencePiece store_reference_piece(const std::filesystem::path& cache_dir,
                                     const ReferenceKey& key, const std::string& bytes);

/// The seed of the second half, derived from the study's seed.
std::uint64_t second_half_seed(std::uint64_t seed);

/// The digest of the reference's code the keys hold (kReferenceSourceDigest).
const char* reference_code_digest();

/// The key of the incidence `theta_i_deg` (at reference.phi_i_deg) of a study's reference with the
/// settings `reference`.
ReferenceKey reference_key(const std::string& config_id, const Stack& stack, double theta_i_deg,
                           const SimulationSettings& reference);
/// The same with the light from azimuth `phi_i_deg` (the key says it only where it is not 0, so
/// that a piece lit from φi = 0 has the key it always had).
ReferenceKey reference_key(const std::string& config_id, const Stack& stack, double theta_i_deg,
                           const SimulationSettings& reference, double phi_i_deg);

}  // namespace lamina
