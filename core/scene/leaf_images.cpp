// leaf_images.cpp — see leaf_images.h.
#include "core/scene/leaf_images.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "core/util/color.h"
#include "core/util/limits.h"

namespace sylva {

namespace {

// An image read whole as 8-bit: its size, channel count and which channel is alpha (−1: none).
struct Image8 {
  uint32_t width = 0, height = 0;
  int channels = 0, alpha_channel = -1;
  std::vector<uint8_t> texels;
};

Expected<Image8> read_image8(const std::string& path, const std::string& role) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string why = OIIO::geterror();
    if (why.empty()) why = "cannot open";
    return file_diagnostic(path, "cannot read the leaf " + role + " image: " + why);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
    return file_diagnostic(path, "the leaf " + role + " image must be a 2D image with at least one pixel");
  if (auto problem = image_size_problem(static_cast<uint64_t>(spec.width), static_cast<uint64_t>(spec.height)))
    return file_diagnostic(path, "the leaf " + role + " image is too large: " + *problem);
  Image8 image;
  image.width = static_cast<uint32_t>(spec.width);
  image.height = static_cast<uint32_t>(spec.height);
  image.channels = std::min(spec.nchannels, 4);
  image.alpha_channel = spec.alpha_channel >= 0 && spec.alpha_channel < image.channels ? spec.alpha_channel
                        : image.channels == 2 || image.channels == 4                   ? image.channels - 1
                                                                                       : -1;
  image.texels.resize(size_t{image.width} * image.height * static_cast<size_t>(image.channels));
  if (!in->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::UINT8, image.texels.data())) {
    std::string why = in->geterror();
    if (why.empty()) why = "the pixel data does not decode";
    return file_diagnostic(path, "cannot read the leaf " + role + " image: " + why);
  }
  return image;
}

// `image` resampled onto a width × height layer: channel c at layer texel (x, y) is the
// texel itself at the same size, else bilinear, clamped (GL_LINEAR + GL_CLAMP_TO_EDGE)
// between the four image texels around the layer texel's centre mapped into the image
// (texel centres at integers). The weights of each column and row are found once.
class Resampler {
 public:
  Resampler(const Image8& image, uint32_t width, uint32_t height)
      : image_(image), same_(image.width == width && image.height == height) {
    if (same_) return;
    columns_ = axis(image.width, width);
    rows_ = axis(image.height, height);
  }

  double at(int c, uint32_t x, uint32_t y) const {
    if (same_) return texel(c, x, y) / 255.0;
    const Tap &u = columns_[x], &v = rows_[y];
    return ((1 - v.weight) * ((1 - u.weight) * texel(c, u.lo, v.lo) + u.weight * texel(c, u.hi, v.lo)) +
            v.weight * ((1 - u.weight) * texel(c, u.lo, v.hi) + u.weight * texel(c, u.hi, v.hi))) /
           255.0;
  }

 private:
  struct Tap {
    uint32_t lo = 0, hi = 0;  // the clamped texels either side
    double weight = 0;        // of `hi`
  };
  // Layer texel i's centre (i + ½) · source / layer − ½ in the image, for i < layer.
  static std::vector<Tap> axis(uint32_t source, uint32_t layer) {
    std::vector<Tap> taps(layer);
    for (uint32_t i = 0; i < layer; ++i) {
      const double p = (i + 0.5) * source / layer - 0.5, f = std::floor(p);
      auto clamped = [&](double t) {
        return static_cast<uint32_t>(std::clamp<int64_t>(static_cast<int64_t>(t), 0, int64_t{source} - 1));
      };
      taps[i] = {clamped(f), clamped(f + 1), p - f};
    }
    return taps;
  }
  double texel(int c, uint32_t x, uint32_t y) const {
    return image_.texels[(size_t{y} * image_.width + x) * static_cast<size_t>(image_.channels) + static_cast<size_t>(c)];
  }

