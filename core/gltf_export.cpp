// gltf_export.cpp — skeletons to glTF 2.0 and back (gltf_export.h, issue 5).
//
// The glTF JSON is written with the json.h writers rather than tinygltf: the file then
// has the same guarantees as a skeleton file (fixed key order, shortest round-trip
// numbers, byte-identical output for identical input), and none of tinygltf 2.7's
// writer traps can reach it (mode -1 when Primitive::mode is unset, empty nodes as
// `null`, Value("text") turned into a bool, accessor min/max left empty). The reader
// uses json.h too: strict, located, depth-limited, and it needs only the JSON chunk —
// a truncated binary chunk cannot stop the skeleton from being read back, and no URI is
// ever resolved. The tests read every exported file with tinygltf as well, as an
// independent second reader.
//
// Buffer layout: one buffer; one tightly packed bufferView per accessor, each starting
// at a multiple of 4 bytes, then (.glb only) one bufferView per embedded image. Floats
// are little-endian IEEE 754 (as the machine's).
#include "core/gltf_export.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>
#include <string_view>
#include <utility>

#include <OpenImageIO/imageio.h>

#include <glm/geometric.hpp>

#include "core/util/file_io.h"
#include "core/util/json.h"
#include "core/materials.h"
#include "core/normal_map.h"
#include "core/skin.h"
#include "core/tessellate.h"

static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");

namespace sylva {
namespace {

constexpr uint32_t kComponentFloat = 5126;
constexpr uint32_t kComponentUint32 = 5125;
constexpr int kTargetArrayBuffer = 34962;
constexpr int kTargetElementArrayBuffer = 34963;
constexpr int kModeLines = 1;
constexpr int kModeTriangles = 4;
constexpr int kFilterLinear = 9729;
constexpr int kFilterLinearMipmapLinear = 9987;
constexpr int kWrapRepeat = 10497;
constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kGlbChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbChunkBin = 0x004E4942;   // "BIN\0"

struct BufferView {
  size_t offset = 0;
  size_t length = 0;
  int target = 0;  // 0: none (instancing attributes)
};

struct Accessor {
  size_t view = 0;
  uint32_t component = kComponentFloat;
  size_t count = 0;
  const char* type = "SCALAR";
  std::vector<double> min, max;  // per component, exact values of the stored elements
};

// The binary buffer and the views/accessors describing it.
class BufferBuilder {
 public:
  // Appends `values` (count × components floats) and returns the accessor index.
  // min/max are those of the floats actually stored (the validator compares exactly).
  size_t add_floats(const std::vector<float>& values, int components, const char* type, int target) {
    const size_t count = values.size() / static_cast<size_t>(components);
    Accessor a;
    a.type = type;
    a.count = count;
    a.min.assign(static_cast<size_t>(components), std::numeric_limits<double>::infinity());
    a.max.assign(static_cast<size_t>(components), -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < values.size(); ++i) {
      const size_t k = i % static_cast<size_t>(components);
      a.min[k] = std::min(a.min[k], static_cast<double>(values[i]));
      a.max[k] = std::max(a.max[k], static_cast<double>(values[i]));
    }
    a.view = add_view(values.data(), values.size() * sizeof(float), target);
    accessors_.push_back(std::move(a));
    return accessors_.size() - 1;
  }

  size_t add_indices(const std::vector<uint32_t>& indices) {
    Accessor a;
    a.component = kComponentUint32;
    a.count = indices.size();
    uint32_t lo = std::numeric_limits<uint32_t>::max(), hi = 0;
    for (uint32_t i : indices) lo = std::min(lo, i), hi = std::max(hi, i);
    a.min = {static_cast<double>(lo)};
    a.max = {static_cast<double>(hi)};
    a.view = add_view(indices.data(), indices.size() * sizeof(uint32_t), kTargetElementArrayBuffer);
    accessors_.push_back(std::move(a));
    return accessors_.size() - 1;
  }

  // Appends raw bytes (an image) as a bufferView without target; returns the view index.
  size_t add_bytes(std::string_view data) { return add_view(data.data(), data.size(), 0); }

  const std::string& bytes() const { return bytes_; }
  const std::vector<BufferView>& views() const { return views_; }
  const std::vector<Accessor>& accessors() const { return accessors_; }

 private:
  size_t add_view(const void* data, size_t length, int target) {
    while (bytes_.size() % 4 != 0) bytes_.push_back('\0');
    views_.push_back({bytes_.size(), length, target});
    bytes_.append(static_cast<const char*>(data), length);
    return views_.size() - 1;
  }

