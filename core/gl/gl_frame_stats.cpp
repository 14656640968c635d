// gl_frame_stats.cpp — see gl_frame_stats.h.
#include "core/gl/gl_frame_stats.h"

namespace sylva {

const char* gl_pass_name(GlPass pass, GeometryKind geometry) {
  switch (pass) {
    case GlPass::shadow: return "shadow map";
    case GlPass::geometry: return geometry == GeometryKind::mesh ? "mesh" : "frusta";
    case GlPass::shade: return "shade";
    case GlPass::fog_cones: return "fog cones";
    case GlPass::fog: return "fog";
    case GlPass::present: return "present";
  }
  return "?";
}

double GlFrameStats::gpu_s() const {
  double total = 0;
  for (const GlPassStats& p : passes) total += p.gpu_s;
  return total;
}

std::vector<RenderPass> describe_frame(const GlFrameStats& s) {
  std::vector<RenderPass> out;
  auto gpu = [&](GlPass pass) { return std::string(gl_pass_name(pass, s.geometry)) + " (GPU)"; };
  auto runs = [&](GlPass pass) { return std::to_string(s.pass(pass).runs) + " pass(es), "; };
  if (s.compile_s > 0) out.push_back({"programs", s.compile_s, "built for this frame: " + s.compiled});
  if (s.shadow_texels > 0)
    out.push_back({gpu(GlPass::shadow), s.pass(GlPass::shadow).gpu_s,
                   std::to_string(s.shadow_texels) + "x" + std::to_string(s.shadow_texels) + ", " +
                       runs(GlPass::shadow) + s.pass(GlPass::shadow).program});
  const GlPassStats& geometry = s.pass(GlPass::geometry);
  if (s.geometry == GeometryKind::mesh)
    out.push_back({gpu(GlPass::geometry), geometry.gpu_s,
                   std::to_string(s.triangles) + " triangles (" + s.geometry_label + "), " + runs(GlPass::geometry) +
                       geometry.program});
  else
    out.push_back({gpu(GlPass::geometry), geometry.gpu_s,
                   std::to_string(s.frusta) + " frusta, " + runs(GlPass::geometry) + geometry.program +
                       (s.eye_inside ? ", " + std::to_string(s.eye_inside) + " around the eye" : "")});
  out.push_back({gpu(GlPass::shade), s.pass(GlPass::shade).gpu_s, runs(GlPass::shade) + s.pass(GlPass::shade).program});
  if (s.fog_cones > 0)
    out.push_back({gpu(GlPass::fog_cones), s.pass(GlPass::fog_cones).gpu_s,
                   std::to_string(s.fog_cones) + " cones, " + runs(GlPass::fog_cones) +
                       (s.fog_counted ? std::to_string(s.fog_fragments) + " intervals, " +
                                            std::to_string(s.fog_overflow_pixels) + " pixels overflowed, "
                                      : std::string()) +
                       s.pass(GlPass::fog_cones).program});
  if (!s.fog_mode.empty())
    out.push_back({gpu(GlPass::fog), s.pass(GlPass::fog).gpu_s,
                   s.fog_mode + ", " + std::to_string(s.fog_steps) + " steps, " + runs(GlPass::fog) +
                       s.pass(GlPass::fog).program});
  if (s.presented)
    out.push_back({gpu(GlPass::present), s.pass(GlPass::present).gpu_s,
                   std::to_string(s.width) + "x" + std::to_string(s.height) + ", " + s.pass(GlPass::present).program});
  return out;
}

}  // namespace sylva