  const Image8& image_;
  bool same_;
  std::vector<Tap> columns_, rows_;
};

uint8_t to_byte(double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255)); }

}  // namespace

std::pair<uint32_t, uint32_t> leaf_layer_size(uint32_t width, uint32_t height, size_t layers) {
  if (width == 0 || height == 0) return {width, height};
  const double texels = static_cast<double>(width) * height * static_cast<double>(std::max<size_t>(layers, 1));
  const double scale = std::min({1.0, static_cast<double>(kMaxLeafLayerSide) / width, static_cast<double>(kMaxLeafLayerSide) / height,
                                 std::sqrt(static_cast<double>(kMaxLeafLayerTexels) / texels)});
  if (scale >= 1) return {width, height};
  auto side = [&](uint32_t s) { return std::max<uint32_t>(1, static_cast<uint32_t>(std::floor(s * scale))); };
  return {side(width), side(height)};
}

Expected<std::shared_ptr<const LeafImages>> LeafImages::load(const std::map<uint32_t, SceneMaterial>& table) {
  auto out = std::make_shared<LeafImages>();
  std::map<std::string, Image8> files;
  auto read = [&](const std::string& path, const std::string& role) -> Status {
    if (files.count(path)) return {};
    Expected<Image8> image = read_image8(path, role);
    if (!image) return std::move(image.error());
    files.emplace(path, std::move(*image));
    return {};
  };
  for (const auto& [index, m] : table) {
    if (!m.two_sided) out->one_sided_[index] = true;
    if (m.albedo_image)
      if (Status s = read(*m.albedo_image, "albedo"); !s) return std::move(s.error());
    if (m.alpha_image)
      if (Status s = read(*m.alpha_image, "alpha"); !s) return std::move(s.error());
  }
  uint32_t widest = 0, tallest = 0;
  for (const auto& [path, image] : files) {
    widest = std::max(widest, image.width);
    tallest = std::max(tallest, image.height);
  }
  const size_t layers = static_cast<size_t>(std::count_if(
      table.begin(), table.end(), [](const auto& entry) { return entry.second.albedo_image || entry.second.alpha_image; }));
  std::tie(out->width_, out->height_) = leaf_layer_size(widest, tallest, layers);
  std::array<double, 256> linear;  // each encoded byte decoded
  for (size_t b = 0; b < linear.size(); ++b) linear[b] = srgb_to_linear(static_cast<double>(b) / 255.0);
  for (const auto& [index, m] : table) {
    if (!m.albedo_image && !m.alpha_image) continue;
    const Image8* albedo = m.albedo_image ? &files.at(*m.albedo_image) : nullptr;
    const Image8* alpha = m.alpha_image ? &files.at(*m.alpha_image) : nullptr;
    // Alpha: the `alpha` image's alpha channel (else its first); else the albedo image's alpha.
    const Image8* a_image = alpha ? alpha : albedo && albedo->alpha_channel >= 0 ? albedo : nullptr;
    const int a_channel = !a_image ? -1 : a_image->alpha_channel >= 0 ? a_image->alpha_channel : 0;
    Layer layer;
    layer.material = index;
    layer.albedo = albedo != nullptr;
    layer.cutout = a_image != nullptr;
    const uint32_t w = out->width_, h = out->height_;
    const std::optional<Resampler> albedo_at = albedo ? std::optional<Resampler>(std::in_place, *albedo, w, h) : std::nullopt;
    const std::optional<Resampler> alpha_at =
        a_image ? std::optional<Resampler>(std::in_place, *a_image, w, h) : std::nullopt;
    layer.rgba.resize(size_t{w} * h * 4);
    glm::dvec3 sum(0);
    double opaque = 0;
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        uint8_t* t = &layer.rgba[(size_t{y} * w + x) * 4];
        for (int c = 0; c < 3; ++c) {
          // A gray albedo gives gray; a gray + alpha image's colour is its first channel.
          const int channel = !albedo ? 0 : albedo->channels >= 3 ? c : 0;
          t[c] = albedo ? to_byte(albedo_at->at(channel, x, y)) : 255;
        }
        t[3] = a_image ? to_byte(alpha_at->at(a_channel, x, y)) : 255;
        if (t[3] >= 128) {
          sum += glm::dvec3(linear[t[0]], linear[t[1]], linear[t[2]]);
          opaque += 1;
        }
      }
    layer.mean = opaque > 0 ? sum / opaque : glm::dvec3(0);
    out->layer_of_[index] = out->layers_.size();
    out->layers_.push_back(std::move(layer));
  }
  return std::shared_ptr<const LeafImages>(std::move(out));
}

