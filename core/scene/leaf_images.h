// leaf_images.h — how a scene's `materials` table (docs/materials.md) dresses its leaves:
// an albedo image, an alpha cut-out, one-sidedness. Read once per render or export and
// shared by the CPU ray caster, the GL renderer and the glTF writer, so all three sample
// the same texels with the same filter.
//
// Images: for every material index whose entry names an `albedo` image or an `alpha` image,
// one RGBA8 **layer**: RGB the albedo image's sRGB-encoded values (white where the entry has
// no albedo image: the entry's colour is then the leaf's), A the cut-out: the `alpha`
// image's alpha channel when it has one, else its first channel; without an `alpha` image
// the albedo image's own alpha channel; 255 (opaque) without either. Every layer of a
// scene has one size, the largest width and the largest height among its images (a smaller
// image is resampled bilinearly, as sample() reads), so the GL renderer holds them in one
// 2D array texture — bounded (docs/limits.md): each side at most kMaxLeafLayerSide and all
// layers together at most kMaxLeafLayerTexels, both sides scaled down by one factor where
// the largest sizes would exceed that (a 65536×1 and a 1×65536 image would otherwise merge
// into 4 G texels), the images then resampled onto the smaller layer.
//
// Lookup (sample): (u, v) a leaf's texture coordinates (leaf_mesh.h leaf_uvs: v = 0 at the
// petiole, the image's bottom row); texel (x, y) with x = u·width − ½, y = (1 − v)·height − ½,
// bilinear between the four nearest texel centres, clamped at the edges — OpenGL's
// GL_LINEAR with GL_CLAMP_TO_EDGE, no MIP levels (a leaf covers few pixels far away: the
// pixel sampler's --spp smooths its outline). RGB filtered encoded, then decoded
// (IEC 61966-2-1), as the bark textures are (texture.h).
//
// Cut-out: a leaf point is there where its alpha is at least kLeafAlphaCutoff (glTF's
// alphaMode MASK with alphaCutoff 0.5); elsewhere every ray passes through it.
// One-sided (`two_sided: false`): the leaf exists on its front only (the side its Newell
// normal points to): every ray arriving at its back passes through — camera, shadow and
// sun rays alike (glTF doubleSided false; docs/materials.md).
//
// A segment (not a leaf) of a material with an albedo image has the image's mean linear
// albedo (over its opaque texels): segments have no leaf texture coordinates — unless the
// entry lays the image on its segments (`u_repeat` / `v_per_metre`: scene.h
// segment_texture, looked up as a bark texture by texture.h and bark.glsl).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene/scene.h"
#include "core/util/diagnostic.h"

namespace sylva {

inline constexpr double kLeafAlphaCutoff = 0.5;

// The merged layers' bounds: a side (OpenGL 4.5's least GL_MAX_TEXTURE_SIZE), and the
// texels of all layers together (2^26: 256 MiB of RGBA8, eight 2896² layers).
inline constexpr uint32_t kMaxLeafLayerSide = 16384;
inline constexpr uint64_t kMaxLeafLayerTexels = uint64_t{1} << 26;

// The size of `layers` merged layers whose images are at most `width` × `height` (the
// largest width and the largest height): that size, or both sides scaled down by one
// factor (each at least 1) to keep within the bounds above.
std::pair<uint32_t, uint32_t> leaf_layer_size(uint32_t width, uint32_t height, size_t layers);

class LeafImages {
 public:
  // Reads the images of `table` (each named file once). Failure: a Diagnostic for the file
  // whose message says why. No image and no one-sided entry: an empty() object.
  static Expected<std::shared_ptr<const LeafImages>> load(const std::map<uint32_t, SceneMaterial>& table);

  // Nothing to do for a leaf: no image and every material two-sided.
  bool empty() const { return layers_.empty() && one_sided_.empty(); }

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  size_t layer_count() const { return layers_.size(); }
  // Layer k's texels: width·height RGBA8, row 0 the image's top (the leaf's tip side).
  const std::vector<uint8_t>& layer(size_t k) const { return layers_[k].rgba; }

  // The layer of material `material`, −1 when it has none.
  int layer_of(uint32_t material) const;
  // Whether `material`'s layer has an albedo image / a cut-out.
  bool has_albedo(uint32_t material) const;
  bool has_cutout(uint32_t material) const;
  bool one_sided(uint32_t material) const { return one_sided_.count(material) > 0; }

  // Material `material`'s alpha at (u, v), in [0, 1] (1 without a layer).
  double alpha(uint32_t material, double u, double v) const;
  // Whether a leaf point of `material` at (u, v) is there (alpha ≥ kLeafAlphaCutoff).
  bool opaque(uint32_t material, double u, double v) const { return alpha(material, u, v) >= kLeafAlphaCutoff; }
  // Material `material`'s linear albedo at (u, v) (has_albedo(material)).
  glm::dvec3 albedo(uint32_t material, double u, double v) const;
  // The mean linear albedo of `material`'s albedo image over its opaque texels
  // (has_albedo(material)).
  glm::dvec3 mean_albedo(uint32_t material) const;

 private:
  struct Layer {
    uint32_t material = 0;
    bool albedo = false, cutout = false;
    std::vector<uint8_t> rgba;
    glm::dvec3 mean{0};
  };
  // Bilinear RGBA (encoded, [0, 1]) of layer `k` at (u, v).
  void sample(size_t k, double u, double v, double out[4]) const;

  uint32_t width_ = 0, height_ = 0;
  std::vector<Layer> layers_;
  std::map<uint32_t, size_t> layer_of_;
  std::map<uint32_t, bool> one_sided_;
};

// The leaf materials of `scene`'s table (LeafImages::load), null when it names no image
// and no one-sided material; std::runtime_error naming the file if one cannot be read.
std::shared_ptr<const LeafImages> scene_leaf_images(const Scene& scene);

// The albedo of a segment (not a leaf) of `material`: material_look's, except a material
// with an albedo image, whose segments take the image's mean (`images` may be null).
MaterialLook segment_look(const std::map<uint32_t, SceneMaterial>& table, const Bark* bark, uint32_t material,
                          const LeafImages* images);

}  // namespace sylva
