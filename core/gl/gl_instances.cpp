// gl_instances.cpp — see gl_instances.h.
#include "core/gl/gl_instances.h"

#include "core/gl/gl_views.h"

namespace sylva {

GpuInstance gpu_instance(const PlantTransform& t, uint32_t plant, bool own) {
  GpuInstance g{};
  const GlFloatSplit p = split_to_floats(t.position);
  for (int k = 0; k < 3; ++k) g.position_hi[k] = p.hi[k], g.position_lo[k] = p.lo[k];
  g.scale = static_cast<float>(t.scale);
  g.cos_y = static_cast<float>(t.cos_y);
  g.sin_y = static_cast<float>(t.sin_y);
  g.plant = plant;
  g.own = own ? 1 : 0;
  return g;
}

GlInstanceGroups gl_instance_groups(const Scene& scene, bool instance,
                                    const std::function<bool(uint32_t)>& instanceable) {
  const uint32_t n = static_cast<uint32_t>(scene.plants.size());
  GlInstanceGroups out;
  if (!instance) {
    for (uint32_t p = 0; p < n; ++p) out.world.push_back(p);
    return out;
  }
  const PlantInstances shared = plant_instances(scene);
  std::vector<std::vector<uint32_t>> plants_of(shared.distinct());
  for (uint32_t p = 0; p < n; ++p)
    if (instanceable(p)) plants_of[shared.prototype_of_plant[p]].push_back(p);
  std::vector<char> in_world(n, 1);
  for (std::vector<uint32_t>& g : plants_of) {
    if (g.size() < 2) continue;
    for (uint32_t p : g) in_world[p] = 0;
    out.groups.push_back(std::move(g));
  }
  for (uint32_t p = 0; p < n; ++p)
    if (in_world[p]) out.world.push_back(p);
  return out;
}

}  // namespace sylva