  std::string bytes_;
  std::vector<BufferView> views_;
  std::vector<Accessor> accessors_;
};

void append_vec(std::string& out, const double* v, size_t n) {
  out += '[';
  for (size_t i = 0; i < n; ++i) {
    if (i) out += ',';
    append_json_number(out, v[i]);
  }
  out += ']';
}

void append_vec(std::string& out, const glm::dvec3& v) {
  const double a[3] = {v.x, v.y, v.z};
  append_vec(out, a, 3);
}

// The skeleton document of skeleton.md with the seed as a string (JSON consumers read
// numbers as doubles, which cannot hold every 64-bit seed).
void append_skeleton_document(std::string& out, const Skeleton& sk) {
  out += "\"format\":\"sylva-skeleton\",\"version\":1,\"source\":{\"grammar\":";
  append_json_string(out, sk.source.grammar);
  out += ",\"seed\":\"" + std::to_string(sk.source.seed) + "\",\"steps\":";
  append_json_int64(out, sk.source.steps);
  out += ",\"defines\":{";
  bool first = true;
  for (const auto& [name, value] : sk.source.defines) {
    if (!first) out += ',';
    first = false;
    append_json_string(out, name);
    out += ':';
    append_json_number(out, value);
  }
  out += "}},\"chains\":[";
  for (size_t c = 0; c < sk.chains.size(); ++c) {
    if (c) out += ',';
    append_chain_json(out, sk, c, true);
  }
  out += ']';
}

// Per frustum of skin_skeleton (default options): what a renderer needs beyond the
// skeleton to reproduce the surface parametrization.
void append_skinning(std::string& out, const SkinnedSkeleton& skinned) {
  const SkinOptions defaults;
  out += "\"skinning\":{\"max_tilt_deg\":";
  append_json_number(out, defaults.max_tilt_deg);
  out += ",\"columns\":[\"chain\",\"segment\",\"knuckle\",\"lower_normal\",\"lower_offset_m\","
         "\"upper_normal\",\"upper_offset_m\",\"u_offset\"],\"frusta\":[";
  for (size_t f = 0; f < skinned.frusta.size(); ++f) {
    const Frustum& fr = skinned.frusta[f];
    if (f) out += ',';
    out += '[';
    append_json_uint64(out, fr.chain);
    out += ',';
    append_json_uint64(out, fr.segment);
    out += fr.kind == FrustumKind::knuckle ? ",true," : ",false,";
    append_vec(out, fr.shape.lower.normal);
    out += ',';
    append_json_number(out, fr.shape.lower.offset);
    out += ',';
    append_vec(out, fr.shape.upper.normal);
    out += ',';
    append_json_number(out, fr.shape.upper.offset);
    out += ',';
    append_json_number(out, fr.u_offset);
    out += ']';
  }
  out += "]}";
}

void append_instance(std::string& out, const GltfPlant& p) {
  out += "{\"name\":";
  append_json_string(out, p.name);
  out += ",\"position_m\":";
  append_vec(out, p.position_m, 3);
  out += ",\"rotate_y_deg\":";
  append_json_number(out, p.rotate_y_deg);
  out += ",\"scale\":";
  append_json_number(out, p.scale);
  out += '}';
}

// Unit quaternion (x, y, z, w) of a rotation about +Y.
std::array<double, 4> quaternion_about_y(double angle_deg) {
  const double half = angle_deg * std::numbers::pi / 360.0;
  return {0.0, std::sin(half), 0.0, std::cos(half)};
}

std::string base64(std::string_view bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) |
                       (uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8) | static_cast<uint8_t>(bytes[i + 2]);
    out += kDigits[(v >> 18) & 63], out += kDigits[(v >> 12) & 63], out += kDigits[(v >> 6) & 63], out += kDigits[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint32_t{static_cast<uint8_t>(bytes[i])} << 16;
    out += kDigits[(v >> 18) & 63], out += kDigits[(v >> 12) & 63], out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint32_t{static_cast<uint8_t>(bytes[i])} << 16) | (uint32_t{static_cast<uint8_t>(bytes[i + 1])} << 8);
    out += kDigits[(v >> 18) & 63], out += kDigits[(v >> 12) & 63], out += kDigits[(v >> 6) & 63], out += '=';
  }
  return out;
}

