// instances.cpp — plants grouped by skeleton, and their transforms (see instances.h).
#include "core/scene/instances.h"

#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

namespace sylva {

PlantTransform PlantTransform::of(const ScenePlant& plant) {
  PlantTransform t;
  t.position = plant.position;
  t.scale = plant.scale;
  const double angle = plant.rotate_y_deg * std::numbers::pi / 180;  // as place_plant
  t.cos_y = std::cos(angle);
  t.sin_y = std::sin(angle);
  return t;
}

glm::dvec3 PlantTransform::rotate(const glm::dvec3& v) const {
  // R_y: x' = c x + s z, z' = −s x + c z (place_plant).
  return {cos_y * v.x + sin_y * v.z, v.y, -sin_y * v.x + cos_y * v.z};
}

glm::dvec3 PlantTransform::unrotate(const glm::dvec3& v) const {
  return {cos_y * v.x - sin_y * v.z, v.y, sin_y * v.x + cos_y * v.z};
}

glm::dvec3 PlantTransform::to_world(const glm::dvec3& p) const {
  // Scale first, then rotate, then translate, each rounded as place_plant rounds it.
  const glm::dvec3 s = scale * p;
  return {position.x + cos_y * s.x + sin_y * s.z, position.y + s.y, position.z - sin_y * s.x + cos_y * s.z};
}

glm::dvec3 PlantTransform::to_local(const glm::dvec3& p) const { return unrotate(p - position) / scale; }

Aabb PlantTransform::world_box(const Aabb& local) const {
  if (!(local.lo.x <= local.hi.x)) return local;  // empty
  Aabb box = empty_box();
  for (const glm::dvec3& c : corners(local)) grow(box, to_world(c));
  return box;
}

namespace {

// Whether two skeletons have the same shape: joints, chains and leaves (not their source,
// whose seed may differ where the grammar draws no random number).
bool same_shape(const Skeleton& a, const Skeleton& b) {
  return a.joints == b.joints && a.chains == b.chains && a.leaves == b.leaves;
}

}  // namespace

PlantInstances plant_instances(const Scene& scene) {
  // Candidates: the same grammar, steps, defines and skin, and as many joints and leaves.
  using Key =
      std::tuple<std::string, std::optional<int64_t>, std::map<std::string, double>, SkinStyle, size_t, size_t>;
  std::map<Key, std::vector<uint32_t>> prototypes_of_key;  // prototype indices
  PlantInstances out;
  out.prototype_of_plant.resize(scene.plants.size());
  for (uint32_t p = 0; p < scene.plants.size(); ++p) {
    const ScenePlant& plant = scene.plants[p];
    if (!plant.skeleton) throw std::logic_error("plant_instances: a plant has no skeleton (call grow_scene_plants)");
    std::vector<uint32_t>& candidates = prototypes_of_key[Key{plant.grammar, plant.steps, plant.defines, plant.skin,
                                                              plant.skeleton->joints.size(),
                                                              plant.skeleton->leaves.size()}];
    uint32_t found = UINT32_MAX;
    for (uint32_t k : candidates)
      if (same_shape(*scene.plants[out.prototypes[k]].skeleton, *plant.skeleton)) {
        found = k;
        break;
      }
    if (found == UINT32_MAX) {
      found = static_cast<uint32_t>(out.prototypes.size());
      out.prototypes.push_back(p);
      candidates.push_back(found);
    }
    out.prototype_of_plant[p] = found;
  }
  return out;
}

}  // namespace sylva
