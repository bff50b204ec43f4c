#pragma once
// A study's reference spread over the processes of a run (`mpirun -n K lamina study …`,
// docs/scaling.md). The reference pieces (one per configuration × incidence, study/reference.h) are
// dealt round robin, in the study's fixed order, to the ranks; each rank simulates its pieces and
// sends their bytes to the root, which stores them in its cache exactly as one process would have
// (the same bytes, bar the piece's `seconds`). The root then runs the study alone: every piece is
// in its cache, so the outputs are those of a one-process run. No shared file system is assumed:
// only the root reads the cache or writes.

#include "distributed/communicator.h"
#include "study/configurations.h"
#include "study/reference.h"
#include "study/study.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace lamina {

/// The study's reference pieces in run_study's order: configuration by configuration, incidence
/// by incidence.
std::vector<ReferenceKey> study_reference_keys(const std::vector<StudyConfiguration>& configs,
                                               const StudySettings& settings);

/// Collective over `comm`. At the root, `keys` and `cache_dir` say what the study needs and where
/// its cache is; the pieces missing from the cache are computed over all ranks and stored there.
/// The other ranks pass empty `keys` and `cache_dir` and learn their work from the root. Each rank
/// simulates with `threads` threads (0: all of OpenMP's); the root draws the progress of its own
/// pieces (stderr, on a terminal). Returns the number of pieces computed (at the root; 0
/// elsewhere). With one process it does nothing: run_study computes the pieces as it goes.
std::size_t share_reference_pieces(Communicator& comm, const std::filesystem::path& cache_dir,
                                   const std::vector<ReferenceKey>& keys, int threads);

}  // namespace lamina
