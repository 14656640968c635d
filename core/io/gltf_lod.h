// gltf_lod.h — levels of detail of a glTF export (docs/gltf.md "Levels of detail"): each
// level re-meshed from the skeleton, the last one crossed impostor cards. Pure geometry;
// the card images come from a renderer the front end supplies (CardRenderer, gltf.h).
//
// Level 0 is the plant as `--mesh` writes it. Level k (1 ≤ k < N), from level k − 1:
//   - columns around each frustum halved (at least 3);
//   - chains dropped by size: each chain's size is its first joint's radius, capped by its
//     parent's size (so a kept chain's parent is kept); the largest chains are kept, in
//     decreasing size, while the wood's estimated triangles (each chain's frusta in the
//     whole plant's skin, tessellated with level k's columns) stay within a quarter of
//     level k − 1's estimate; the root chains are always kept. A dropped chain
//     keeps its first joint only (no segment), so chain and joint indices of the kept
//     chains are those of the full skeleton (the rig's weights and the wind data apply
//     unchanged);
//   - leaves merged: consecutive groups of 4^k leaves (in the skeleton's order, which is
//     the order the grammar closed them: neighbours on a branch) become one, the group's
//     largest leaf scaled about its centroid to the group's total area, hanging from its
//     joint (or, where that chain was dropped, from the kept joint its branch grows from).
// The last level N: two vertical cards crossed on the plant's vertical axis through the
// centre of its bounding box, one facing +Z and one facing +X, each as wide as the box
// seen from its side and as tall as the box, textured with the plant rendered from that
// side (an RGBA cut-out).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/geometry/skeleton.h"
#include "core/geometry/skin.h"

namespace sylva {

inline constexpr uint32_t kMaxLodLevels = 6;  // `--lod N`: N from 1 to this

// Level k (1 ≤ k) of `skeleton` re-meshed at `columns` around (the columns of level k,
// lod_columns), as above; the chains' costs are those of `skin` (the plant's own skin:
// smooth or paper, SkinOptions::styled).
Skeleton lod_skeleton(const Skeleton& skeleton, uint32_t level, int level0_columns, const SkinOptions& skin = {});

// Levels 1 … `levels` at once (element k − 1 is level k, equal to lod_skeleton's): one skin
// and one tessellation a level, where calling lod_skeleton for each level would tessellate
// levels(levels + 1)/2 times.
std::vector<Skeleton> lod_skeletons(const Skeleton& skeleton, uint32_t levels, int level0_columns,
                                    const SkinOptions& skin = {});

// The columns around of level k: level0_columns halved k times, at least 3.
int lod_columns(int level0_columns, uint32_t level);

// One impostor card: a vertical rectangle through `centre_m`, spanning `half_width_m`
// along `right` and `half_height_m` along +Y, seen from the side `normal` points to
// (right = cross(−normal, +Y)... i.e. the image's right as a camera on that side sees it).
struct ImpostorCard {
  glm::dvec3 centre_m{0};
  glm::dvec3 normal{0, 0, 1};  // unit, horizontal
  glm::dvec3 right{1, 0, 0};   // unit: the image's +u direction
  double half_width_m = 0, half_height_m = 0;
};

// The two cards of `skeleton` (its joints' and leaves' bounding box; nullopt when it has
// no extent to show).
std::optional<std::vector<ImpostorCard>> impostor_cards(const Skeleton& skeleton);

}  // namespace sylva
