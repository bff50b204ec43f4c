#include "distributed/launch.h"

#include "distributed/communicator.h"

#include <omp.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>

namespace lamina {

namespace {

std::optional<int> positive_int(const char* text) {
    if (!text) return std::nullopt;
    char* end = nullptr;
    const long v = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || v < 1 || v > 1'000'000) return std::nullopt;
    return int(v);
}

}  // namespace

Launch detect_launch() {
    Launch launch;
    // In order of precedence; the first present is the evidence.
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"}) {
        if (const char* value = std::getenv(name)) {
            launch.by_mpi_launcher = true;
            launch.evidence = name;
            if (std::string(name) != "PMIX_RANK" && std::string(name) != "PMI_RANK")
                launch.processes = positive_int(value);
            break;
        }
    }
    if (launch.by_mpi_launcher && !launch.processes) {
        if (auto n = positive_int(std::getenv("OMPI_COMM_WORLD_SIZE")))
            launch.processes = n;
        else if (auto m = positive_int(std::getenv("PMI_SIZE")))
            launch.processes = m;
    }
    return launch;
}

int cpus_allowed() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) != 0) return cpus_online();
    return std::max(1, CPU_COUNT(&set));
}

int cpus_online() {
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? int(n) : 1;
}

int default_threads_per_process(const Communicator& comm) {
    if (std::getenv("OMP_NUM_THREADS")) return std::max(1, omp_get_max_threads());
    const int allowed = cpus_allowed(), online = cpus_online();
    if (allowed < online) return allowed;  // the launcher gave this process its own CPUs
    return std::max(1, online / std::max(1, comm.local_size()));
}

}  // namespace lamina
