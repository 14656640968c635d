// bench_gpu_fog.h — `sylva bench gpu --fog`: the GL fog pass's error against its GPU time
// (docs/benchmarks.md, "GL fog"), one row per way the GL backend draws the fog.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/gl/gl_context.h"

namespace sylva::cli {

struct GpuFogArgs {
  std::vector<std::string> inputs;  // foggy scenes (resolved); empty: the elm grove at a low sun
  std::vector<std::pair<uint32_t, uint32_t>> sizes;
  uint32_t frames = 10, warmup = 2;
  uint32_t reference_stride = 1;  // the CPU reference (and the error) on every S-th pixel each way
  bool quick = false;  // brute 16 and 64 only, 200 000 photons at most
  std::string csv, plot;
};

// Per input and size: the CPU's reference fog (fog mode reference at the scene's steps,
// through the pixel centres of every reference_stride-th pixel each way), then brute at
// N ∈ {16, 32, 64, 128, 256} steps, fast and medium (the cones built once per kind, as
// render_gl builds them), each `warmup` + `frames` frames; a row per method — the fog
// pass's and the cone pass's GPU ms (GlFrameStats, median), the frame's, and the RMSE of
// the fog AOV's in-scatter against the reference — printed and appended to the CSV as it
// finishes; then the log-log plot (RMSE against fog GPU ms). Returns the exit code.
int run_gpu_fog_rows(const GpuFogArgs& args, const std::string& device, const GlContextInfo& gl);

}  // namespace sylva::cli
