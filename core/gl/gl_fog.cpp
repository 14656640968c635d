// gl_fog.cpp — see gl_fog.h.
#include "core/gl/gl_fog.h"

#include <vector>

#include "core/gl/gl_api.h"
#include "core/gl/gl_context.h"

namespace sylva {

GlFogCones upload_fog_cones(const ConeSet& set) {
  GlFogCones out;
  const std::vector<ShadowCone>& cones = set.cones();
  for (const ShadowCone& c : cones) out.origin += c.base / static_cast<double>(cones.size());
  std::vector<gl::GpuShadowConeRecord> records;
  records.reserve(cones.size());
  for (const ShadowCone& c : cones) {
    const ShadowConeGeometry g = cone_geometry(c);
    const glm::dvec3 base = g.base - out.origin;
    gl::GpuShadowConeRecord r;
    r.base_radius0[0] = static_cast<float>(base.x);
    r.base_radius0[1] = static_cast<float>(base.y);
    r.base_radius0[2] = static_cast<float>(base.z);
    r.base_radius0[3] = static_cast<float>(g.radius0);
    r.axis_end[0] = static_cast<float>(g.axis.x);
    r.axis_end[1] = static_cast<float>(g.axis.y);
    r.axis_end[2] = static_cast<float>(g.axis.z);
    r.axis_end[3] = static_cast<float>(g.end);
    r.slope_plant[0] = static_cast<float>(g.slope);
    r.slope_plant[1] = static_cast<float>(c.plant);
    r.slope_plant[2] = r.slope_plant[3] = 0;
    records.push_back(r);
  }
  out.bytes = records.size() * sizeof(gl::GpuShadowConeRecord);
  out.records = make_gl_buffer(records.data(), out.bytes);
  out.count = static_cast<uint32_t>(records.size());
  check_gl("fog cones");
  return out;
}

uint32_t GlFogLists::reserve(uint32_t want_pixels, uint32_t want_capacity) {
  uint32_t allocated = 0;
  if (want_pixels > pixels) {
    heads = make_gl_buffer(nullptr, size_t{want_pixels} * 4, GL_DYNAMIC_STORAGE_BIT);
    overflow = make_gl_buffer(nullptr, size_t{want_pixels} * 4, GL_DYNAMIC_STORAGE_BIT);
    pixels = want_pixels;
    allocated += 2;
  }
  if (want_capacity > capacity) {
    nodes = make_gl_buffer(nullptr, size_t{want_capacity} * sizeof(gl::FogNodeRecord), GL_DYNAMIC_STORAGE_BIT);
    capacity = want_capacity;
    ++allocated;
  }
  if (counters.id() == 0) {
    const gl::GlFogCounters zero;
    counters = make_gl_buffer(&zero, sizeof zero, GL_DYNAMIC_STORAGE_BIT);
    ++allocated;
  }
  check_gl("fog lists");
  return allocated;
}

void GlFogLists::bind() const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogNodesBinding, nodes.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogHeadsBinding, heads.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogOverflowBinding, overflow.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogCountersBinding, counters.id());
}

void GlFogLists::clear_frame() const {
  const uint32_t zero = 0;
  glClearNamedBufferData(counters.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glClearNamedBufferData(overflow.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

void GlFogLists::clear_pass() const {
  const uint32_t end = gl::kFogListEnd, zero = 0;
  glClearNamedBufferData(heads.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &end);
  glClearNamedBufferSubData(counters.id(), GL_R32UI, 0, 4, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

gl::GlFogCounters GlFogLists::read_counters() const {
  gl::GlFogCounters c;
  glGetNamedBufferSubData(counters.id(), 0, sizeof c, &c);
  return c;
}

}  // namespace sylva
