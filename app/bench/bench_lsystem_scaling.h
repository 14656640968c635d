// bench_lsystem_scaling.h — `sylva bench lsystem`'s scaling rows: the work bounds of
// docs/limits.md "Work" (declared names, printing, context across branches, interpretation
// depth) measured at doubling sizes, so a row whose time per item grows shows a
// non-linear walk. Google Benchmark fits each family's complexity (the `_BigO` row).
#pragma once

namespace sylva::cli {

// Registers the scaling benchmarks (sizes 10 k, 20 k, 40 k; --quick: 1 k, 2 k, 4 k).
void register_lsystem_scaling_benchmarks(bool quick);

}  // namespace sylva::cli