void append_u32(std::string& out, uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

std::string lower_case(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

// One group of plants sharing a skeleton (instancing) or a single plant.
struct PlantGroup {
  std::vector<size_t> plants;  // indices into the caller's vector, first one names the node
};

std::optional<std::string> check_plant(const GltfPlant& p, size_t index) {
  const std::string which = "plant " + std::to_string(index) + " (" + json_excerpt(p.name) + ")";
  for (double v : p.position_m)
    if (!std::isfinite(v)) return which + ": the position is not finite";
  if (!std::isfinite(p.rotate_y_deg)) return which + ": rotate_y_deg is not finite";
  if (!std::isfinite(p.scale) || p.scale <= 0) return which + ": the scale must be a finite number > 0";
  if (auto err = validate_skeleton(p.skeleton)) return which + ": " + err->message;
  if (!std::isfinite(p.bark.u_repeat) || p.bark.u_repeat <= 0) return which + ": bark u_repeat must be a finite number > 0";
  if (!std::isfinite(p.bark.v_per_metre) || p.bark.v_per_metre <= 0)
    return which + ": bark v_per_metre must be a finite number > 0";
  if (!std::isfinite(p.bark.relief_depth_m) || p.bark.relief_depth_m < 0)
    return which + ": bark relief_depth must be a finite number >= 0";
  return std::nullopt;
}

// An image embedded in the file.
struct EmbeddedImage {
  std::string bytes;
  const char* mime = "image/png";
};

// Reads a bark albedo texture to embed it byte for byte: glTF takes PNG or JPEG only.
std::optional<std::string> read_albedo_image(const std::string& path, EmbeddedImage* out) {
  FileReadResult file = read_text_file(path);
  if (!file.contents)
    return path + ": error: cannot read the bark albedo texture: " +
           (file.error ? file.error->message : std::string("unreadable"));
  const std::string& bytes = *file.contents;
  if (bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) out->mime = "image/png";
  else if (bytes.compare(0, 3, "\xFF\xD8\xFF") == 0) out->mime = "image/jpeg";
  else return path + ": error: the bark albedo texture must be a PNG or JPEG file to be embedded in glTF";
  // The header must decode too (a viewer, and the validator, read it).
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    const std::string why = OIIO::geterror();
    return path + ": error: the bark albedo texture is not a readable image" + (why.empty() ? "" : ": " + why);
  }
  out->bytes = bytes;
  return std::nullopt;
}

// Identifies a bark for grouping identical plants (instancing).
std::string bark_key(const Bark& b) {
  std::string key = "albedo:";
  if (b.albedo_texture) key += "file:" + *b.albedo_texture;
  if (b.albedo_rgb) append_vec(key, *b.albedo_rgb);
  key += "\nheight:" + b.height_texture.value_or("") + "\n";
  for (double v : {b.relief_depth_m, b.u_repeat, b.v_per_metre}) append_json_number(key, v), key += ',';
  return key;
}

// The material of index `material` of a plant with bark `bark` (gltf_export.h).
std::string material_json(uint32_t material, const Bark& bark, std::optional<size_t> albedo_texture,
                          std::optional<size_t> normal_texture, double r_ref_m) {
  std::string m = "{\"name\":\"sylva_material_" + std::to_string(material) + "\",\"pbrMetallicRoughness\":{";
  if (albedo_texture) {
    m += "\"baseColorFactor\":[1,1,1,1],\"baseColorTexture\":{\"index\":" + std::to_string(*albedo_texture) + "},";
  } else {
    const double* rgb = default_material_albedo(material);
    const glm::dvec3 colour = material == 0 && bark.albedo_rgb ? *bark.albedo_rgb : glm::dvec3(rgb[0], rgb[1], rgb[2]);
    m += "\"baseColorFactor\":[";
    for (int k = 0; k < 3; ++k) append_json_number(m, colour[k]), m += ',';
    m += "1],";
  }
  m += "\"metallicFactor\":0,\"roughnessFactor\":0.9}";
  if (normal_texture) m += ",\"normalTexture\":{\"index\":" + std::to_string(*normal_texture) + "}";
  m += ",\"extras\":{\"sylva\":{\"material_index\":" + std::to_string(material);
  if (bark.albedo_texture) {
    m += ",\"albedo\":";
    append_json_string(m, *bark.albedo_texture);
  } else if (bark.albedo_rgb) {
    m += ",\"albedo\":";
    append_vec(m, *bark.albedo_rgb);
  }
  if (bark.height_texture) {
    m += ",\"height\":";
    append_json_string(m, *bark.height_texture);
  }
  m += ",\"relief_depth_m\":";
  append_json_number(m, bark.relief_depth_m);
  m += ",\"u_repeat\":";
  append_json_number(m, bark.u_repeat);
  m += ",\"v_per_metre\":";
  append_json_number(m, bark.v_per_metre);
  if (normal_texture) {
    m += ",\"r_ref_m\":";
    append_json_number(m, r_ref_m);
  }
  m += ",\"texcoord_0\":\"s = u * u_repeat with u in turns around the axis, t = v_m * v_per_metre with v_m the "
       "arc length in metres\"}}}";
  return m;
}

double median_segment_radius(const SkinnedSkeleton& skinned) {
  std::vector<double> radii;
  for (const Frustum& f : skinned.frusta)
    if (f.kind == FrustumKind::segment && (f.shape.radius0 > 0 || f.shape.radius1 > 0))
      radii.push_back(0.5 * (f.shape.radius0 + f.shape.radius1));
  if (radii.empty()) return 0;
  const size_t mid = radii.size() / 2;
  std::nth_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(mid), radii.end());
  if (radii.size() % 2 == 1) return radii[mid];
  const double upper = radii[mid];
  return 0.5 * (*std::max_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(mid)) + upper);
}

// Per vertex of `tm`: TANGENT (gltf_export.h) as 4 floats, xyz unit in float.
std::vector<float> vertex_tangents(const TriangleMesh& tm, const SkinnedSkeleton& skinned) {
  // Each vertex belongs to one frustum (tessellate.h makes every frustum's own vertices).
  std::vector<int64_t> frustum_of(tm.positions.size(), -1);
  for (size_t t = 0; t < tm.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) frustum_of[tm.indices[3 * t + static_cast<size_t>(c)]] = tm.triangle_frustum[t];
  std::vector<float> tangents;
  tangents.reserve(tm.positions.size() * 4);
  for (size_t v = 0; v < tm.positions.size(); ++v) {
    const glm::dvec3 n = tm.normals[v];
    const glm::dvec3 axis = frustum_of[v] >= 0 ? skinned.frusta[static_cast<size_t>(frustum_of[v])].shape.axis
                                               : glm::dvec3(0, 1, 0);
    glm::dvec3 t = glm::cross(axis, n);  // u grows counter-clockwise about the axis
    // On a cap (normal ∥ axis) any direction ⊥ the normal will do.
    if (glm::length(t) < 1e-6) t = axis_frame(glm::normalize(n)).e0;
    t = glm::normalize(t);
    // cross(N, T)·w must point toward decreasing t, i.e. against the axis.
    const float w = glm::dot(glm::cross(n, t), axis) > 0 ? -1.0f : 1.0f;
    float f[3] = {static_cast<float>(t.x), static_cast<float>(t.y), static_cast<float>(t.z)};
    const float len = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    tangents.insert(tangents.end(), {f[0] / len, f[1] / len, f[2] / len, w});
  }
  return tangents;
}

