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
    double theta_i_deg = 0;
    std::uint64_t particles = 0;  ///< in all, both halves together
    std::uint64_t seed = 1;
    HemisphereGrid grid;
    /// The particle kernel; its description (with the SIMD instruction set) is part of the key,
    /// since tables are bitwise reproducible per kernel description only.
    Kernel kernel = Kernel::Simd;
    /// Single- or multiple-scattering microsurfaces (part of the key when multiple; the text of
    /// single-scattering keys is what it was before the option existed, so their caches stay).
    Microsurface microsurface = Microsurface::Single;
    /// The refraction masking of single-scattering rough dielectrics (physics/microfacet.h).
    /// Part of the key where it changes the table (single scattering and a rough dielectric in
    /// the stack) and it is `smith`: caches made before the option, with the pbrt form, are then
    /// reused for `pbrt` only.
    TransmissionMasking transmission_masking = TransmissionMasking::Smith;

    /// A canonical text of every field, lamina's version and the digest of the reference's code
    /// (kReferenceSourceDigest: src/core, physics, layers and simulator, so that a kernel whose
    /// numbers changed is never served a table the old code cached), and its 64-bit FNV-1a hash.
    std::string canonical() const;
    std::string file_name() const;
};

struct ReferencePiece {
    bool has_transmission = false;
    /// [side][bin]: the average of the halves and its standard error, as stored (float32).
    std::array<std::vector<Rgbd>, 2> f, se;
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

}  // namespace lamina
