// Communicator without MPI (LAMINA_MPI=OFF): always one process, rank 0; every operation is the
// identity.
#include "core/check.h"
#include "core/error.h"
#include "distributed/communicator.h"
#include "distributed/launch.h"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>

namespace lamina {

struct Communicator::Pending {};

Communicator& Communicator::world() {
    static Communicator instance;
    return instance;
}

Communicator::Communicator() {
    const Launch launch = detect_launch();
    if (launch.by_mpi_launcher && launch.processes.value_or(1) > 1)
        throw InputError("launch", launch.evidence,
                         fmt::format("started as one of {} processes, but this lamina was built "
                                     "without MPI (LAMINA_MPI=OFF): install libopenmpi-dev "
                                     "(make deps) and rebuild, or run one process",
                                     *launch.processes));
}

Communicator::~Communicator() = default;

void Communicator::barrier() {}
void Communicator::broadcast(std::string&) {}
std::vector<std::string> Communicator::gather(const std::string& bytes) {
    return {bytes};
}
void Communicator::post_to_root(std::string) {
    LAMINA_CHECK(false && "one process: no root to post to");
}
void Communicator::flush_posts() {}
std::optional<RankMessage> Communicator::receive_at_root(bool) {
    return std::nullopt;
}
void Communicator::sum_to_root(std::vector<IncidenceSums>&) {}

void Communicator::abort(const std::string& message, int exit_code) {
    std::fprintf(stderr, "lamina: %s\n", message.c_str());
    std::exit(exit_code);
}

}  // namespace lamina
