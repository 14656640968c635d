// cli.h — the `sylva` command line's subcommands (docs/spec/cli.md); app/main.cpp
// dispatches to them, the benchmarks (app/bench/bench.h) and the studio. Shared flags and
// exit statuses: app/front/args.h.
#pragma once

#include <string>
#include <vector>

#include "app/front/args.h"

namespace sylva::cli {

int run_derive(const std::vector<std::string>& args);
int run_grow(const std::vector<std::string>& args);
int run_render(const std::vector<std::string>& args);
int run_export(const std::vector<std::string>& args);

}  // namespace sylva::cli
