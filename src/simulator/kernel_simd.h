#pragma once
// The batched SIMD particle kernel (goniophotometer.h, Kernel::Simd).

#include "simulator/tally.h"

namespace lamina {

/// Traces the block's particles as lanes of SIMD vectors; same contract as trace_block_scalar.
void trace_block_simd(const BlockJob& job, Tally& tally, BlockBudget& block);

/// Applies LAMINA_SIMD_TARGET (an instruction set name as simd_target_name prints it, e.g. AVX2 or
/// SSE4), which caps the dispatch at that set: the way to reproduce another machine's tables, or to
/// test every compiled set on one machine. Once per process; InputError for an unknown or
/// unsupported name.
void select_simd_target();

/// The instruction set the SIMD kernel dispatches to on this machine (e.g. "AVX3"), after
/// LAMINA_SIMD_TARGET.
const char* simd_target_name();

}  // namespace lamina
