// studio.h — the entry point of `sylva studio` (docs/spec/studio.md), dispatched by
// app/main.cpp.
#pragma once

#include <string>
#include <vector>

namespace sylva::studio {

// Runs the studio with the arguments after "studio"; returns the exit status (cli.h).
// Throws cli::UsageError for bad arguments.
int run_studio(const std::vector<std::string>& args);

// `sylva bench studio [--quick]` (bench_studio.cpp): edit-to-picture latency, UI frame
// time during a long derivation, memory over many regrows; args start with "studio".
int run_bench_studio(const std::vector<std::string>& args);

}  // namespace sylva::studio
