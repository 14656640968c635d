// gl_crotch_fade.h — the tables the GPU's relief fade reads (shaders/crotch.glsl, the frusta
// program's CROTCH_FADE): on a plant whose skin blends its crotches (crotch.h) and that has
// a relief, the relief of each crotch's frusta fades into its fillet as on the CPU
// (crotch.h crotch_relief_fade, core/cpu/crotch_tracer.h CrotchBalls::relief_fade).
//
// Layout (std430, bindings.h kCrotchesBinding / kCrotchListsBinding):
//   crotches  one GpuCrotchRecord per crotch: positions relative to its origin_hi, the
//             origin_hi of its first parent record (float-exact, so that a shader's
//             differences of origins between nearby records are exact);
//   lists     words [0, records): per record, the index in `lists` of its crotch list, 0
//             where it belongs to none; a list is a count then that many crotch indices;
//             after the lists, each crotch's parent group then its lateral group, as record
//             indices (GpuCrotchRecord::parent_first / lateral_first).
// Preconditions: the crotches' frustum indices are record indices (< records.size()).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/gl/bindings.h"
#include "core/geometry/crotch.h"

namespace sylva {

struct GlCrotchFadeTables {
  std::vector<gl::GpuCrotchRecord> crotches;
  std::vector<uint32_t> lists;
  bool empty() const { return crotches.empty(); }
  size_t bytes() const { return crotches.size() * sizeof(gl::GpuCrotchRecord) + lists.size() * sizeof(uint32_t); }
};

// The tables of `crotches` over `records` (none: empty tables).
GlCrotchFadeTables pack_crotch_fade(std::span<const Crotch> crotches, std::span<const GpuSegment> records);

}  // namespace sylva
