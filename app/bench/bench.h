// bench.h — `sylva bench`: the benchmarks and error-against-time reports (docs/benchmarks.md).
#pragma once

#include <string>
#include <vector>

#include "app/front/args.h"

namespace sylva::cli {

// `sylva bench SUITE ...`: dispatches to the suites below (lsystem is its own).
int run_bench(const std::vector<std::string>& args);
// `sylva bench raycast` (bench_raycast.cpp).
int run_bench_raycast(const std::vector<std::string>& args);
// `sylva bench geometry` (bench_geometry.cpp).
int run_bench_geometry(const std::vector<std::string>& args);
// `sylva bench gpu` (bench_gpu.cpp).
int run_bench_gpu(const std::vector<std::string>& args);
// `sylva bench fog` (bench_fog.cpp).
int run_bench_fog(const std::vector<std::string>& args);
// `sylva bench spp` (bench_spp.cpp).
int run_bench_spp(const std::vector<std::string>& args);
// `sylva bench export` (bench_export.cpp).
int run_bench_export(const std::vector<std::string>& args);
// `sylva bench light` (bench_light.cpp).
int run_bench_light(const std::vector<std::string>& args);

}  // namespace sylva::cli
