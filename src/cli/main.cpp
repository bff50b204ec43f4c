// The `lamina` executable: the command-line interface of cli/run.cpp.
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "simulator/goniophotometer.h"

#include <fmt/format.h>

#ifdef __GLIBC__
#include <malloc.h>
#endif

int main(int argc, char** argv) {
#ifdef __GLIBC__
    // A study allocates and frees tables of a few to some tens of MB per model, configuration and
    // thread. glibc serves blocks that large from fresh mappings, returned on free, so every one
    // was faulted in and zeroed again: 0.64 M page faults and 5 s of system time on the quick
    // study. Kept in the heap instead (0.1 M faults, 1.2 s; the peak memory unchanged, 0.35 GB;
    // docs/performance.md, "The quick study").
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
    lamina::remove_staging_on_interrupt();
    if (const int asked = lamina::cap_openmp_threads())
        fmt::print(stderr,
                   "lamina: warning: OpenMP asked for {} threads (OMP_NUM_THREADS); "
                   "running at most {}\n",
                   asked, lamina::kMaxThreads);
    return lamina::cli::run(argc, argv);
}
