// Communicator over MPI (LAMINA_MPI=ON). Only the main thread calls MPI (MPI_THREAD_FUNNELED);
// OpenMP threads never do.
#include "core/check.h"
#include "core/error.h"
#include "distributed/communicator.h"
#include "distributed/launch.h"
#include "distributed/sums_buffer.h"

#include <fmt/format.h>
#include <mpi.h>

#include <climits>
#include <cstdio>
#include <cstdlib>

namespace lamina {

namespace {

// Posts to the root carry this tag; what they hold says what they are.
constexpr int kPostTag = 7101;

int checked_count(std::size_t n) {
    LAMINA_CHECK(n <= std::size_t(INT_MAX));
    return int(n);
}

// The MPI_Op of sum_to_root: adds 128-bit integers (MPI has no 128-bit integer type). Integer
// addition is commutative and associative, so MPI may combine in any order.
void add_fixed128(void* in, void* inout, int* len, MPI_Datatype*) {
    add_flat_sums(static_cast<const Fixed128*>(in), static_cast<Fixed128*>(inout),
                  std::size_t(*len));
}

}  // namespace

struct Communicator::Pending {
    std::string bytes;
    MPI_Request request = MPI_REQUEST_NULL;
};

Communicator& Communicator::world() {
    static Communicator instance;
    return instance;
}

Communicator::Communicator() {
    const Launch launch = detect_launch();
    if (!launch.by_mpi_launcher) return;  // a plain run: one process, no MPI
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    initialized_ = true;
    // Errors in MPI calls abort the run (the default handler, stated here on purpose).
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    // The ranks sharing this machine's memory (MPI-3).
    MPI_Comm local;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
    MPI_Comm_size(local, &local_size_);
    MPI_Comm_free(&local);
}

Communicator::~Communicator() {
    if (!initialized_) return;
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (finalized) return;
    flush_posts();
    MPI_Finalize();
}

void Communicator::barrier() {
    if (size_ > 1) MPI_Barrier(MPI_COMM_WORLD);
}

void Communicator::broadcast(std::string& bytes) {
    if (size_ == 1) return;
    unsigned long long n = bytes.size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
    bytes.resize(std::size_t(n));
    MPI_Bcast(bytes.data(), checked_count(bytes.size()), MPI_BYTE, 0, MPI_COMM_WORLD);
}

std::vector<std::string> Communicator::gather(const std::string& bytes) {
    if (size_ == 1) return {bytes};
    const int n = checked_count(bytes.size());
    std::vector<int> counts(is_root() ? size_ : 0), offsets(is_root() ? size_ : 0);
    MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::string all;
    if (is_root()) {
        std::size_t total = 0;
        for (int r = 0; r < size_; ++r) {
            offsets[r] = checked_count(total);
            total += std::size_t(counts[r]);
        }
        all.resize(total);
        checked_count(total);
    }
    MPI_Gatherv(bytes.data(), n, MPI_BYTE, all.data(), counts.data(), offsets.data(), MPI_BYTE, 0,
                MPI_COMM_WORLD);
    std::vector<std::string> out;
    for (int r = 0; is_root() && r < size_; ++r)
        out.push_back(all.substr(std::size_t(offsets[r]), std::size_t(counts[r])));
    return out;
}

void Communicator::post_to_root(std::string bytes) {
    LAMINA_CHECK(!is_root() && size_ > 1);
    auto p = std::make_unique<Pending>();
    p->bytes = std::move(bytes);
    MPI_Isend(p->bytes.data(), checked_count(p->bytes.size()), MPI_BYTE, 0, kPostTag,
              MPI_COMM_WORLD, &p->request);
    pending_.push_back(std::move(p));
    // Forget the posts already received (their buffers may go).
    std::erase_if(pending_, [](const std::unique_ptr<Pending>& q) {
        int done = 0;
        MPI_Test(&q->request, &done, MPI_STATUS_IGNORE);
        return done != 0;
    });
}

void Communicator::flush_posts() {
    for (const auto& p : pending_)
        MPI_Wait(&p->request, MPI_STATUS_IGNORE);
    pending_.clear();
}

std::optional<RankMessage> Communicator::receive_at_root(bool wait) {
    LAMINA_CHECK(is_root());
    if (size_ == 1) return std::nullopt;
    MPI_Status status;
    if (wait) {
        MPI_Probe(MPI_ANY_SOURCE, kPostTag, MPI_COMM_WORLD, &status);
    } else {
        int arrived = 0;
        MPI_Iprobe(MPI_ANY_SOURCE, kPostTag, MPI_COMM_WORLD, &arrived, &status);
        if (!arrived) return std::nullopt;
    }
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    RankMessage m;
    m.source = status.MPI_SOURCE;
    m.bytes.resize(std::size_t(count));
    MPI_Recv(m.bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, kPostTag, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    return m;
}

void Communicator::sum_to_root(std::vector<IncidenceSums>& sums) {
    if (size_ == 1) return;
    std::vector<Fixed128> mine = flatten_sums(sums);
    // Every rank must contribute the same count (a mismatch would be a bug, not bad input).
    unsigned long long n = mine.size(), n_min = 0, n_max = 0;
    MPI_Allreduce(&n, &n_min, 1, MPI_UNSIGNED_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&n, &n_max, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    if (n_min != n_max)
        abort(fmt::format("internal error: the ranks' sums differ in size ({} to {} integers)",
                          n_min, n_max));
    MPI_Datatype int128;
    MPI_Type_contiguous(int(sizeof(Fixed128)), MPI_BYTE, &int128);
    MPI_Type_commit(&int128);
    MPI_Op add;
    MPI_Op_create(&add_fixed128, /*commute=*/1, &add);
    std::vector<Fixed128> total(is_root() ? mine.size() : 0);
    MPI_Reduce(mine.data(), total.data(), checked_count(mine.size()), int128, add, 0,
               MPI_COMM_WORLD);
    MPI_Op_free(&add);
    MPI_Type_free(&int128);
    if (is_root()) unflatten_sums(total, sums);
}

void Communicator::abort(const std::string& message, int exit_code) {
    if (size_ > 1)
        std::fprintf(stderr, "lamina (process %d of %d): %s\n", rank_, size_, message.c_str());
    else
        std::fprintf(stderr, "lamina: %s\n", message.c_str());
    std::fflush(stderr);
    if (initialized_ && size_ > 1) MPI_Abort(MPI_COMM_WORLD, exit_code);
    if (initialized_) MPI_Finalize();  // alone: an orderly exit
    std::exit(exit_code);
}

}  // namespace lamina
