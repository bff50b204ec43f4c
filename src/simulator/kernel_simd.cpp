#include "simulator/kernel_simd.h"

namespace lamina {

// Placeholder while the Highway kernel is written: the scalar path.
void trace_block_simd(const BlockJob& job, Tally& tally, BlockBudget& block) {
    trace_block_scalar(job, tally, block);
}

const char* simd_target_name() { return "scalar-fallback"; }

}  // namespace lamina
