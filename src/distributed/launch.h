#pragma once
// How this process was started: by an MPI launcher or plainly (communicator.h lists the variables
// read and why).

#include <optional>
#include <string>

namespace lamina {

struct Launch {
    bool by_mpi_launcher = false;
    /// The variable that told, e.g. "OMPI_COMM_WORLD_SIZE" (empty for a plain start).
    std::string evidence;
    /// The process count the launcher announced, when it did (OMPI_COMM_WORLD_SIZE, PMI_SIZE).
    std::optional<int> processes;
};

/// Reads the environment; no MPI call.
Launch detect_launch();

/// CPUs this process may run on (its affinity mask) and CPUs online on the machine (both ≥ 1).
int cpus_allowed();
int cpus_online();

}  // namespace lamina
