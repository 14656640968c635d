// normal_map.cpp — height map to tangent-space normal map (normal_map.h).
#include "core/io/normal_map.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cassert>
#include <cmath>
#include <numbers>

#include "core/util/file_io.h"
#include "core/util/limits.h"

namespace sylva {

Expected<HeightMap> read_height_map(const std::string& path) {
  // ImageInput rather than a cached ImageBuf: the file is read once, now, as it is on
  // disk (a cache could hand back an older version of a file rewritten under the same name).
  note_input_file(path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string why = OIIO::geterror();
    if (why.empty()) why = "cannot open";
    return file_diagnostic(path, "cannot read the height map: " + why);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1)
    return file_diagnostic(path, "the height map must be a 2D image with at least one pixel");
  if (auto problem = image_size_problem(static_cast<uint64_t>(spec.width), static_cast<uint64_t>(spec.height)))
    return file_diagnostic(path, "the height map is too large: " + *problem);
  HeightMap map;
  map.width = static_cast<uint32_t>(spec.width);
  map.height = static_cast<uint32_t>(spec.height);
  map.values.resize(static_cast<size_t>(map.width) * map.height);
  if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, map.values.data())) {
    std::string why = in->geterror();
    return file_diagnostic(path, "cannot read the height map's pixels: " + (why.empty() ? "read failed" : why));
  }
  for (float v : map.values)
    if (!std::isfinite(v)) return file_diagnostic(path, "the height map holds a value that is not finite");
  return map;
}

NormalMapMetric bark_normal_map_metric(uint32_t width, uint32_t height, double r_ref_m, double u_repeat,
                                       double v_per_metre, double relief_depth_m) {
  NormalMapMetric m;
  m.texel_s_m = 2 * std::numbers::pi * r_ref_m / (u_repeat * width);
  m.texel_t_m = 1 / (v_per_metre * height);
  m.depth_m = relief_depth_m;
  return m;
}

std::vector<glm::dvec3> bake_tangent_normals(const HeightMap& map, const NormalMapMetric& metric) {
  assert(map.width > 0 && map.height > 0 && map.values.size() == size_t{map.width} * map.height);
  assert(metric.texel_s_m > 0 && metric.texel_t_m > 0 && std::isfinite(metric.texel_s_m) &&
         std::isfinite(metric.texel_t_m));
  const uint32_t w = map.width, h = map.height;
  // depth·∂h/∂x by central differences over two texels; the factors fold depth in.
  const double ks = metric.depth_m / (2 * metric.texel_s_m);
  const double kt = metric.depth_m / (2 * metric.texel_t_m);
  std::vector<glm::dvec3> normals(static_cast<size_t>(w) * h);
  for (uint32_t j = 0; j < h; ++j) {
    const uint32_t up = j == 0 ? h - 1 : j - 1, down = j + 1 == h ? 0 : j + 1;
    for (uint32_t i = 0; i < w; ++i) {
      const uint32_t left = i == 0 ? w - 1 : i - 1, right = i + 1 == w ? 0 : i + 1;
      const double slope_s = ks * (double{map.at(right, j)} - map.at(left, j));  // depth·∂h/∂x_s
      const double slope_t = kt * (double{map.at(i, down)} - map.at(i, up));     // depth·∂h/∂x_t
      // (ŝ, t̂, n) components (−slope_s, −slope_t, 1); glTF's Y is −t̂.
      const glm::dvec3 n(-slope_s, slope_t, 1.0);
      normals[static_cast<size_t>(j) * w + i] = n / std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    }
  }
  return normals;
}

std::vector<uint8_t> encode_normals_rgb8(const std::vector<glm::dvec3>& normals) {
  std::vector<uint8_t> rgb;
  rgb.reserve(normals.size() * 3);
  auto quantise = [](double c) {
    const double v = std::round(255.0 * (1.0 + c) / 2.0);
    return static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v);
  };
  for (const glm::dvec3& n : normals) rgb.insert(rgb.end(), {quantise(n.x), quantise(n.y), quantise(n.z)});
  return rgb;
}

std::optional<std::string> encode_png_in_memory(uint32_t width, uint32_t height, int channels,
                                                const std::vector<uint8_t>& pixels) {
  if (width == 0 || height == 0 || channels < 1 || channels > 4 ||
      pixels.size() != size_t{width} * height * static_cast<size_t>(channels))
    return std::nullopt;
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  // The proxy given to create() receives the bytes; "normal_map.png" only names them.
  auto out = OIIO::ImageOutput::create("png", &proxy);
  if (!out || !out->supports("ioproxy")) return std::nullopt;
  OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), channels, OIIO::TypeDesc::UINT8);
  spec.attribute("png:compressionLevel", 9);
  if (!out->open("normal_map.png", spec)) return std::nullopt;
  const bool written = out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
  if (!out->close() || !written) return std::nullopt;
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace sylva