// Everything the materials of one export refer to, read and baked once.
class MaterialTable {
 public:
  // Reads every texture the plants' barks name (before anything is written).
  std::optional<std::string> load(const std::vector<GltfPlant>& plants) {
    for (const GltfPlant& p : plants) {
      if (p.bark.albedo_texture && !albedo_files_.count(*p.bark.albedo_texture)) {
        EmbeddedImage image;
        if (auto err = read_albedo_image(*p.bark.albedo_texture, &image)) return err;
        albedo_files_.emplace(*p.bark.albedo_texture, std::move(image));
      }
      if (p.bark.height_texture && !height_files_.count(*p.bark.height_texture)) {
        HeightMapReadResult r = read_height_map(*p.bark.height_texture);
        if (!r.map) return r.error.value_or(*p.bark.height_texture + ": error: unreadable height map");
        height_files_.emplace(*p.bark.height_texture, std::move(*r.map));
      }
    }
    return std::nullopt;
  }

  // The normal map texture of `bark` at radius r_ref_m (baked on first use), or nothing
  // when the bark has no height map or the plant no radius.
  std::optional<size_t> normal_texture(const Bark& bark, double r_ref_m, std::string* error) {
    if (!bark.height_texture || !(r_ref_m > 0)) return std::nullopt;
    std::string key = "normal:" + *bark.height_texture + "\n";
    for (double v : {r_ref_m, bark.u_repeat, bark.v_per_metre, bark.relief_depth_m}) append_json_number(key, v), key += ',';
    if (auto it = image_of_.find(key); it != image_of_.end()) return it->second;
    const HeightMap& map = height_files_.at(*bark.height_texture);
    const NormalMapMetric metric =
        bark_normal_map_metric(map.width, map.height, r_ref_m, bark.u_repeat, bark.v_per_metre, bark.relief_depth_m);
    std::optional<std::string> png =
        encode_png_in_memory(map.width, map.height, 3, encode_normals_rgb8(bake_tangent_normals(map, metric)));
    if (!png) {
      *error = *bark.height_texture + ": error: cannot encode the normal map baked from this height map as PNG";
      return std::nullopt;
    }
    return add_image(key, {std::move(*png), "image/png"});
  }

  std::optional<size_t> albedo_texture(const Bark& bark) {
    if (!bark.albedo_texture) return std::nullopt;
    const std::string key = "albedo:" + *bark.albedo_texture;
    if (auto it = image_of_.find(key); it != image_of_.end()) return it->second;
    return add_image(key, albedo_files_.at(*bark.albedo_texture));
  }

  // The index of a material, written once however many plants use it.
  size_t material(const std::string& json) {
    auto [it, inserted] = material_of_.emplace(json, materials_.size());
    if (inserted) materials_.push_back(json);
    return it->second;
  }

  const std::vector<std::string>& materials() const { return materials_; }
  const std::vector<EmbeddedImage>& images() const { return images_; }  // texture i = image i

 private:
  size_t add_image(const std::string& key, EmbeddedImage image) {
    images_.push_back(std::move(image));
    image_of_.emplace(key, images_.size() - 1);
    return images_.size() - 1;
  }

  std::map<std::string, EmbeddedImage> albedo_files_;
  std::map<std::string, HeightMap> height_files_;
  std::map<std::string, size_t> image_of_;
  std::vector<EmbeddedImage> images_;
  std::map<std::string, size_t> material_of_;
  std::vector<std::string> materials_;
};

}  // namespace

std::optional<std::string> check_bark_textures(const Bark& bark) {
  if (bark.albedo_texture) {
    EmbeddedImage image;
    if (auto err = read_albedo_image(*bark.albedo_texture, &image)) return err;
  }
  if (bark.height_texture) {
    HeightMapReadResult r = read_height_map(*bark.height_texture);
    if (!r.map) return r.error.value_or(*bark.height_texture + ": error: unreadable height map");
  }
  return std::nullopt;
}

double bark_reference_radius_m(const Skeleton& skeleton) { return median_segment_radius(skin_skeleton(skeleton)); }