int LeafImages::layer_of(uint32_t material) const {
  const auto it = layer_of_.find(material);
  return it == layer_of_.end() ? -1 : static_cast<int>(it->second);
}

bool LeafImages::has_albedo(uint32_t material) const {
  const int k = layer_of(material);
  return k >= 0 && layers_[static_cast<size_t>(k)].albedo;
}

bool LeafImages::has_cutout(uint32_t material) const {
  const int k = layer_of(material);
  return k >= 0 && layers_[static_cast<size_t>(k)].cutout;
}

void LeafImages::sample(size_t k, double u, double v, double out[4]) const {
  const double x = u * width_ - 0.5, y = (1 - v) * height_ - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const std::vector<uint8_t>& t = layers_[k].rgba;
  auto texel = [&](double i, double j) {
    const int64_t xi = std::clamp<int64_t>(static_cast<int64_t>(i), 0, int64_t{width_} - 1);
    const int64_t yj = std::clamp<int64_t>(static_cast<int64_t>(j), 0, int64_t{height_} - 1);
    return &t[(static_cast<size_t>(yj) * width_ + static_cast<size_t>(xi)) * 4];
  };
  const uint8_t *a = texel(fx, fy), *b = texel(fx + 1, fy), *c = texel(fx, fy + 1), *d = texel(fx + 1, fy + 1);
  for (int i = 0; i < 4; ++i)
    out[i] = ((1 - ay) * ((1 - ax) * a[i] + ax * b[i]) + ay * ((1 - ax) * c[i] + ax * d[i])) / 255.0;
}

double LeafImages::alpha(uint32_t material, double u, double v) const {
  const int k = layer_of(material);
  if (k < 0 || !layers_[static_cast<size_t>(k)].cutout) return 1;
  double rgba[4];
  sample(static_cast<size_t>(k), u, v, rgba);
  return rgba[3];
}

glm::dvec3 LeafImages::albedo(uint32_t material, double u, double v) const {
  double rgba[4];
  sample(static_cast<size_t>(layer_of(material)), u, v, rgba);
  return {srgb_to_linear(rgba[0]), srgb_to_linear(rgba[1]), srgb_to_linear(rgba[2])};
}

glm::dvec3 LeafImages::mean_albedo(uint32_t material) const { return layers_[static_cast<size_t>(layer_of(material))].mean; }

std::shared_ptr<const LeafImages> scene_leaf_images(const Scene& scene) {
  Expected<std::shared_ptr<const LeafImages>> images = LeafImages::load(scene.materials);
  if (!images) throw std::runtime_error(images.error().file + ": " + images.error().message);
  return (*images)->empty() ? nullptr : *images;
}

MaterialLook segment_look(const std::map<uint32_t, SceneMaterial>& table, const Bark* bark, uint32_t material,
                          const LeafImages* images) {
  MaterialLook look = material_look(table, bark, material);
  const bool bark_colour = material == 0 && bark && (bark->albedo_rgb || bark->albedo_texture);
  if (images && !bark_colour && images->has_albedo(material)) look.albedo = images->mean_albedo(material);
  return look;
}

}  // namespace sylva
