// instances.h — which plants of a scene share one skeleton, so that a renderer skins and
// uploads it once and draws it once per plant through the plant's transform (docs/scatter.md,
// "Instancing"). A scatter entry makes many plants from few recipes (grammar, seed, steps,
// defines); grow_scene_plants gives every plant of a recipe an equal copy of its skeleton.
//
// A plant's transform is place_plant's (scene.h): p_world = position + R_y(θ)·(scale·p),
// with the same cos θ and sin θ, so a point taken to the world here lands where place_plant
// puts the joint. Rotation about y and a uniform scale > 0: normals only rotate, lengths scale.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene/scene.h"
#include "core/util/bounds.h"

namespace sylva {

// A plant's placement as a similarity transform (and its inverse).
struct PlantTransform {
  glm::dvec3 position{0, 0, 0};
  double scale = 1;
  double cos_y = 1, sin_y = 0;  // of rotate_y_deg, computed as place_plant does

  static PlantTransform of(const ScenePlant& plant);
  // R_y(θ)·v (a direction or normal; no scale).
  glm::dvec3 rotate(const glm::dvec3& v) const;
  // R_y(θ)ᵀ·v.
  glm::dvec3 unrotate(const glm::dvec3& v) const;
  // position + R_y(θ)·(scale·p).
  glm::dvec3 to_world(const glm::dvec3& p) const;
  // The inverse: R_y(θ)ᵀ·(p − position) / scale.
  glm::dvec3 to_local(const glm::dvec3& p) const;
  // The world box holding `local` once transformed (its eight corners' box; empty stays empty).
  Aabb world_box(const Aabb& local) const;
};

// The plants of a scene grouped by skeleton. prototypes[k] is the first plant with the k-th
// distinct skeleton; prototype_of_plant[p] is the k of plant p. Two plants share a prototype
// iff their skeletons have the same shape — equal joints, chains and leaves; the source may
// differ in its seed (a grammar without randomness grows one shape from every seed,
// grow_scene_plants) — and a recipe (grammar, steps, defines) and the joint and leaf
// counts only narrow the search, so plants whose skeletons were changed one by one (an
// animation's frame) are never merged.
struct PlantInstances {
  std::vector<uint32_t> prototypes;
  std::vector<uint32_t> prototype_of_plant;
  size_t distinct() const { return prototypes.size(); }
};

// Groups `scene`'s plants (every skeleton set: grow_scene_plants). Cost: one shape
// comparison per plant against each prototype of its recipe and counts.
PlantInstances plant_instances(const Scene& scene);

}  // namespace sylva
