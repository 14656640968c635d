// gl_crotch_fade.cpp — see gl_crotch_fade.h.
#include "core/gl/gl_crotch_fade.h"

#include <cassert>

namespace sylva {

GlCrotchFadeTables pack_crotch_fade(std::span<const Crotch> crotches, std::span<const GpuSegment> records) {
  GlCrotchFadeTables t;
  if (crotches.empty()) return t;
  // Each record's crotch list, in crotch order.
  const CrotchesOfFrusta of_record = crotches_of_frusta(crotches, records.size());
  t.lists.assign(records.size(), 0);
  for (uint32_t r = 0; r < records.size(); ++r) {
    const std::span<const uint32_t> list = of_record.of(r);
    if (list.empty()) continue;
    t.lists[r] = static_cast<uint32_t>(t.lists.size());
    t.lists.push_back(static_cast<uint32_t>(list.size()));
    t.lists.insert(t.lists.end(), list.begin(), list.end());
  }
  for (const Crotch& c : crotches) {
    assert(!c.parent_frusta.empty() && c.depth.size() <= kCrotchDepthSamples);
    gl::GpuCrotchRecord g{};
    const GpuSegment& frame = records[c.parent_frusta.front()];
    const glm::dvec3 origin(frame.origin_hi[0], frame.origin_hi[1], frame.origin_hi[2]);
    for (int i = 0; i < 3; ++i) {
      g.origin_hi[i] = frame.origin_hi[i];
      g.centre[i] = static_cast<float>(c.centre[i] - origin[i]);
      g.start[i] = static_cast<float>(c.start[i] - origin[i]);
      g.direction[i] = static_cast<float>(c.direction[i]);
    }
    g.radius = static_cast<float>(c.radius);
    g.k = static_cast<float>(c.k);
    g.lateral_radius = static_cast<float>(c.lateral_radius);
    g.depth_step = static_cast<float>(c.depth_step);
    g.parent_first = static_cast<uint32_t>(t.lists.size());
    g.parent_count = static_cast<uint32_t>(c.parent_frusta.size());
    t.lists.insert(t.lists.end(), c.parent_frusta.begin(), c.parent_frusta.end());
    g.lateral_first = static_cast<uint32_t>(t.lists.size());
    g.lateral_count = static_cast<uint32_t>(c.lateral_frusta.size());
    t.lists.insert(t.lists.end(), c.lateral_frusta.begin(), c.lateral_frusta.end());
    g.depth_count = static_cast<uint32_t>(c.depth.size());
    for (size_t i = 0; i < c.depth.size(); ++i) g.depth[i] = static_cast<float>(c.depth[i]);
    t.crotches.push_back(g);
  }
  return t;
}

}  // namespace sylva
