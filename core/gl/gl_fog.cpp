// gl_fog.cpp — see gl_fog.h.
#include "core/gl/gl_fog.h"

#include <algorithm>
#include <string>
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

GlFogMaps upload_fog_maps(std::span<const SunDepthMap> maps) {
  if (maps.empty() || maps.size() > gl::kFogMaxMaps)
    throw GlError("the fog pass walks 1 to " + std::to_string(gl::kFogMaxMaps) + " sun maps, not " +
                  std::to_string(maps.size()));
  static_assert(SunDepthMap::kTile == gl::kFogMapTile && SunDepthMap::kNoSlot == gl::kFogMapNoSlot);
  GlFogMaps out;
  out.origin = maps[0].frame().centre;
  std::vector<gl::GpuSunMapRecord> records;
  std::vector<uint32_t> slots;
  std::vector<float> ranges, texels;
  for (const SunDepthMap& map : maps) {
    const SunMapFrame& f = map.frame();
    const glm::dvec3 c = f.centre - out.origin;
    gl::GpuSunMapRecord r;
    const float centre_half[4] = {float(c.x), float(c.y), float(c.z), float(f.half_extent_m)};
    const float to_sun_texel[4] = {float(f.to_sun.x), float(f.to_sun.y), float(f.to_sun.z), float(f.texel_m())};
    const float e0_size[4] = {float(f.e0.x), float(f.e0.y), float(f.e0.z), float(f.size)};
    const float e1_tiles[4] = {float(f.e1.x), float(f.e1.y), float(f.e1.z), float(map.tiles_per_side())};
    std::copy(centre_half, centre_half + 4, r.centre_half);
    std::copy(to_sun_texel, to_sun_texel + 4, r.to_sun_texel);
    std::copy(e0_size, e0_size + 4, r.e0_size);
    std::copy(e1_tiles, e1_tiles + 4, r.e1_tiles);
    r.first_tile[0] = static_cast<uint32_t>(slots.size());
    r.first_tile[1] = r.first_tile[2] = r.first_tile[3] = 0;
    records.push_back(r);
    const uint32_t first_slot = static_cast<uint32_t>(ranges.size() / 2);
    for (uint32_t slot : map.slot_of_tile()) slots.push_back(slot == SunDepthMap::kNoSlot ? slot : slot + first_slot);
    for (size_t k = 0; k < map.allocated_tiles(); ++k) {
      ranges.push_back(map.tile_min()[k]);
      ranges.push_back(map.tile_max()[k]);
    }
    texels.insert(texels.end(), map.texels().begin(), map.texels().end());
  }
  // An empty buffer cannot be bound: a map set without a slot keeps one unread entry.
  if (ranges.empty()) ranges.assign(2, 0.0f), texels.assign(1, 0.0f);
  out.count = static_cast<uint32_t>(records.size());
  out.records = make_gl_buffer(records.data(), records.size() * sizeof(gl::GpuSunMapRecord));
  out.slots = make_gl_buffer(slots.data(), slots.size() * sizeof(uint32_t));
  out.ranges = make_gl_buffer(ranges.data(), ranges.size() * sizeof(float));
  out.texels = make_gl_buffer(texels.data(), texels.size() * sizeof(float));
  out.bytes = records.size() * sizeof(gl::GpuSunMapRecord) + slots.size() * 4 + ranges.size() * 4 + texels.size() * 4;
  check_gl("fog maps");
  return out;
}

void GlFogMaps::bind() const {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogMapsBinding, records.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogMapSlotsBinding, slots.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogMapRangesBinding, ranges.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gl::kFogMapTexelsBinding, texels.id());
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