std::optional<std::string> export_gltf(const std::vector<GltfPlant>& plants, const std::string& path,
                                       const GltfExportOptions& options) {
  const std::string ext = lower_case(path);
  const bool glb = ends_with(ext, ".glb");
  if (!glb && !ends_with(ext, ".gltf")) return path + ": error: the output must end in .gltf or .glb";
  if (plants.empty()) return path + ": error: no plants to export";
  if (options.segments_around < 3 || options.segments_around > 4096)
    return path + ": error: segments around must be an integer from 3 to 4096";
  for (size_t i = 0; i < plants.size(); ++i)
    if (auto err = check_plant(plants[i], i)) return path + ": error: " + *err;
  MaterialTable table;
  if (options.mesh)
    if (auto err = table.load(plants)) return err;

  // Group identical skeletons when instancing (compared by their exact serialization,
  // and by their barks when those shape the mesh).
  std::vector<PlantGroup> groups;
  if (options.instancing) {
    std::map<std::string, size_t> group_of;
    for (size_t i = 0; i < plants.size(); ++i) {
      std::string key = write_skeleton_json(plants[i].skeleton);
      if (options.mesh) key += bark_key(plants[i].bark);
      auto [it, inserted] = group_of.emplace(std::move(key), groups.size());
      if (inserted) groups.emplace_back();
      groups[it->second].plants.push_back(i);
    }
  } else {
    for (size_t i = 0; i < plants.size(); ++i) groups.push_back({{i}});
  }

  BufferBuilder buffer;
  std::vector<std::string> meshes, nodes;
  bool any_instancing = false;
  for (const PlantGroup& group : groups) {
    const GltfPlant& plant = plants[group.plants.front()];
    const Skeleton& sk = plant.skeleton;
    const SkinnedSkeleton skinned = skin_skeleton(sk);

    // The skeleton as LINES: vertex i is joint i; one (parent joint, child joint) pair
    // per segment, a branch's first segment starting at the joint it grows from.
    std::string primitives;
    if (sk.segment_count() > 0) {
      std::vector<float> positions, radii;
      positions.reserve(sk.joints.size() * 3);
      for (const Joint& j : sk.joints) {
        for (double x : j.position_m) positions.push_back(static_cast<float>(x));
        radii.push_back(static_cast<float>(j.radius_m));
      }
      std::vector<uint32_t> pairs;
      pairs.reserve(sk.segment_count() * 2);
      for (const Chain& c : sk.chains) {
        for (uint32_t j = 1; j < c.joint_count; ++j) {
          uint32_t lower = c.first_joint + j - 1;
          if (j == 1 && c.parent) lower = sk.chains[c.parent->chain].first_joint + c.parent->joint;
          pairs.push_back(lower);
          pairs.push_back(c.first_joint + j);
        }
      }
      const size_t pos = buffer.add_floats(positions, 3, "VEC3", kTargetArrayBuffer);
      const size_t rad = buffer.add_floats(radii, 1, "SCALAR", kTargetArrayBuffer);
      const size_t idx = buffer.add_indices(pairs);
      primitives += "{\"attributes\":{\"POSITION\":" + std::to_string(pos) + ",\"_RADIUS\":" + std::to_string(rad) +
                    "},\"indices\":" + std::to_string(idx) + ",\"mode\":" + std::to_string(kModeLines) + "}";
    }
    if (options.mesh && !skinned.frusta.empty()) {
      TessellateOptions to;
      to.segments_around = options.segments_around;
      const TriangleMesh tm = tessellate(skinned, to);
      if (!tm.indices.empty()) {
        const Bark& bark = plant.bark;
        const double r_ref_m = median_segment_radius(skinned);
        std::string error;
        const std::optional<size_t> normal_texture = table.normal_texture(bark, r_ref_m, &error);
        if (!error.empty()) return error;
        const std::optional<size_t> albedo_texture = table.albedo_texture(bark);

        std::vector<float> positions, normals, texcoords;
        positions.reserve(tm.positions.size() * 3);
        normals.reserve(tm.normals.size() * 3);
        texcoords.reserve(tm.uvs.size() * 2);
        for (const glm::dvec3& p : tm.positions)
          positions.insert(positions.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
        for (const glm::dvec3& n : tm.normals) {
          // Renormalised in float so the validator's unit-length check holds exactly.
          float f[3] = {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)};
          const float len = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
          normals.insert(normals.end(), {f[0] / len, f[1] / len, f[2] / len});
        }
        for (const glm::dvec2& uv : tm.uvs)
          texcoords.insert(texcoords.end(),
                           {static_cast<float>(uv.x * bark.u_repeat), static_cast<float>(uv.y * bark.v_per_metre)});
        std::string attributes = "{\"POSITION\":" + std::to_string(buffer.add_floats(positions, 3, "VEC3", kTargetArrayBuffer)) +
                                 ",\"NORMAL\":" + std::to_string(buffer.add_floats(normals, 3, "VEC3", kTargetArrayBuffer));
        if (normal_texture)
          attributes += ",\"TANGENT\":" +
                        std::to_string(buffer.add_floats(vertex_tangents(tm, skinned), 4, "VEC4", kTargetArrayBuffer));
        attributes += ",\"TEXCOORD_0\":" + std::to_string(buffer.add_floats(texcoords, 2, "VEC2", kTargetArrayBuffer)) + "}";

        // One primitive per material index, in increasing order.
        std::map<uint32_t, std::vector<uint32_t>> triangles_of;
        for (size_t t = 0; t < tm.triangle_count(); ++t) {
          std::vector<uint32_t>& list = triangles_of[skinned.frusta[tm.triangle_frustum[t]].material];
          list.insert(list.end(), tm.indices.begin() + static_cast<std::ptrdiff_t>(3 * t),
                      tm.indices.begin() + static_cast<std::ptrdiff_t>(3 * t + 3));
        }
        for (const auto& [material, indices] : triangles_of) {
          const size_t m = table.material(material_json(material, bark, albedo_texture, normal_texture, r_ref_m));
          if (!primitives.empty()) primitives += ',';
          primitives += "{\"attributes\":" + attributes + ",\"indices\":" + std::to_string(buffer.add_indices(indices)) +
                        ",\"material\":" + std::to_string(m) + ",\"mode\":" + std::to_string(kModeTriangles) + "}";
        }
      }
    }

    std::string node = "{\"name\":";
    append_json_string(node, plant.name);
    if (!primitives.empty()) {
      meshes.push_back("{\"name\":");
      append_json_string(meshes.back(), plant.name);
      meshes.back() += ",\"primitives\":[" + primitives + "]}";
      node += ",\"mesh\":" + std::to_string(meshes.size() - 1);
    }
    const bool instanced = group.plants.size() > 1;
    if (instanced) {
      // EXT_mesh_gpu_instancing: the node keeps the identity transform; each instance's
      // TRS is in the attributes (float), exact values in extras.sylva.instances.
      std::vector<float> translation, rotation, scale;
      for (size_t i : group.plants) {
        const GltfPlant& p = plants[i];
        for (double x : p.position_m) translation.push_back(static_cast<float>(x));
        for (double q : quaternion_about_y(p.rotate_y_deg)) rotation.push_back(static_cast<float>(q));
        for (int k = 0; k < 3; ++k) scale.push_back(static_cast<float>(p.scale));
      }
      const size_t t = buffer.add_floats(translation, 3, "VEC3", 0);
      const size_t r = buffer.add_floats(rotation, 4, "VEC4", 0);
      const size_t s = buffer.add_floats(scale, 3, "VEC3", 0);
      node += ",\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":{\"TRANSLATION\":" + std::to_string(t) +
              ",\"ROTATION\":" + std::to_string(r) + ",\"SCALE\":" + std::to_string(s) + "}}}";
      any_instancing = true;
    } else {
      if (plant.position_m[0] != 0 || plant.position_m[1] != 0 || plant.position_m[2] != 0) {
        node += ",\"translation\":";
        append_vec(node, plant.position_m, 3);
      }
      if (plant.rotate_y_deg != 0) {
        const auto q = quaternion_about_y(plant.rotate_y_deg);
        node += ",\"rotation\":";
        append_vec(node, q.data(), 4);
      }
      if (plant.scale != 1) {
        const double s[3] = {plant.scale, plant.scale, plant.scale};
        node += ",\"scale\":";
        append_vec(node, s, 3);
      }
    }
    node += ",\"extras\":{\"sylva\":{";
    append_skeleton_document(node, sk);
    node += ',';
    append_skinning(node, skinned);
    node += ",\"instances\":[";
    for (size_t k = 0; k < group.plants.size(); ++k) {
      if (k) node += ',';
      append_instance(node, plants[group.plants[k]]);
    }
    node += "]}}}";
    nodes.push_back(std::move(node));
  }

  // The document. Arrays that would be empty are left out (glTF forbids empty arrays).
  std::string json = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sylva\"}";
  if (any_instancing) json += ",\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"]";
  json += ",\"scene\":0,\"scenes\":[{\"nodes\":[";
  for (size_t i = 0; i < nodes.size(); ++i) json += (i ? "," : "") + std::to_string(i);
  json += "]}],\"nodes\":[";
  for (size_t i = 0; i < nodes.size(); ++i) json += (i ? "," : "") + nodes[i];
  json += ']';
  if (!meshes.empty()) {
    json += ",\"meshes\":[";
    for (size_t i = 0; i < meshes.size(); ++i) json += (i ? "," : "") + meshes[i];
    json += ']';
  }
  if (!table.materials().empty()) {
    json += ",\"materials\":[";
    for (size_t i = 0; i < table.materials().size(); ++i) json += (i ? "," : "") + table.materials()[i];
    json += ']';
  }
  if (!table.images().empty()) {
    // Texture i shows image i; one sampler: linear, mipmapped, repeating (the bark tiles).
    json += ",\"samplers\":[{\"magFilter\":" + std::to_string(kFilterLinear) +
            ",\"minFilter\":" + std::to_string(kFilterLinearMipmapLinear) + ",\"wrapS\":" + std::to_string(kWrapRepeat) +
            ",\"wrapT\":" + std::to_string(kWrapRepeat) + "}],\"textures\":[";
    for (size_t i = 0; i < table.images().size(); ++i)
      json += std::string(i ? "," : "") + "{\"sampler\":0,\"source\":" + std::to_string(i) + "}";
    json += "],\"images\":[";
    for (size_t i = 0; i < table.images().size(); ++i) {
      const EmbeddedImage& image = table.images()[i];
      if (i) json += ',';
      if (glb)
        json += "{\"bufferView\":" + std::to_string(buffer.add_bytes(image.bytes)) + ",\"mimeType\":\"" + image.mime + "\"}";
      else
        json += "{\"uri\":\"data:" + std::string(image.mime) + ";base64," + base64(image.bytes) + "\"}";
    }
    json += ']';
  }
  const std::string& bin = buffer.bytes();
  if (!buffer.accessors().empty()) {
    json += ",\"accessors\":[";
    for (size_t i = 0; i < buffer.accessors().size(); ++i) {
      const Accessor& a = buffer.accessors()[i];
      if (i) json += ',';
      json += "{\"bufferView\":" + std::to_string(a.view) + ",\"componentType\":" + std::to_string(a.component) +
              ",\"count\":" + std::to_string(a.count) + ",\"type\":\"" + a.type + "\",\"min\":";
      append_vec(json, a.min.data(), a.min.size());
      json += ",\"max\":";
      append_vec(json, a.max.data(), a.max.size());
      json += '}';
    }
    json += "],\"bufferViews\":[";
    for (size_t i = 0; i < buffer.views().size(); ++i) {
      const BufferView& v = buffer.views()[i];
      if (i) json += ',';
      json += "{\"buffer\":0,\"byteOffset\":" + std::to_string(v.offset) + ",\"byteLength\":" + std::to_string(v.length);
      if (v.target) json += ",\"target\":" + std::to_string(v.target);
      json += '}';
    }
    json += "],\"buffers\":[{\"byteLength\":" + std::to_string(bin.size());
    if (!glb) json += ",\"uri\":\"data:application/octet-stream;base64," + base64(bin) + "\"";
    json += "}]";
  }
  json += "}\n";

  std::string file;
  if (glb) {
    std::string json_chunk = json;
    while (json_chunk.size() % 4 != 0) json_chunk += ' ';
    std::string bin_chunk = bin;
    while (bin_chunk.size() % 4 != 0) bin_chunk += '\0';
    const size_t total = 12 + 8 + json_chunk.size() + (bin_chunk.empty() ? 0 : 8 + bin_chunk.size());
    if (total > std::numeric_limits<uint32_t>::max()) return path + ": error: the model exceeds the 4 GiB of a GLB file";
    file.reserve(total);
    append_u32(file, kGlbMagic);
    append_u32(file, 2);
    append_u32(file, static_cast<uint32_t>(total));
    append_u32(file, static_cast<uint32_t>(json_chunk.size()));
    append_u32(file, kGlbChunkJson);
    file += json_chunk;
    if (!bin_chunk.empty()) {
      append_u32(file, static_cast<uint32_t>(bin_chunk.size()));
      append_u32(file, kGlbChunkBin);
      file += bin_chunk;
    }
  } else {
    file = std::move(json);
  }
  if (auto err = write_file_atomically(path, file)) return err->format();
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------
// Import: only the JSON is read; every value is checked before use.

namespace {

std::string place(const std::string& path, const JsonValue& v) {
  return path + ":" + std::to_string(v.line) + ":" + std::to_string(v.column) + ": error: ";
}

// Writes a DOM value back as JSON text (numbers by their exact source text).
void append_value(std::string& out, const JsonValue& v) {
  switch (v.kind) {
    case JsonValue::Kind::Null: out += "null"; break;
    case JsonValue::Kind::Bool: out += v.boolean ? "true" : "false"; break;
    case JsonValue::Kind::Number: out += v.text; break;
    case JsonValue::Kind::String: append_json_string(out, v.text); break;
    case JsonValue::Kind::Array:
      out += '[';
      for (size_t i = 0; i < v.elements.size(); ++i) {
        if (i) out += ',';
        append_value(out, v.elements[i]);
      }
      out += ']';
      break;
    case JsonValue::Kind::Object:
      out += '{';
      for (size_t i = 0; i < v.members.size(); ++i) {
        if (i) out += ',';
        append_json_string(out, v.members[i].key.name);
        out += ':';
        append_value(out, v.members[i].value);
      }
      out += '}';
      break;
  }
}

// The JSON text of a .gltf, or the JSON chunk of a .glb (checked against the file size).
std::optional<std::string> json_text_of(const std::string& path, const std::string& bytes, std::string_view* json) {
  auto u32_at = [&](size_t offset) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + offset, 4);
    return v;
  };
  if (bytes.size() >= 4 && u32_at(0) == kGlbMagic) {
    if (bytes.size() < 20) return path + ": error: truncated GLB file: " + std::to_string(bytes.size()) + " bytes, less than a header";
    if (u32_at(4) != 2) return path + ": error: GLB version " + std::to_string(u32_at(4)) + " is not supported (only 2)";
    if (u32_at(8) != bytes.size())
      return path + ": error: GLB header says " + std::to_string(u32_at(8)) + " bytes but the file has " +
             std::to_string(bytes.size()) + " (truncated or corrupt)";
    const uint64_t json_length = u32_at(12);
    if (u32_at(16) != kGlbChunkJson) return path + ": error: the first GLB chunk is not JSON";
    if (20 + json_length > bytes.size())
      return path + ": error: the GLB JSON chunk (" + std::to_string(json_length) + " bytes) runs past the end of the file";
    *json = std::string_view(bytes).substr(20, json_length);
    return std::nullopt;
  }
  size_t i = 0;
  if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\n' || bytes[i] == '\r')) ++i;
  if (i == bytes.size() || bytes[i] != '{')
    return path + ": error: not a glTF file (neither GLB nor a JSON object)";
  *json = bytes;
  return std::nullopt;
}

