// height_maps.cpp — see height_maps.h.
#include "core/scene/height_maps.h"

#include <algorithm>
#include <map>

#include <OpenImageIO/imageio.h>

namespace sylva {

Expected<HeightTexels> read_height_texels(const std::string& path) {
  auto input = OIIO::ImageInput::open(path);
  if (!input) return file_diagnostic(path, "cannot open texture '" + path + "': " + OIIO::geterror());
  const OIIO::ImageSpec spec = input->spec();
  HeightTexels h;
  h.width = std::max(1, spec.width);
  h.height = std::max(1, spec.height);
  h.texels.resize(static_cast<size_t>(h.width) * h.height);
  if (!input->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, h.texels.data()))
    return file_diagnostic(path, "cannot read texture '" + path + "': " + input->geterror());
  return h;
}

Expected<std::vector<HeightFn>> scene_displacements(const Scene& scene) {
  std::map<std::string, std::shared_ptr<const HeightTexels>> read;
  std::vector<HeightFn> out(scene.plants.size());
  for (size_t p = 0; p < scene.plants.size(); ++p) {
    const Bark& bark = scene.plants[p].bark;
    if (!bark.height_texture || !(bark.relief_depth_m > 0)) continue;
    std::shared_ptr<const HeightTexels>& texels = read[*bark.height_texture];
    if (!texels) {
      Expected<HeightTexels> r = read_height_texels(*bark.height_texture);
      if (!r) return r.error();
      texels = std::make_shared<const HeightTexels>(std::move(*r));
    }
    out[p] = relief_displacement([texels](double s, double t) { return texels->at(s, t); }, bark.relief_depth_m,
                                 bark.u_repeat, bark.v_per_metre);
  }
  return out;
}

}  // namespace sylva
