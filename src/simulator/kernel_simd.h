#pragma once
// The batched SIMD particle kernel (goniophotometer.h, Kernel::Simd).

#include "simulator/tally.h"

namespace lamina {

/// Traces the block's particles as lanes of SIMD vectors; same contract as trace_block_scalar.
void trace_block_simd(const BlockJob& job, Tally& tally, BlockBudget& block);

/// The instruction set the SIMD kernel dispatches to on this machine (e.g. "AVX3_ZEN4").
const char* simd_target_name();

}  // namespace lamina