// One node's extras.sylva back into plants (one per instance).
std::optional<std::string> read_sylva_extras(const std::string& path, const JsonValue& node, size_t node_index,
                                             const JsonValue& sylva, std::vector<GltfPlant>* plants) {
  const JsonValue* name_value = node.find("name");
  const std::string node_name = name_value && name_value->is_string() ? name_value->text : "";
  const std::string where = "node " + std::to_string(node_index) +
                            (node_name.empty() ? "" : " (" + json_excerpt(node_name) + ")") + " extras.sylva";
  if (!sylva.is_object()) return place(path, sylva) + where + " is " + sylva.kind_name() + ", expected an object";

  // Rebuild the skeleton document (seed string back to an integer) and read it with the
  // skeleton reader, which checks every value.
  std::string text = "{";
  bool first = true;
  for (const char* key : {"format", "version", "source", "chains"}) {
    const JsonValue* v = sylva.find(key);
    if (!v) return place(path, sylva) + where + ": missing key \"" + key + "\"";
    if (!first) text += ',';
    first = false;
    append_json_string(text, key);
    text += ':';
    if (std::string_view(key) != "source") {
      append_value(text, *v);
      continue;
    }
    if (!v->is_object()) return place(path, *v) + where + ".source is " + v->kind_name() + ", expected an object";
    text += '{';
    for (size_t m = 0; m < v->members.size(); ++m) {
      const JsonMember& member = v->members[m];
      if (m) text += ',';
      append_json_string(text, member.key.name);
      text += ':';
      if (member.key.name == "seed") {
        const JsonValue& seed = member.value;
        bool digits = seed.is_string() && !seed.text.empty() && seed.text.size() <= 20;
        for (char c : seed.text) digits = digits && c >= '0' && c <= '9';
        if (!digits) return place(path, seed) + where + ".source.seed must be a string of decimal digits (a 64-bit seed)";
        text += seed.text;  // range checked by the skeleton reader
      } else {
        append_value(text, member.value);
      }
    }
    text += '}';
  }
  text += '}';
  SkeletonReadResult read = read_skeleton_json(text, path);
  if (!read.skeleton) {
    const std::string message = read.error ? read.error->message : "unreadable skeleton";
    return place(path, sylva) + where + ": " + message;
  }

  const JsonValue* instances = sylva.find("instances");
  if (!instances) {
    GltfPlant p;
    p.name = node_name;
    p.skeleton = std::move(*read.skeleton);
    plants->push_back(std::move(p));
    return std::nullopt;
  }
  if (!instances->is_array() || instances->elements.empty())
    return place(path, *instances) + where + ".instances must be a non-empty array";
  for (size_t k = 0; k < instances->elements.size(); ++k) {
    const JsonValue& inst = instances->elements[k];
    const std::string iwhere = where + ".instances[" + std::to_string(k) + "]";
    if (!inst.is_object()) return place(path, inst) + iwhere + " must be an object";
    GltfPlant p;
    p.skeleton = *read.skeleton;
    const JsonValue* name = inst.find("name");
    const JsonValue* position = inst.find("position_m");
    const JsonValue* rotate = inst.find("rotate_y_deg");
    const JsonValue* scale = inst.find("scale");
    if (!name || !name->is_string()) return place(path, inst) + iwhere + ".name must be a string";
    p.name = name->text;
    if (!position || !position->is_array() || position->elements.size() != 3)
      return place(path, inst) + iwhere + ".position_m must be an array of 3 numbers";
    for (size_t c = 0; c < 3; ++c) {
      if (!position->elements[c].is_number()) return place(path, position->elements[c]) + iwhere + ".position_m must hold numbers";
      p.position_m[c] = position->elements[c].number;
    }
    if (!rotate || !rotate->is_number()) return place(path, inst) + iwhere + ".rotate_y_deg must be a number";
    p.rotate_y_deg = rotate->number;
    if (!scale || !scale->is_number() || !(scale->number > 0))
      return place(path, inst) + iwhere + ".scale must be a number > 0";
    p.scale = scale->number;
    plants->push_back(std::move(p));
  }
  return std::nullopt;
}

}  // namespace

