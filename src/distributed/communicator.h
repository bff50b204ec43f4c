#pragma once
// The processes of one lamina run (docs/scaling.md). `mpirun -n K lamina simulate|study …` starts
// K processes; Communicator::world() names them 0 … K−1 (rank 0, the root, reads the inputs and
// writes every output file; the others compute and send their results to it).
//
// Launch detection: MPI is initialized only when the process was started by an MPI launcher, i.e.
// when one of these variables is set (launch.h):
//   OMPI_COMM_WORLD_SIZE  (OpenMPI's mpirun),
//   PMIX_RANK             (any PMIx launcher: OpenMPI ≥ 4, `srun --mpi=pmix`),
//   PMI_SIZE, PMI_RANK    (MPICH/Hydra, Intel MPI, `srun --mpi=pmi2`).
// SLURM_PROCID alone is not taken as a launch: a Slurm batch script sets it for the script itself,
// where lamina must run as one plain process. A plain `lamina …` never touches MPI; it is one
// process of rank 0 (so are the tests).
//
// Every operation below is collective over all ranks (each must call it, in the same order) unless
// it says otherwise. With one process each is the identity and calls no MPI function. MPI is
// finalized when the process exits normally; an error on any rank ends all of them (abort), never
// leaves the others waiting.
//
// Assumes the ranks run the same lamina binary on machines of the same byte order (the sums travel
// as raw 128-bit integers). No shared file system is assumed: only rank 0 reads and writes files.

#include "simulator/goniophotometer.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

/// A message posted to the root (Communicator::post_to_root).
struct RankMessage {
    int source = 0;  ///< the rank that posted it
    std::string bytes;
};

class Communicator {
  public:
    /// The processes of this run: initializes MPI on the first call if the process was launched by
    /// an MPI launcher (see above). Throws InputError when launched as one of several processes
    /// by a lamina built without MPI (LAMINA_MPI=OFF), so that K copies never all act as the root.
    static Communicator& world();

    ~Communicator();
    Communicator(const Communicator&) = delete;
    Communicator& operator=(const Communicator&) = delete;

    int rank() const { return rank_; }
    int size() const { return size_; }
    bool is_root() const { return rank_ == 0; }
    /// More than one process: the run is split.
    bool distributed() const { return size_ > 1; }
    /// Processes of this run on this machine (≥ 1), this one included.
    int local_size() const { return local_size_; }

    void barrier();
    /// The root's `bytes` replace every other rank's.
    void broadcast(std::string& bytes);
    /// At the root: every rank's bytes in rank order (the root's own first). Elsewhere: empty.
    std::vector<std::string> gather(const std::string& bytes);

    /// Point to point (not collective). A non-root rank posts `bytes` to the root and goes on
    /// without waiting for the root to receive them (the bytes are kept until flush_posts).
    void post_to_root(std::string bytes);
    /// Waits until the root has received everything this rank posted.
    void flush_posts();
    /// At the root: the next posted message from any rank, in arrival order; waits for one if
    /// `wait`, else returns empty when none has arrived yet.
    std::optional<RankMessage> receive_at_root(bool wait);

    /// Sums `sums` over the ranks into the root's `sums` (IncidenceSums::add, exact integers, so
    /// the result does not depend on the order of additions). Every rank must hold the same number
    /// of incidences with the same bin count. Other ranks' `sums` are left unspecified.
    void sum_to_root(std::vector<IncidenceSums>& sums);

    /// Ends every process of the run: prints `lamina: <message>` (with the rank when there are
    /// several) on stderr and exits with `exit_code` (≠ 0). Callable from one rank alone.
    [[noreturn]] void abort(const std::string& message, int exit_code = 1);

  private:
    Communicator();
    int rank_ = 0, size_ = 1, local_size_ = 1;
    bool initialized_ = false;  // this process called MPI_Init
    struct Pending;
    std::vector<std::unique_ptr<Pending>> pending_;  // posts not yet known to be received
};

/// Threads for each process when the user gave none (`--threads 0`):
///  - OMP_NUM_THREADS when set (the user's choice, as OpenMP reads it);
///  - otherwise, when the launcher bound this process to fewer CPUs than the machine has (mpirun's
///    binding, `srun --cpus-per-task`), the CPUs it may run on;
///  - otherwise the machine's CPUs divided among the run's processes on it (at least 1), so that
///    `mpirun -n 2` on 2 cores does not oversubscribe.
/// With one process and no binding this is every CPU (as a plain run).
int default_threads_per_process(const Communicator& comm);

}  // namespace lamina
