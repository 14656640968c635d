// main.cpp — `sylva`: one executable with git-style subcommands (docs/spec/cli.md).
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "app/bench/bench.h"
#include "app/cli/cli.h"
#include "app/studio/studio.h"
#include "core/cpu/sun_maps.h"
#include "core/geometry/tessellate.h"
#include "core/util/file_io.h"

namespace {

void print_help(std::ostream& out) {
  out << "usage: sylva SUBCOMMAND [ARGS...]\n\n"
               "sylva grows plants from L-system grammars (The Algorithmic Beauty of Plants, cpfg).\n\n"
               "subcommands:\n"
               "  derive GRAMMAR [-n STEPS] [--seed S] [-D NAME=VALUE]...   print the derived word\n"
               "  grow   GRAMMAR [-n STEPS] [--seed S] [-D ...] -o FILE.skel.json\n"
               "                                      write the skeleton and print a summary\n"
               "  render INPUT -o IMAGE [--backend auto|gl|cpu] [--aov ...]   render to PNG/EXR\n"
               "  export INPUT -o FILE.gltf|FILE.glb [--mesh]   glTF 2.0 with the skeleton in extras\n"
               "  studio [INPUT] [--screenshot OUT.png]   edit a grammar and watch the plant regrow\n"
               "  bench  lsystem [--quick]            derivation and turtle benchmarks\n"
               "  bench  raycast                      primary rays per second: sylva's BVH against Embree\n"
               "  bench  geometry                     error against run time of frusta, relief, meshes\n"
               "  bench  gpu                          GPU time per frame and error of the GL backend\n"
               "  bench  fog                          sun photons and shadow cones against the photon count\n"
               "  bench  spp                          sampling error of both backends against samples per pixel\n"
               "  bench  studio [--quick]             the studio's edit-to-picture latency, frame time, memory\n\n"
               "'sylva SUBCOMMAND --help' describes every flag; 'sylva --version' prints the version.\n"
               "Exit status: 0 success, 1 bad input, 2 usage error, 3 internal error.\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sylva::cli;
  // An interrupt leaves no temporary, and outputs never land on an input (docs/limits.md,
  // "Outputs") — except in the studio, which saves over the document it opened.
  sylva::remove_temporaries_on_signals();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << "sylva: error: missing SUBCOMMAND\n\n";
    print_help(std::cerr);
    return kUsageError;
  }
  const std::string sub = args[0];
  args.erase(args.begin());
  if (sub == "derive" || sub == "grow" || sub == "render" || sub == "export") sylva::refuse_outputs_onto_inputs();
  try {
    if (sub == "-h" || sub == "--help" || sub == "help") {
      print_help(std::cout);
      return kOk;
    }
    if (sub == "--version" || sub == "version") {
      std::cout << "sylva " SYLVA_VERSION "\n";
      return kOk;
    }
    if (sub == "derive") return run_derive(args);
    if (sub == "grow") return run_grow(args);
    if (sub == "bench" && !args.empty() && args[0] == "studio") return sylva::studio::run_bench_studio(args);
    if (sub == "bench") return run_bench(args);
    if (sub == "render") return run_render(args);
    if (sub == "export") return run_export(args);
    if (sub == "studio") return sylva::studio::run_studio(args);
    std::cerr << "sylva: error: unknown subcommand '" << sub << "' (see 'sylva --help')\n";
    return kUsageError;
  } catch (const UsageError& e) {
    std::cerr << "sylva " << sub << ": error: " << e.message << " (see 'sylva " << sub << " --help')\n";
    return kUsageError;
  } catch (const sylva::MeshTooLarge& e) {  // refused before allocating (docs/limits.md)
    std::cerr << "sylva " << sub << ": error: " << e.what() << "\n";
    return kInputError;
  } catch (const sylva::SunMapsRefused& e) {  // the same for the fog's sun maps (docs/fog-map.md)
    std::cerr << "sylva " << sub << ": error: " << e.what() << "\n";
    return kInputError;
  } catch (const std::bad_alloc&) {
    std::cerr << "sylva: error: out of memory\n";
    return kInternalError;
  } catch (const std::exception& e) {
    std::cerr << "sylva: internal error: " << e.what() << "\n";
    return kInternalError;
  }
}