GltfImportResult import_gltf_skeletons(const std::string& path) {
  GltfImportResult result;
  FileReadResult file = read_text_file(path);
  if (!file.contents) {
    result.error = file.error ? file.error->format() : path + ": error: cannot read";
    return result;
  }
  std::string_view json;
  if (auto err = json_text_of(path, *file.contents, &json)) {
    result.error = *err;
    return result;
  }
  JsonParseResult parsed = parse_json(json);
  if (!parsed.value) {
    const JsonError e = parsed.error.value_or(JsonError{});
    result.error = path + ":" + std::to_string(e.line) + ":" + std::to_string(e.column) + ": error: " + e.message;
    return result;
  }
  const JsonValue& root = *parsed.value;
  if (!root.is_object()) {
    result.error = place(path, root) + "a glTF document is a JSON object";
    return result;
  }
  const JsonValue* asset = root.find("asset");
  const JsonValue* version = asset && asset->is_object() ? asset->find("version") : nullptr;
  if (!version || !version->is_string() || version->text.rfind("2.", 0) != 0) {
    result.error = place(path, asset ? *asset : root) + "not a glTF 2.0 file (asset.version \"2.x\" missing)";
    return result;
  }
  const JsonValue* nodes = root.find("nodes");
  if (nodes && !nodes->is_array()) {
    result.error = place(path, *nodes) + "\"nodes\" is " + nodes->kind_name() + ", expected an array";
    return result;
  }
  for (size_t n = 0; nodes && n < nodes->elements.size(); ++n) {
    const JsonValue& node = nodes->elements[n];
    if (!node.is_object()) continue;
    const JsonValue* extras = node.find("extras");
    const JsonValue* sylva = extras && extras->is_object() ? extras->find("sylva") : nullptr;
    if (!sylva) continue;
    if (auto err = read_sylva_extras(path, node, n, *sylva, &result.plants)) {
      result.plants.clear();
      result.error = *err;
      return result;
    }
  }
  if (result.plants.empty())
    result.error = path + ": error: no sylva skeleton in this glTF file (no node has extras.sylva; "
                          "files written by 'sylva export' have one per plant)";
  return result;
}

}  // namespace sylva
