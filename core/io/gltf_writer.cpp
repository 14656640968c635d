// gltf_writer.cpp — skeletons to glTF 2.0 (core/io/gltf.h); the reader is gltf_reader.cpp.
//
// The glTF JSON is written with json.h's JsonWriter rather than tinygltf: the file then
// has the same guarantees as a skeleton file (fixed key order, shortest round-trip
// numbers, byte-identical output for identical input), and none of tinygltf 2.7's
// writer traps can reach it (mode -1 when Primitive::mode is unset, empty nodes as
// `null`, Value("text") turned into a bool, accessor min/max left empty). The tests read
// every exported file with tinygltf as well, as an independent second reader.
//
// Buffer layout: one buffer; one tightly packed bufferView per accessor, each starting
// at a multiple of 4 bytes, then (.glb only) one bufferView per embedded image. Floats
// are little-endian IEEE 754 (as the machine's).
#include "core/io/gltf.h"

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
#include <type_traits>
#include <utility>

#include <OpenImageIO/imageio.h>
#include <meshoptimizer.h>

#include <glm/geometric.hpp>

#include "core/io/gltf_format.h"
#include "core/util/file_io.h"
#include "core/util/image_io.h"
#include "core/util/json.h"
#include "core/geometry/leaf_mesh.h"
#include "core/scene/leaf_images.h"
#include "core/scene/materials.h"
#include "core/io/normal_map.h"
#include "core/geometry/crotch_mesh.h"
#include "core/geometry/skin.h"
#include "core/geometry/tessellate.h"

static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");

namespace sylva {
namespace {

using namespace gltf_format;

constexpr uint32_t kComponentFloat = 5126;
constexpr uint32_t kComponentUint32 = 5125;
constexpr uint32_t kComponentUint16 = 5123;
constexpr uint32_t kComponentUint8 = 5121;
constexpr int kTargetArrayBuffer = 34962;
constexpr int kTargetElementArrayBuffer = 34963;
constexpr int kModeLines = 1;
constexpr int kModeTriangles = 4;
constexpr int kFilterLinear = 9729;
constexpr int kFilterLinearMipmapLinear = 9987;
constexpr int kWrapRepeat = 10497;

// How EXT_meshopt_compression may encode a bufferView (none: never, it stays as it is).
enum class MeshoptMode { none, attributes, triangles, indices };

struct BufferView {
  size_t offset = 0;
  size_t length = 0;
  int target = 0;  // 0: none (instancing attributes)
  MeshoptMode meshopt = MeshoptMode::none;
  size_t stride = 0;  // bytes an element (meshopt modes)
  // After BufferBuilder::compress_meshopt, for an encoded view: where its bytes are in the
  // fallback buffer 1 (offset, length) and its encoding in buffer 0.
  bool compressed = false;
  size_t encoded_offset = 0, encoded_length = 0;
};

struct Accessor {
  size_t view = 0;
  uint32_t component = kComponentFloat;
  size_t count = 0;
  const char* type = "SCALAR";
  std::vector<double> min, max;  // per component, exact values of the stored elements;
                                 // empty: not written (normalized weights)
  bool normalized = false;
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
    set_meshopt(a.view, MeshoptMode::attributes, sizeof(float) * static_cast<size_t>(components));
    accessors_.push_back(std::move(a));
    return accessors_.size() - 1;
  }

  // Appends `values` (count × components unsigned integers, T = uint8_t or uint16_t:
  // JOINTS_0, WEIGHTS_0) with their min/max, or `normalized` (WEIGHTS_0: read as
  // value / max of T) without bounds.
  template <class T>
  size_t add_unsigned(const std::vector<T>& values, int components, const char* type, int target,
                      bool normalized = false) {
    static_assert(std::is_same_v<T, uint8_t> || std::is_same_v<T, uint16_t>);
    const size_t n = static_cast<size_t>(components);
    Accessor a;
    a.component = sizeof(T) == 1 ? kComponentUint8 : kComponentUint16;
    a.type = type;
    a.count = values.size() / n;
    a.normalized = normalized;
    if (!normalized) {
      a.min.assign(n, static_cast<double>(std::numeric_limits<T>::max()));
      a.max.assign(n, 0);
      for (size_t i = 0; i < values.size(); ++i) {
        a.min[i % n] = std::min(a.min[i % n], static_cast<double>(values[i]));
        a.max[i % n] = std::max(a.max[i % n], static_cast<double>(values[i]));
      }
    }
    a.view = add_view(values.data(), values.size() * sizeof(T), target);
    set_meshopt(a.view, MeshoptMode::attributes, sizeof(T) * n);
    accessors_.push_back(std::move(a));
    return accessors_.size() - 1;
  }

  // Indices of a primitive: `triangles` for a triangle list, else (LINES) any sequence.
  size_t add_indices(const std::vector<uint32_t>& indices, bool triangles = true) {
    Accessor a;
    a.component = kComponentUint32;
    a.count = indices.size();
    uint32_t lo = std::numeric_limits<uint32_t>::max(), hi = 0;
    for (uint32_t i : indices) lo = std::min(lo, i), hi = std::max(hi, i);
    a.min = {static_cast<double>(lo)};
    a.max = {static_cast<double>(hi)};
    a.view = add_view(indices.data(), indices.size() * sizeof(uint32_t), kTargetElementArrayBuffer);
    set_meshopt(a.view, triangles && indices.size() % 3 == 0 ? MeshoptMode::triangles : MeshoptMode::indices,
                sizeof(uint32_t));
    accessors_.push_back(std::move(a));
    return accessors_.size() - 1;
  }

  // Appends raw bytes (an image) as a bufferView without target; returns the view index.
  size_t add_bytes(std::string_view data) { return add_view(data.data(), data.size(), 0); }

  // Appends raw little-endian values (extras "compact", gltf_export.h) as a bufferView
  // without target or accessor, 8-byte aligned for the float64 ones; returns its index.
  template <class T>
  size_t add_raw(const std::vector<T>& values) {
    return add_view(values.data(), values.size() * sizeof(T), 0, 8);
  }

  // EXT_meshopt_compression (`--compress meshopt`): every view an accessor reads is encoded
  // (vertex codec for attributes, index codec version 1 for triangle lists, the index
  // sequence codec for other indices) into buffer 0; its plain bytes move to the fallback
  // buffer 1, which the file does not hold. Views without a codec (images, compact
  // extras) stay in buffer 0 as they are, aligned as they were.
  void compress_meshopt() {
    meshopt_encodeIndexVersion(1);
    std::string out, encoded;
    fallback_length_ = 0;
    for (BufferView& v : views_) {
      const unsigned char* data = reinterpret_cast<const unsigned char*>(bytes_.data()) + v.offset;
      if (v.meshopt == MeshoptMode::none || v.length == 0) {
        const size_t alignment = v.target == 0 && v.meshopt == MeshoptMode::none ? 8 : 4;
        while (out.size() % alignment != 0) out.push_back('\0');
        const size_t offset = out.size();
        out.append(reinterpret_cast<const char*>(data), v.length);
        v.offset = offset;
        continue;
      }
      const size_t count = v.length / v.stride;
      if (v.meshopt == MeshoptMode::attributes) {
        encoded.resize(meshopt_encodeVertexBufferBound(count, v.stride));
        encoded.resize(meshopt_encodeVertexBuffer(reinterpret_cast<unsigned char*>(encoded.data()), encoded.size(), data,
                                                  count, v.stride));
      } else {
        std::vector<unsigned int> indices(count);
        std::memcpy(indices.data(), data, v.length);
        const size_t vertices = indices.empty() ? 0 : *std::max_element(indices.begin(), indices.end()) + 1;
        encoded.resize(v.meshopt == MeshoptMode::triangles ? meshopt_encodeIndexBufferBound(count, vertices)
                                                            : meshopt_encodeIndexSequenceBound(count, vertices));
        encoded.resize(v.meshopt == MeshoptMode::triangles
                           ? meshopt_encodeIndexBuffer(reinterpret_cast<unsigned char*>(encoded.data()), encoded.size(),
                                                       indices.data(), count)
                           : meshopt_encodeIndexSequence(reinterpret_cast<unsigned char*>(encoded.data()),
                                                         encoded.size(), indices.data(), count));
      }
      while (out.size() % 4 != 0) out.push_back('\0');
      v.encoded_offset = out.size();
      v.encoded_length = encoded.size();
      out += encoded;
      while (fallback_length_ % 4 != 0) ++fallback_length_;
      v.offset = fallback_length_;
      fallback_length_ += v.length;
      v.compressed = true;
    }
    bytes_ = std::move(out);
  }
  size_t fallback_length() const { return fallback_length_; }
  bool has_meshopt_views() const {
    return std::any_of(views_.begin(), views_.end(),
                       [](const BufferView& v) { return v.meshopt != MeshoptMode::none && v.length > 0; });
  }

  const std::string& bytes() const { return bytes_; }
  const std::vector<BufferView>& views() const { return views_; }
  const std::vector<Accessor>& accessors() const { return accessors_; }

 private:
  size_t add_view(const void* data, size_t length, int target, size_t alignment = 4) {
    while (bytes_.size() % alignment != 0) bytes_.push_back('\0');
    views_.push_back({bytes_.size(), length, target});
    bytes_.append(static_cast<const char*>(data), length);
    return views_.size() - 1;
  }

  void set_meshopt(size_t view, MeshoptMode mode, size_t stride) {
    views_[view].meshopt = mode;
    views_[view].stride = stride;
  }

  std::string bytes_;
  std::vector<BufferView> views_;
  std::vector<Accessor> accessors_;
  size_t fallback_length_ = 0;
};

void write_vec3(JsonWriter& w, const glm::dvec3& v) {
  const double a[3] = {v.x, v.y, v.z};
  w.numbers(a, 3);
}


// Extras "compact": `key` = the bufferView of `values`, left out when there are none.
template <class T>
void write_view(JsonWriter& w, const char* key, const std::vector<T>& values, BufferBuilder& buffer) {
  if (!values.empty()) w.key(key).integer(buffer.add_raw(values));
}

void push_ref(std::vector<uint32_t>& out, const std::optional<ChainParent>& ref) {
  out.push_back(ref ? ref->chain : kNoIndex);
  out.push_back(ref ? ref->joint : kNoIndex);
}

// Extras "compact" (gltf_export.h): the skeleton document's header, then its chains and
// leaves as bufferViews.
void write_compact_skeleton(JsonWriter& w, const Skeleton& sk, BufferBuilder& buffer) {
  write_skeleton_members(w, sk, {.compact = true, .seed_as_string = true, .header_only = true});
  std::vector<uint32_t> counts, parents, materials;
  std::vector<double> joints;
  for (const Chain& c : sk.chains) {
    counts.push_back(c.joint_count);
    push_ref(parents, c.parent);
    for (uint32_t j = 0; j < c.joint_count; ++j) {
      const Joint& joint = sk.joints[c.first_joint + j];
      joints.insert(joints.end(), {joint.position_m[0], joint.position_m[1], joint.position_m[2], joint.radius_m});
      materials.push_back(joint.material);
    }
  }
  w.key("chains").begin_object().key("count").integer(sk.chains.size());
  write_view(w, "joint_count", counts, buffer);
  write_view(w, "parent", parents, buffer);
  write_view(w, "joints", joints, buffer);
  write_view(w, "material", materials, buffer);
  w.end_object();
  if (sk.leaves.empty()) return;
  std::vector<uint32_t> vertex_counts, leaf_joints, leaf_materials, back_materials;
  std::vector<double> vertices;
  const bool backs = std::any_of(sk.leaves.begin(), sk.leaves.end(), [](const Leaf& l) { return l.back_material.has_value(); });
  for (const Leaf& leaf : sk.leaves) {
    vertex_counts.push_back(static_cast<uint32_t>(leaf.vertices_m.size()));
    push_ref(leaf_joints, leaf.joint);
    leaf_materials.push_back(leaf.material);
    // A double-sided leaf's back (docs/leaves.md), the front's where a leaf has none.
    if (backs) back_materials.push_back(leaf.back_material.value_or(leaf.material));
    for (const auto& v : leaf.vertices_m) vertices.insert(vertices.end(), v.begin(), v.end());
  }
  w.key("leaves").begin_object().key("count").integer(sk.leaves.size());
  write_view(w, "vertex_count", vertex_counts, buffer);
  write_view(w, "joint", leaf_joints, buffer);
  write_view(w, "material", leaf_materials, buffer);
  if (backs) write_view(w, "back_material", back_materials, buffer);
  write_view(w, "vertices", vertices, buffer);
  w.end_object();
}

// Per frustum of skin_skeleton (default options): what a renderer needs beyond the
// skeleton to reproduce the surface parametrization. With `binary` (extras "compact")
// the frusta go to bufferViews.
void write_skinning(JsonWriter& w, const SkinnedSkeleton& skinned, SkinStyle skin, BufferBuilder* binary) {
  const SkinOptions defaults;
  w.key("skinning").begin_object();
  w.key("max_tilt_deg").number(defaults.max_tilt_deg);
  w.key("skin").string(skin_style_name(skin));
  w.key("columns").begin_array();
  for (const char* column : {"chain", "segment", "knuckle", "lower_normal", "lower_offset_m", "upper_normal",
                             "upper_offset_m", "u_offset"})
    w.string(column);
  w.end_array();
  if (binary) {
    std::vector<uint32_t> ids;
    std::vector<double> planes;
    for (const Frustum& fr : skinned.frusta) {
      ids.insert(ids.end(), {fr.chain, fr.segment, fr.kind == FrustumKind::knuckle ? 1u : 0u});
      const glm::dvec3 lo = fr.shape.lower.normal, up = fr.shape.upper.normal;
      planes.insert(planes.end(), {lo.x, lo.y, lo.z, fr.shape.lower.offset, up.x, up.y, up.z, fr.shape.upper.offset,
                                   fr.u_offset});
    }
    w.key("frusta").begin_object().key("count").integer(skinned.frusta.size());
    write_view(w, "ids", ids, *binary);
    write_view(w, "planes", planes, *binary);
    w.end_object().end_object();
    return;
  }
  w.key("frusta").begin_array();
  for (const Frustum& fr : skinned.frusta) {
    w.begin_array().integer(fr.chain).integer(fr.segment).boolean(fr.kind == FrustumKind::knuckle);
    write_vec3(w, fr.shape.lower.normal);
    w.number(fr.shape.lower.offset);
    write_vec3(w, fr.shape.upper.normal);
    w.number(fr.shape.upper.offset).number(fr.u_offset).end_array();
  }
  w.end_array();
  w.end_object();
}

void write_instance(JsonWriter& w, const GltfPlant& p) {
  w.begin_object();
  w.key("name").string(p.name);
  w.key("position_m").numbers(p.position_m, 3);
  w.key("rotate_y_deg").number(p.rotate_y_deg);
  w.key("scale").number(p.scale);
  w.end_object();
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

std::string lower_case(std::string s) {
  for (char& c : s)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return s;
}

// One group of plants sharing a skeleton (instancing) or a single plant.
struct PlantGroup {
  std::vector<size_t> plants;  // indices into the caller's vector, first one names the node
};

// Why plant `index` cannot be exported, or nothing.
std::optional<std::string> plant_problem(const GltfPlant& p, size_t index) {
  const std::string which = "plant " + std::to_string(index) + " (" + json_excerpt(p.name) + ")";
  for (double v : p.position_m)
    if (!std::isfinite(v)) return which + ": the position is not finite";
  if (!std::isfinite(p.rotate_y_deg)) return which + ": rotate_y_deg is not finite";
  if (!std::isfinite(p.scale) || p.scale <= 0) return which + ": the scale must be a finite number > 0";
  if (Status valid = validate_skeleton(p.skeleton); !valid) return which + ": " + valid.error().message;
  if (auto far = plant_extent_problem(p.skeleton, {p.position_m[0], p.position_m[1], p.position_m[2]}, p.scale))
    return which + ": " + *far;
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

// Reads an albedo texture laid on segments (a bark's, or the materials table's: scene.h
// segment_texture) to embed it byte for byte: glTF takes PNG or JPEG only.
Expected<EmbeddedImage> read_albedo_image(const std::string& path, const std::string& what = "the bark albedo texture") {
  Expected<std::string> file = read_text_file(path);
  if (!file) return file_diagnostic(path, "cannot read " + what + ": " + file.error().message);
  EmbeddedImage image;
  const std::string& bytes = *file;
  if (bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) image.mime = "image/png";
  else if (bytes.compare(0, 3, "\xFF\xD8\xFF") == 0) image.mime = "image/jpeg";
  else return file_diagnostic(path, what + " must be a PNG or JPEG file to be embedded in glTF");
  // It must decode too, to its last row (a viewer, and the validator, read it).
  if (Status decodes = check_image_opens(path); !decodes)
    return file_diagnostic(path, what + " is not a readable image: " + decodes.error().message);
  image.bytes = std::move(*file);
  return image;
}

// Identifies a bark for grouping identical plants (instancing).
std::string bark_key(const Bark& b) {
  std::string key = "albedo:";
  if (b.albedo_texture) key += "file:" + *b.albedo_texture;
  if (b.albedo_rgb) {
    JsonWriter rgb;
    write_vec3(rgb, *b.albedo_rgb);
    key += rgb.text();
  }
  key += "\nheight:" + b.height_texture.value_or("") + "\n";
  for (double v : {b.relief_depth_m, b.u_repeat, b.v_per_metre}) append_json_number(key, v), key += ',';
  return key;
}

// The material of index `material` of a plant with bark `bark` (gltf_export.h), as JSON
// text (identical materials are written once: the text is their key).
// `albedo_texture`: the texture segment_texture names for it (the bark's or the table's),
// read through TEXCOORD_`texcoord`.
std::string material_json(uint32_t material, const Bark& bark, const std::map<uint32_t, SceneMaterial>& materials,
                          std::optional<size_t> albedo_texture, int texcoord, std::optional<size_t> normal_texture,
                          double r_ref_m, const LeafImages* images) {
  // A segment of a material with a leaf image: the image's mean (leaf_images.h).
  const MaterialLook look = segment_look(materials, &bark, material, images);
  const std::optional<SegmentTexture> segment = segment_texture(materials, &bark, material);
  JsonWriter w;
  w.begin_object();
  w.key("name").string("sylva_material_" + std::to_string(material));
  w.key("pbrMetallicRoughness").begin_object();
  if (albedo_texture) {
    const double white[4] = {1, 1, 1, 1};
    w.key("baseColorFactor").numbers(white, 4);
    w.key("baseColorTexture").begin_object().key("index").integer(*albedo_texture);
    if (texcoord != 0) w.key("texCoord").integer(texcoord);
    w.end_object();
  } else {
    const double factor[4] = {look.albedo.x, look.albedo.y, look.albedo.z, 1};
    w.key("baseColorFactor").numbers(factor, 4);
  }
  w.key("metallicFactor").number(0);
  w.key("roughnessFactor").number(0.9);
  w.end_object();
  if (normal_texture) w.key("normalTexture").begin_object().key("index").integer(*normal_texture).end_object();
  w.key("extras").begin_object().key("sylva").begin_object();
  w.key("material_index").integer(material);
  if (materials.count(material)) {  // an entry of the scene's table (docs/materials.md)
    w.key("specular").number(look.specular);
  }
  if (albedo_texture && segment && !segment->from_bark) {  // the table's image on the segments
    w.key("segment_texture").begin_object();
    w.key("albedo").string(segment->path);
    w.key("u_repeat").number(segment->u_repeat);
    w.key("v_per_metre").number(segment->v_per_metre);
    w.key("texcoord").string("TEXCOORD_" + std::to_string(texcoord) +
                             ": s = u * u_repeat with u in turns around the axis, t = v_m * v_per_metre");
    w.end_object();
  }
  if (material != 0) {  // the bark is the wood's alone (materials.h)
    w.end_object().end_object();
    w.end_object();
    return w.take();
  }
  if (bark.albedo_texture) w.key("albedo").string(*bark.albedo_texture);
  else if (bark.albedo_rgb) write_vec3(w.key("albedo"), *bark.albedo_rgb);
  if (bark.height_texture) w.key("height").string(*bark.height_texture);
  w.key("relief_depth_m").number(bark.relief_depth_m);
  w.key("u_repeat").number(bark.u_repeat);
  w.key("v_per_metre").number(bark.v_per_metre);
  if (normal_texture) w.key("r_ref_m").number(r_ref_m);
  w.key("texcoord_0").string("s = u * u_repeat with u in turns around the axis, t = v_m * v_per_metre with v_m the "
                             "arc length in metres");
  w.end_object().end_object();
  w.end_object();
  return w.take();
}

// The material of the leaves of index `material` (gltf_export.h): the table's look, never
// the bark's (docs/leaves.md); with the table's leaf image (leaf_images.h) `texture` as
// baseColorTexture (its RGB white where the entry has only an alpha image: the colour is
// then the factor), alphaMode MASK at kLeafAlphaCutoff for a cut-out, doubleSided unless
// the entry is one-sided.
// `one_side`: a side of a double-sided leaf with two materials (docs/leaves.md), drawn as
// its own single-sided triangles.
std::string leaf_material_json(uint32_t material, const std::map<uint32_t, SceneMaterial>& materials,
                               const LeafImages* images, std::optional<size_t> texture, bool one_side = false) {
  const MaterialLook look = material_look(materials, nullptr, material);
  const bool image_albedo = images && images->has_albedo(material);
  JsonWriter w;
  w.begin_object();
  w.key("name").string("sylva_leaf_material_" + std::to_string(material) + (one_side ? "_one_side" : ""));
  w.key("pbrMetallicRoughness").begin_object();
  const double factor[4] = {image_albedo ? 1 : look.albedo.x, image_albedo ? 1 : look.albedo.y,
                            image_albedo ? 1 : look.albedo.z, 1};
  w.key("baseColorFactor").numbers(factor, 4);
  if (texture) w.key("baseColorTexture").begin_object().key("index").integer(*texture).end_object();
  w.key("metallicFactor").number(0);
  w.key("roughnessFactor").number(0.9);
  w.end_object();
  if (texture && images->has_cutout(material)) {
    w.key("alphaMode").string("MASK");
    w.key("alphaCutoff").number(kLeafAlphaCutoff);
  }
  w.key("doubleSided").boolean(!one_side && !(images && images->one_sided(material)));
  w.key("extras").begin_object().key("sylva").begin_object();
  w.key("material_index").integer(material);
  w.key("leaf").boolean(true);
  if (one_side) w.key("one_side_of_two").boolean(true);
  if (materials.count(material)) w.key("specular").number(look.specular);
  w.end_object().end_object();
  w.end_object();
  return w.take();
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

// float(v) of each component, appended.
void append_float3(std::vector<float>& out, const glm::dvec3& v) {
  out.insert(out.end(), {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
}

// A unit vector appended as floats, renormalised in float so the validator's unit-length
// check holds exactly.
void append_unit_float3(std::vector<float>& out, const glm::dvec3& n) {
  const float f[3] = {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)};
  const float len = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  out.insert(out.end(), {f[0] / len, f[1] / len, f[2] / len});
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
    append_unit_float3(tangents, t);
    tangents.push_back(w);
  }
  return tangents;
}

// Everything the materials of one export refer to, read and baked once.
class MaterialTable {
 public:
  // Reads every texture the plants' barks and the table's leaves name (before anything is
  // written).
  Status load(const std::vector<GltfPlant>& plants, const std::map<uint32_t, SceneMaterial>& materials) {
    Expected<std::shared_ptr<const LeafImages>> leaf = LeafImages::load(materials);
    if (!leaf) return std::move(leaf.error());
    leaf_images_ = std::move(*leaf);
    for (uint32_t k = 0; k < kMaterialSlots; ++k) {  // the table's images on segments
      const std::optional<SegmentTexture> t = segment_texture(materials, nullptr, k);
      if (!t || albedo_files_.count(t->path)) continue;
      Expected<EmbeddedImage> image =
          read_albedo_image(t->path, "the albedo image of material " + std::to_string(k) + " (on its segments)");
      if (!image) return std::move(image.error());
      albedo_files_.emplace(t->path, std::move(*image));
    }
    for (const GltfPlant& p : plants) {
      if (p.bark.albedo_texture && !albedo_files_.count(*p.bark.albedo_texture)) {
        Expected<EmbeddedImage> image = read_albedo_image(*p.bark.albedo_texture);
        if (!image) return std::move(image.error());
        albedo_files_.emplace(*p.bark.albedo_texture, std::move(*image));
      }
      if (p.bark.height_texture && !height_files_.count(*p.bark.height_texture)) {
        Expected<HeightMap> map = read_height_map(*p.bark.height_texture);
        if (!map) return std::move(map.error());
        height_files_.emplace(*p.bark.height_texture, std::move(*map));
      }
    }
    return {};
  }

  // The normal map texture of `bark` at radius r_ref_m (baked on first use), or nothing
  // when the bark has no height map or the plant no radius.
  Expected<std::optional<size_t>> normal_texture(const Bark& bark, double r_ref_m) {
    if (!bark.height_texture || !(r_ref_m > 0)) return std::optional<size_t>();
    std::string key = "normal:" + *bark.height_texture + "\n";
    for (double v : {r_ref_m, bark.u_repeat, bark.v_per_metre, bark.relief_depth_m}) append_json_number(key, v), key += ',';
    if (auto it = image_of_.find(key); it != image_of_.end()) return std::optional<size_t>(it->second);
    const HeightMap& map = height_files_.at(*bark.height_texture);
    const NormalMapMetric metric =
        bark_normal_map_metric(map.width, map.height, r_ref_m, bark.u_repeat, bark.v_per_metre, bark.relief_depth_m);
    std::optional<std::string> png =
        encode_png_in_memory(map.width, map.height, 3, encode_normals_rgb8(bake_tangent_normals(map, metric)));
    if (!png)
      return file_diagnostic(*bark.height_texture, "cannot encode the normal map baked from this height map as PNG");
    return std::optional<size_t>(add_image(key, {std::move(*png), "image/png"}));
  }

  // The texture of an albedo image laid on segments (read by load).
  size_t albedo_texture(const std::string& path) {
    const std::string key = "albedo:" + path;
    if (auto it = image_of_.find(key); it != image_of_.end()) return it->second;
    return add_image(key, albedo_files_.at(path));
  }

  // The leaf image of material `material` (leaf_images.h: its merged RGBA layer as a PNG),
  // or nothing when the table names none for it.
  Expected<std::optional<size_t>> leaf_texture(uint32_t material) {
    const int k = leaf_images_ ? leaf_images_->layer_of(material) : -1;
    if (k < 0) return std::optional<size_t>();
    const std::string key = "leaf:" + std::to_string(material);
    if (auto it = image_of_.find(key); it != image_of_.end()) return std::optional<size_t>(it->second);
    std::optional<std::string> png = encode_png_in_memory(leaf_images_->width(), leaf_images_->height(), 4,
                                                          leaf_images_->layer(static_cast<size_t>(k)));
    if (!png) return file_diagnostic("", "cannot encode the leaf image of material " + std::to_string(material) + " as PNG");
    return std::optional<size_t>(add_image(key, {std::move(*png), "image/png"}));
  }
  const LeafImages* leaf_images() const { return leaf_images_.get(); }

  // An image made here (an impostor card's PNG), embedded once per key.
  size_t png_texture(const std::string& key, std::string png) {
    if (auto it = image_of_.find(key); it != image_of_.end()) return it->second;
    return add_image(key, {std::move(png), "image/png"});
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
  std::shared_ptr<const LeafImages> leaf_images_;
  std::map<std::string, size_t> image_of_;
  std::vector<EmbeddedImage> images_;
  std::map<std::string, size_t> material_of_;
  std::vector<std::string> materials_;
};

// The triangles of `indices` (3 a triangle), grouped by `material_of(triangle)`, in
// increasing material order: one primitive each.
template <class MaterialOf>
std::map<uint32_t, std::vector<uint32_t>> triangles_by_material(const std::vector<uint32_t>& indices,
                                                                size_t triangle_count, MaterialOf material_of) {
  std::map<uint32_t, std::vector<uint32_t>> triangles_of;
  for (size_t t = 0; t < triangle_count; ++t) {
    std::vector<uint32_t>& list = triangles_of[material_of(t)];
    list.insert(list.end(), indices.begin() + static_cast<std::ptrdiff_t>(3 * t),
                indices.begin() + static_cast<std::ptrdiff_t>(3 * t + 3));
  }
  return triangles_of;
}

// Groups the plants that share a skeleton when instancing (compared by their exact
// serialization, and by their barks when those shape the mesh); else one group a plant.
std::vector<PlantGroup> group_plants(const std::vector<GltfPlant>& plants, const GltfExportOptions& options) {
  std::vector<PlantGroup> groups;
  if (options.instancing) {
    std::map<std::string, size_t> group_of;
    for (size_t i = 0; i < plants.size(); ++i) {
      std::string key = write_skeleton_json(plants[i].skeleton) + skin_style_name(plants[i].skin);
      if (options.mesh) key += bark_key(plants[i].bark);
      auto [it, inserted] = group_of.emplace(std::move(key), groups.size());
      if (inserted) groups.emplace_back();
      groups[it->second].plants.push_back(i);
    }
  } else {
    for (size_t i = 0; i < plants.size(); ++i) groups.push_back({{i}});
  }
  return groups;
}

// What export_gltf builds before the document is written: the binary buffer, the
// materials and images, and the meshes and nodes (each one JSON object, in order).
struct GltfDocument {
  BufferBuilder buffer;
  MaterialTable table;
  std::vector<std::string> meshes, nodes, skins;
  std::vector<size_t> roots;  // the scene's nodes
  bool any_instancing = false;
  bool compress_meshopt = false;  // GltfExportOptions::compress == meshopt
  // The wind clip (GltfExportOptions::animation): its key times' accessor, written once,
  // and its samplers and channels (JSON objects), every plant's.
  std::optional<size_t> clip_times;
  std::vector<std::string> clip_samplers, clip_channels;
};

// A plant's rig and the skeleton it was built on (the mesh's weights come from both).
struct PlantRig {
  const Rig& rig;
  const Skeleton& skeleton;
};

// JOINTS_0 (unsigned byte for rigs of at most 256 joints, else unsigned short) and
// WEIGHTS_0 (normalized unsigned short: the second weight rounded to 1/65535, the first
// the rest, so that every vertex's weights sum to exactly 1) of `weights`, one per
// vertex, as the text `,"JOINTS_0":a,"WEIGHTS_0":b` to add to an open attributes object.
// Unused slots hold joint 0 with weight 0. 12 bytes a vertex (8 with byte joints) where
// floats took 24.
std::string skin_attributes(const std::vector<RigWeights>& weights, size_t rig_joints, BufferBuilder& buffer) {
  std::vector<uint16_t> joints, w;
  joints.reserve(weights.size() * 4);
  w.reserve(weights.size() * 4);
  for (const RigWeights& v : weights) {
    const uint16_t second =
        v.count == 2 ? static_cast<uint16_t>(std::clamp(std::lround(v.weights[1] * 65535.0), 1L, 65534L)) : 0;
    for (size_t i = 0; i < 4; ++i) {
      const bool used = i < static_cast<size_t>(v.count);
      joints.push_back(used ? static_cast<uint16_t>(v.joints[i]) : 0);
      w.push_back(i == 0 ? static_cast<uint16_t>(65535 - second) : i == 1 ? second : 0);
    }
  }
  size_t j;
  if (rig_joints <= 256) {
    const std::vector<uint8_t> bytes(joints.begin(), joints.end());
    j = buffer.add_unsigned(bytes, 4, "VEC4", kTargetArrayBuffer);
  } else {
    j = buffer.add_unsigned(joints, 4, "VEC4", kTargetArrayBuffer);
  }
  const size_t k = buffer.add_unsigned(w, 4, "VEC4", kTargetArrayBuffer, /*normalized=*/true);
  return ",\"JOINTS_0\":" + std::to_string(j) + ",\"WEIGHTS_0\":" + std::to_string(k);
}

// Each vertex's frustum: that of the first triangle using it; UINT32_MAX for a vertex
// on no triangle (a collapsed tip's spare, tessellate.h).
std::vector<uint32_t> vertex_frusta(const TriangleMesh& tm) {
  std::vector<uint32_t> frustum_of(tm.positions.size(), UINT32_MAX);
  for (size_t t = 0; t < tm.triangle_count(); ++t)
    for (size_t k = 0; k < 3; ++k) {
      uint32_t& f = frustum_of[tm.indices[3 * t + k]];
      if (f == UINT32_MAX) f = tm.triangle_frustum[t];
    }
  return frustum_of;
}

// One vertex's wind data (docs/gltf.md "Wind data for shaders"): the point its branch
// swings about, its level (branch order; a leaf one more than its chain) and its phase
// in [0, 1) (its chain's flutter draw).
struct WindVertex {
  glm::dvec3 pivot_m{0};
  uint32_t level = 0;
  double phase = 0;
};

// What the wind data of a plant's vertices comes from.
struct WindSource {
  const Skeleton& skeleton;
  std::vector<uint32_t> order;  // chain_orders
  uint64_t seed;                // the plant's own sway seed

  WindVertex on_chain(uint32_t chain, uint32_t level_offset, const glm::dvec3& pivot) const {
    return {pivot, order[chain] + level_offset, chain_flutter_draw(seed, chain)};
  }
  glm::dvec3 joint(uint32_t j) const {
    return {skeleton.joints[j].position_m[0], skeleton.joints[j].position_m[1], skeleton.joints[j].position_m[2]};
  }
};

// TEXCOORD_2 = (pivot.x, pivot.y), TEXCOORD_3 = (pivot.z, level + phase) as the text
// `,"TEXCOORD_2":a,"TEXCOORD_3":b`, preceded by `,"TEXCOORD_1":texcoord_1` when given
// (glTF numbers the sets without gaps). The phase is kept below 1 in float.
std::string wind_attributes(const std::vector<WindVertex>& wind, BufferBuilder& buffer,
                            std::optional<size_t> texcoord_1 = std::nullopt) {
  std::vector<float> xy, zl;
  xy.reserve(2 * wind.size());
  zl.reserve(2 * wind.size());
  for (const WindVertex& w : wind) {
    xy.insert(xy.end(), {static_cast<float>(w.pivot_m.x), static_cast<float>(w.pivot_m.y)});
    const float level = static_cast<float>(w.level);
    zl.insert(zl.end(), {static_cast<float>(w.pivot_m.z),
                         std::min(level + static_cast<float>(w.phase), std::nextafter(level + 1.0f, level))});
  }
  const size_t a = buffer.add_floats(xy, 2, "VEC2", kTargetArrayBuffer);
  const size_t b = buffer.add_floats(zl, 2, "VEC2", kTargetArrayBuffer);
  return (texcoord_1 ? ",\"TEXCOORD_1\":" + std::to_string(*texcoord_1) : std::string()) + ",\"TEXCOORD_2\":" +
         std::to_string(a) + ",\"TEXCOORD_3\":" + std::to_string(b);
}

// POSITION, NORMAL and TEXCOORD_0 (its accessor in *texcoord_0) of flat geometry (leaves,
// cards) as the text of a JSON object left open for the skin and wind attributes.
std::string open_flat_attributes(const std::vector<float>& positions, const std::vector<float>& normals,
                                 const std::vector<float>& texcoords, BufferBuilder& buffer, size_t* texcoord_0) {
  JsonWriter attributes;
  attributes.begin_object();
  attributes.key("POSITION").integer(buffer.add_floats(positions, 3, "VEC3", kTargetArrayBuffer));
  attributes.key("NORMAL").integer(buffer.add_floats(normals, 3, "VEC3", kTargetArrayBuffer));
  *texcoord_0 = buffer.add_floats(texcoords, 2, "VEC2", kTargetArrayBuffer);
  attributes.key("TEXCOORD_0").integer(*texcoord_0);
  return attributes.take();
}

// The wind data of the segments' mesh: each vertex on its frustum's chain, pivoting about
// the chain's first joint.
std::vector<WindVertex> segment_wind(const TriangleMesh& tm, const std::vector<uint32_t>& frustum_of,
                                     const SkinnedSkeleton& skinned, const WindSource& source) {
  std::vector<WindVertex> wind(tm.positions.size());
  for (size_t v = 0; v < tm.positions.size(); ++v) {
    if (frustum_of[v] == UINT32_MAX) {
      if (v > 0) wind[v] = wind[v - 1];
      continue;
    }
    const uint32_t c = skinned.frusta[frustum_of[v]].chain;
    wind[v] = source.on_chain(c, 0, source.joint(source.skeleton.chains[c].first_joint));
  }
  return wind;
}

// The weights of every vertex of the segments' mesh: each vertex at its arc length along
// the chain of the first triangle that uses it (its projection on that frustum's
// segment; a vertex shared across a joint has the same arc length on both sides).
std::vector<RigWeights> segment_vertex_weights(const TriangleMesh& tm, const std::vector<uint32_t>& frustum_of,
                                               const SkinnedSkeleton& skinned, const PlantRig& plant) {
  const Skeleton& sk = plant.skeleton;
  std::vector<RigWeights> weights(tm.positions.size());
  for (size_t v = 0; v < tm.positions.size(); ++v) {
    if (frustum_of[v] == UINT32_MAX) {  // on no triangle (a collapsed tip's spare): never drawn, it
      if (v > 0) weights[v] = weights[v - 1];  // moves with the vertex before it, its frustum's
      continue;
    }
    const Frustum& f = skinned.frusta[frustum_of[v]];
    const Chain& chain = sk.chains[f.chain];
    const uint32_t lower = chain.first_joint + f.segment;
    double arc = plant.rig.arc_m[lower];
    if (f.segment + 1 < chain.joint_count) {
      const glm::dvec3 a(sk.joints[lower].position_m[0], sk.joints[lower].position_m[1], sk.joints[lower].position_m[2]);
      const glm::dvec3 b(sk.joints[lower + 1].position_m[0], sk.joints[lower + 1].position_m[1],
                         sk.joints[lower + 1].position_m[2]);
      const double length = glm::length(b - a);
      if (length > 0) arc += std::clamp(glm::dot(tm.positions[v] - a, b - a) / length, 0.0, length);
    }
    weights[v] = rig_weights(plant.rig, sk, f.chain, arc);
  }
  return weights;
}

// The primitives of one plant's mesh: a JSON array, open while they are added, and how
// many it holds.
struct MeshPrimitives {
  JsonWriter json;
  size_t count = 0;
};

// The skeleton as LINES: vertex i is joint i; one (parent joint, child joint) pair per
// segment, a branch's first segment starting at the joint it grows from.
void add_skeleton_lines(const Skeleton& sk, BufferBuilder& buffer, MeshPrimitives& primitives) {
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
  const size_t idx = buffer.add_indices(pairs, /*triangles=*/false);
  JsonWriter& json = primitives.json;
  json.begin_object();
  json.key("attributes").begin_object().key("POSITION").integer(pos).key("_RADIUS").integer(rad).end_object();
  json.key("indices").integer(idx);
  json.key("mode").integer(kModeLines);
  json.end_object();
  ++primitives.count;
}

// (u · u_repeat, v_m · v_per_metre) of every vertex of `tm`.
std::vector<float> scaled_uvs(const TriangleMesh& tm, double u_repeat, double v_per_metre) {
  std::vector<float> st;
  st.reserve(tm.uvs.size() * 2);
  for (const glm::dvec2& uv : tm.uvs)
    st.insert(st.end(), {static_cast<float>(uv.x * u_repeat), static_cast<float>(uv.y * v_per_metre)});
  return st;
}

// The vertex attributes all primitives of the segments share, as the text of a JSON
// object left open (a primitive may add its TEXCOORD_1): POSITION, NORMAL, TANGENT with
// a normal map (`tangents`), TEXCOORD_0 in the bark's repeats.
std::string open_segment_attributes(const TriangleMesh& tm, const SkinnedSkeleton& skinned, const Bark& bark,
                                    bool tangents, BufferBuilder& buffer, size_t* texcoord_0) {
  std::vector<float> positions, normals;
  positions.reserve(tm.positions.size() * 3);
  normals.reserve(tm.normals.size() * 3);
  for (const glm::dvec3& p : tm.positions) append_float3(positions, p);
  for (const glm::dvec3& n : tm.normals) append_unit_float3(normals, n);
  const std::vector<float> texcoords = scaled_uvs(tm, bark.u_repeat, bark.v_per_metre);
  // Accessor order NORMAL, POSITION, TANGENT, TEXCOORD_0: the order files written so
  // far have (it came from GCC's right-to-left evaluation of a string concatenation),
  // now fixed in code so that every compiler writes the same bytes.
  const size_t normal_accessor = buffer.add_floats(normals, 3, "VEC3", kTargetArrayBuffer);
  const size_t position_accessor = buffer.add_floats(positions, 3, "VEC3", kTargetArrayBuffer);
  JsonWriter attributes;
  attributes.begin_object();
  attributes.key("POSITION").integer(position_accessor);
  attributes.key("NORMAL").integer(normal_accessor);
  if (tangents)
    attributes.key("TANGENT").integer(buffer.add_floats(vertex_tangents(tm, skinned), 4, "VEC4", kTargetArrayBuffer));
  *texcoord_0 = buffer.add_floats(texcoords, 2, "VEC2", kTargetArrayBuffer);
  attributes.key("TEXCOORD_0").integer(*texcoord_0);
  return attributes.take();
}

// The segments of `skinned` tessellated (tessellate.h), one primitive per material index
// in increasing order, with the bark's textures on the wood; with `fillets_of` (the
// skeleton `skinned` is of) the crotches' fillets an asset carries too (crotch_mesh.h
// asset_fillets): their triangles are in the material of their heavier group's frustum,
// and their vertices are weighted, carry wind data and tangents as that frustum's own
// (each fillet vertex belongs to one group).
Status add_segment_mesh(const SkinnedSkeleton& skinned, const Skeleton* fillets_of, const Bark& bark,
                        const GltfExportOptions& options, const PlantRig* rig, const WindSource* wind,
                        GltfDocument& doc, MeshPrimitives& primitives) {
  TessellateOptions to;
  to.segments_around = options.segments_around;
  TriangleMesh tm = tessellate(skinned, to);
  if (fillets_of) append_mesh(tm, asset_fillets(*fillets_of, skinned.frusta), 0);
  if (tm.indices.empty()) return {};
  const std::map<uint32_t, std::vector<uint32_t>> triangles_of = triangles_by_material(
      tm.indices, tm.triangle_count(), [&](size_t t) { return skinned.frusta[tm.triangle_frustum[t]].material; });
  // The bark's textures are the wood's (material 0, materials.h): a plant without
  // wood embeds none.
  const bool has_wood = triangles_of.count(0) > 0;
  const double r_ref_m = median_segment_radius(skinned);
  Expected<std::optional<size_t>> normal_map =
      has_wood ? doc.table.normal_texture(bark, r_ref_m) : Expected<std::optional<size_t>>(std::optional<size_t>());
  if (!normal_map) return std::move(normal_map.error());
  const std::optional<size_t> normal_texture = *normal_map;

  size_t texcoord_0 = 0;
  std::string open_attributes =
      open_segment_attributes(tm, skinned, bark, normal_texture.has_value(), doc.buffer, &texcoord_0);
  // Each vertex's frustum, once for the skin weights and the wind data.
  const std::vector<uint32_t> frustum_of = rig || wind ? vertex_frusta(tm) : std::vector<uint32_t>();
  if (rig)
    open_attributes +=
        skin_attributes(segment_vertex_weights(tm, frustum_of, skinned, *rig), rig->rig.joints.size(), doc.buffer);
  // Wind data in TEXCOORD_2/3 needs a TEXCOORD_1 (glTF numbers the sets without gaps).
  const std::string wind_text =
      wind ? wind_attributes(segment_wind(tm, frustum_of, skinned, *wind), doc.buffer) : std::string();
  const std::string shared_attributes =
      open_attributes + (wind ? ",\"TEXCOORD_1\":" + std::to_string(texcoord_0) + wind_text : std::string()) + "}";
  // A table image repeating otherwise than the bark reads TEXCOORD_1, its own
  // (u · u_repeat, v_m · v_per_metre); one accessor per distinct pair of repeats.
  std::map<std::pair<double, double>, std::string> attributes_with_texcoord_1;
  for (const auto& [material, indices] : triangles_of) {
    const bool wood = material == 0;  // the bark's textures are the wood's (materials.h)
    const std::optional<SegmentTexture> segment = segment_texture(options.materials, &bark, material);
    int texcoord = 0;
    const std::string* primitive_attributes = &shared_attributes;
    if (segment && (segment->u_repeat != bark.u_repeat || segment->v_per_metre != bark.v_per_metre)) {
      texcoord = 1;
      const std::pair<double, double> repeat{segment->u_repeat, segment->v_per_metre};
      auto it = attributes_with_texcoord_1.find(repeat);
      if (it == attributes_with_texcoord_1.end()) {
        const size_t accessor =
            doc.buffer.add_floats(scaled_uvs(tm, repeat.first, repeat.second), 2, "VEC2", kTargetArrayBuffer);
        it = attributes_with_texcoord_1
                 .emplace(repeat, open_attributes + ",\"TEXCOORD_1\":" + std::to_string(accessor) + wind_text + "}")
                 .first;
      }
      primitive_attributes = &it->second;
    }
    const size_t m = doc.table.material(material_json(
        material, bark, options.materials,
        segment ? std::optional<size_t>(doc.table.albedo_texture(segment->path)) : std::nullopt, texcoord,
        wood ? normal_texture : std::nullopt, r_ref_m, doc.table.leaf_images()));
    JsonWriter& json = primitives.json;
    json.begin_object();
    json.key("attributes").raw(*primitive_attributes);
    json.key("indices").integer(doc.buffer.add_indices(indices));
    json.key("material").integer(m);
    json.key("mode").integer(kModeTriangles);
    json.end_object();
    ++primitives.count;
  }
  return {};
}

// The leaves (leaf_mesh.h): flat triangles with their leaf's normal at each vertex, one
// primitive per material index in increasing order, double-sided materials;
// TEXCOORD_0 = (u, 1 − v) of leaf_uvs (glTF's t runs down the image: an image drawn
// upright, petiole at its bottom row, covers the leaf as the renderers map it). A leaf with
// a back material of its own (docs/leaves.md "Two colours") is two single-sided sheets: its
// triangles in its front's material, and copies of its vertices with the normal reversed,
// wound the other way, in its back's; after the double-sided primitives.
Status add_leaf_mesh(const Skeleton& sk, const GltfExportOptions& options, const PlantRig* rig,
                     const WindSource* wind, GltfDocument& doc, MeshPrimitives& primitives) {
  LeafMesh leaves;
  append_leaves(leaves, sk, 0);
  // (material, one side of two) → its triangles; the back sheets' vertices appended.
  std::map<std::pair<bool, uint32_t>, std::vector<uint32_t>> triangles_of;
  std::vector<uint8_t> reversed(leaves.positions.size(), 0);
  std::vector<uint32_t> copy_of(leaves.positions.size(), UINT32_MAX);
  for (size_t t = 0; t < leaves.triangle_count(); ++t) {
    const LeafRef& leaf = leaves.leaves[leaves.triangle_leaf[t]];
    const uint32_t* tri = &leaves.indices[3 * t];
    const bool two = leaf.back_material != leaf.material;
    std::vector<uint32_t>& front = triangles_of[{two, leaf.material}];
    front.insert(front.end(), tri, tri + 3);
    if (!two) continue;
    std::vector<uint32_t>& back = triangles_of[{true, leaf.back_material}];
    for (int k = 3; k-- > 0;) {
      uint32_t& c = copy_of[tri[k]];
      if (c == UINT32_MAX) {
        c = static_cast<uint32_t>(leaves.positions.size());
        leaves.positions.push_back(leaves.positions[tri[k]]);
        leaves.uvs.push_back(leaves.uvs[tri[k]]);
        leaves.vertex_leaf.push_back(leaves.vertex_leaf[tri[k]]);
        reversed.push_back(1);
      }
      back.push_back(c);
    }
  }
  if (triangles_of.empty()) return {};
  std::vector<float> positions, normals, texcoords;
  for (const glm::dvec2& t : leaves.uvs)
    texcoords.insert(texcoords.end(), {static_cast<float>(t.x), static_cast<float>(1 - t.y)});
  for (const glm::dvec3& q : leaves.positions) append_float3(positions, q);
  for (size_t v = 0; v < leaves.vertex_leaf.size(); ++v) {
    const glm::dvec3& n = leaves.leaves[leaves.vertex_leaf[v]].normal;
    append_unit_float3(normals, reversed[v] ? -n : n);
  }
  size_t texcoord_0 = 0;
  std::string attribute_text = open_flat_attributes(positions, normals, texcoords, doc.buffer, &texcoord_0);
  if (wind) {  // each leaf pivots about its joint, one level above its chain
    std::vector<WindVertex> data;
    data.reserve(leaves.vertex_leaf.size());
    for (size_t v = 0; v < leaves.vertex_leaf.size(); ++v) {
      const Leaf& leaf = sk.leaves[leaves.leaves[leaves.vertex_leaf[v]].leaf];
      if (leaf.joint)
        data.push_back(wind->on_chain(leaf.joint->chain, 1,
                                      wind->joint(wind->skeleton.chains[leaf.joint->chain].first_joint +
                                                  leaf.joint->joint)));
      else  // a leaf before the first segment: about its first vertex, level 1, phase 0
        data.push_back({{leaf.vertices_m[0][0], leaf.vertices_m[0][1], leaf.vertices_m[0][2]}, 1, 0});
    }
    attribute_text += wind_attributes(data, doc.buffer, texcoord_0);
  }
  if (rig) {  // each leaf rides as its joint does
    std::vector<RigWeights> weights;
    weights.reserve(leaves.vertex_leaf.size());
    for (uint32_t l : leaves.vertex_leaf)
      weights.push_back(rig_weights_at_joint(rig->rig, rig->skeleton, sk.leaves[leaves.leaves[l].leaf].joint));
    attribute_text += skin_attributes(weights, rig->rig.joints.size(), doc.buffer);
  }
  attribute_text += "}";
  for (const auto& [key, indices] : triangles_of) {
    const auto [one_side, material] = key;
    JsonWriter& json = primitives.json;
    json.begin_object();
    json.key("attributes").raw(attribute_text);
    json.key("indices").integer(doc.buffer.add_indices(indices));
    Expected<std::optional<size_t>> texture = doc.table.leaf_texture(material);
    if (!texture) return std::move(texture.error());
    json.key("material").integer(doc.table.material(
        leaf_material_json(material, options.materials, doc.table.leaf_images(), *texture, one_side)));
    json.key("mode").integer(kModeTriangles);
    json.end_object();
    ++primitives.count;
  }
  return {};
}

// EXT_mesh_gpu_instancing: the node keeps the identity transform; each instance's TRS is
// in the attributes (float), exact values in extras.sylva.instances.
void write_instancing(JsonWriter& node, const std::vector<GltfPlant>& plants, const PlantGroup& group,
                      BufferBuilder& buffer) {
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
  node.key("extensions").begin_object().key("EXT_mesh_gpu_instancing").begin_object();
  node.key("attributes").begin_object().key("TRANSLATION").integer(t).key("ROTATION").integer(r);
  node.key("SCALE").integer(s).end_object();
  node.end_object().end_object();
}

// A single plant's transform, each part only where it is not the identity's.
void write_placement(JsonWriter& node, const GltfPlant& plant) {
  if (plant.position_m[0] != 0 || plant.position_m[1] != 0 || plant.position_m[2] != 0)
    node.key("translation").numbers(plant.position_m, 3);
  if (plant.rotate_y_deg != 0) node.key("rotation").numbers(quaternion_about_y(plant.rotate_y_deg).data(), 4);
  if (plant.scale != 1) {
    const double s[3] = {plant.scale, plant.scale, plant.scale};
    node.key("scale").numbers(s, 3);
  }
}

// The skeleton document of docs/spec/skeleton.md, the seed as a string (JSON consumers read
// numbers as doubles, which cannot hold every 64-bit seed).
// "compact": the same document with its large arrays in bufferViews (gltf_export.h).
void write_node_extras(JsonWriter& node, const std::vector<GltfPlant>& plants, const PlantGroup& group,
                       const SkinnedSkeleton& skinned, GltfExtras extras, BufferBuilder& buffer) {
  const Skeleton& sk = plants[group.plants.front()].skeleton;
  if (extras == GltfExtras::full) {
    node.key("extras").begin_object().key("sylva").begin_object();
    write_skeleton_members(node, sk, {.compact = true, .seed_as_string = true});
    write_skinning(node, skinned, plants[group.plants.front()].skin, nullptr);
    node.key("instances").begin_array();
    for (size_t i : group.plants) write_instance(node, plants[i]);
    node.end_array();
    node.end_object().end_object();
  } else if (extras == GltfExtras::compact) {
    node.key("extras").begin_object().key("sylva").begin_object();
    write_compact_skeleton(node, sk, buffer);
    write_skinning(node, skinned, plants[group.plants.front()].skin, &buffer);
    std::vector<double> placement;
    node.key("instances").begin_object().key("count").integer(group.plants.size());
    node.key("names").begin_array();
    for (size_t i : group.plants) {
      const GltfPlant& p = plants[i];
      node.string(p.name);
      placement.insert(placement.end(), {p.position_m[0], p.position_m[1], p.position_m[2], p.rotate_y_deg, p.scale});
    }
    node.end_array();
    write_view(node, "placement", placement, buffer);
    node.end_object();
    node.end_object().end_object();
  }
}

// The rotation about the unit `axis` by angle_rad as a glTF quaternion (x, y, z, w).
std::array<float, 4> axis_quaternion(const glm::dvec3& axis, double angle_rad) {
  const double s = std::sin(0.5 * angle_rad);
  return {static_cast<float>(axis.x * s), static_cast<float>(axis.y * s), static_cast<float>(axis.z * s),
          static_cast<float>(std::cos(0.5 * angle_rad))};
}

// The wind clip's channels for one plant's rig (joint j is node base + j): each joint's
// local rotation at every key, R(φ_j − φ_parent) about the sway axis (gltf_rig.h
// pose_rig), the last key a copy of the first. Joints that never turn get no channel.
void add_clip_channels(GltfDocument& doc, const Skeleton& sk, const Rig& rig, size_t base, const GltfWindClip& clip,
                       const SwayParameters& sway) {
  const std::optional<glm::dvec3> axis = sway_axis(sway);
  if (!axis) return;
  const uint64_t intervals = wind_clip_intervals(clip);
  if (!doc.clip_times) {
    std::vector<float> times;
    for (uint64_t i = 0; i <= intervals; ++i)
      times.push_back(static_cast<float>(clip.duration_s * static_cast<double>(i) / static_cast<double>(intervals)));
    doc.clip_times = doc.buffer.add_floats(times, 1, "SCALAR", 0);
  }
  // local[j][i]: joint j's local angle at key i.
  std::vector<std::vector<double>> local(rig.joints.size(), std::vector<double>(intervals + 1, 0.0));
  for (uint64_t i = 0; i < intervals; ++i) {
    const double t_s = clip.duration_s * static_cast<double>(i) / static_cast<double>(intervals);
    const std::vector<double> angle = sway_joint_angles(sk, t_s, sway);
    for (size_t j = 1; j < rig.joints.size(); ++j) {
      const RigJoint& joint = rig.joints[j];
      const double parent = joint.parent == 0 ? 0.0 : angle[rig.joints[joint.parent].skeleton_joint];
      local[j][i] = angle[joint.skeleton_joint] - parent;
    }
  }
  for (size_t j = 1; j < rig.joints.size(); ++j) {
    local[j][intervals] = local[j][0];
    if (std::all_of(local[j].begin(), local[j].end(), [](double a) { return a == 0; })) continue;
    std::vector<float> quaternions;
    quaternions.reserve(4 * local[j].size());
    for (double a : local[j]) {
      const std::array<float, 4> q = axis_quaternion(*axis, a);
      quaternions.insert(quaternions.end(), q.begin(), q.end());
    }
    const size_t output = doc.buffer.add_floats(quaternions, 4, "VEC4", 0);
    JsonWriter sampler;
    sampler.begin_object().key("input").integer(*doc.clip_times).key("interpolation").string("LINEAR");
    sampler.key("output").integer(output).end_object();
    JsonWriter channel;
    channel.begin_object().key("sampler").integer(doc.clip_samplers.size());
    channel.key("target").begin_object().key("node").integer(base + j).key("path").string("rotation").end_object();
    channel.end_object();
    doc.clip_samplers.push_back(sampler.take());
    doc.clip_channels.push_back(channel.take());
  }
}

// The rig of one plant (gltf_rig.h) as glTF: its joints as nodes base, base + 1, … (the
// root, named NAME_rig, a child of the plant's node; joint j named NAME_joint_j with its
// rest offset from its parent and extras {"sylva_rig": {"chain", "joint"}}, the skeleton
// joint it sits on), the skin with inverse bind matrices (the rest positions' inverse
// translations, in the plant's frame), and a scene root node NAME_skin drawing the
// skinned `primitives` (glTF ignores a skinned mesh node's transform; the placement
// reaches the mesh through the joints under the plant's node).
void add_rig_nodes(GltfDocument& doc, const GltfPlant& plant, const Rig& rig,
                   const std::vector<std::pair<std::string, MeshPrimitives>>& surfaces) {
  const size_t base = doc.nodes.size();
  std::vector<std::vector<size_t>> children(rig.joints.size());
  for (size_t j = 1; j < rig.joints.size(); ++j) children[rig.joints[j].parent].push_back(j);
  std::vector<float> inverse_bind;
  inverse_bind.reserve(16 * rig.joints.size());
  for (size_t j = 0; j < rig.joints.size(); ++j) {
    const RigJoint& joint = rig.joints[j];
    JsonWriter node;
    node.begin_object();
    node.key("name").string(j == 0 ? plant.name + "_rig" : plant.name + "_joint_" + std::to_string(j));
    if (!children[j].empty()) {
      node.key("children").begin_array();
      for (size_t c : children[j]) node.integer(base + c);
      node.end_array();
    }
    if (j > 0) {
      const glm::dvec3 offset = joint.position_m - rig.joints[joint.parent].position_m;
      if (offset != glm::dvec3(0)) write_vec3(node.key("translation"), offset);
      node.key("extras").begin_object().key("sylva_rig").begin_object();
      node.key("chain").integer(joint.chain);
      node.key("joint").integer(joint.skeleton_joint - plant.skeleton.chains[joint.chain].first_joint);
      node.end_object().end_object();
    }
    node.end_object();
    doc.nodes.push_back(node.take());
    const float column_major[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, static_cast<float>(-joint.position_m.x),
                                    static_cast<float>(-joint.position_m.y), static_cast<float>(-joint.position_m.z), 1};
    inverse_bind.insert(inverse_bind.end(), std::begin(column_major), std::end(column_major));
  }
  JsonWriter skin;
  skin.begin_object();
  skin.key("inverseBindMatrices").integer(doc.buffer.add_floats(inverse_bind, 16, "MAT4", 0));
  skin.key("joints").begin_array();
  for (size_t j = 0; j < rig.joints.size(); ++j) skin.integer(base + j);
  skin.end_array();
  skin.key("name").string(plant.name);
  skin.key("skeleton").integer(base);
  skin.end_object();
  doc.skins.push_back(skin.take());
  for (const auto& [name, primitives] : surfaces) {
    if (primitives.count == 0) continue;
    JsonWriter mesh;
    mesh.begin_object().key("name").string(name).key("primitives").raw(primitives.json.text()).end_object();
    doc.meshes.push_back(mesh.take());
    JsonWriter node;
    node.begin_object().key("mesh").integer(doc.meshes.size() - 1).key("name").string(name);
    node.key("skin").integer(doc.skins.size() - 1).end_object();
    doc.roots.push_back(doc.nodes.size());
    doc.nodes.push_back(node.take());
  }
}

// The surface of one skeleton (the plant, or a level of detail of it: its chains and
// joints indexed as the plant's): the tessellated segments, with `fillets` the crotches'
// fillets, and the leaves.
Status add_surface(const Skeleton& sk, const SkinnedSkeleton& skinned, bool fillets, const Bark& bark,
                   const GltfExportOptions& options, const PlantRig* rig, const WindSource* wind, GltfDocument& doc,
                   MeshPrimitives& primitives) {
  if (options.mesh && !skinned.frusta.empty())
    if (Status added = add_segment_mesh(skinned, fillets ? &sk : nullptr, bark, options, rig, wind, doc, primitives);
        !added)
      return added;
  if (options.mesh && !sk.leaves.empty())
    if (Status added = add_leaf_mesh(sk, options, rig, wind, doc, primitives); !added) return added;
  return {};
}

// The impostor cards (gltf_lod.h) of `plant` as one primitive each: a double-sided,
// cut-out quad textured with card_renderer's image; on the rig's root, the wind data's
// pivot at the plant's origin (level 0, phase 0).
Status add_impostor_cards(const GltfPlant& plant, size_t plant_index, const GltfExportOptions& options,
                          const PlantRig* rig, const WindSource* wind, GltfDocument& doc, MeshPrimitives& primitives) {
  const std::optional<std::vector<ImpostorCard>> cards = impostor_cards(plant.skeleton);
  if (!cards) return {};
  for (size_t i = 0; i < cards->size(); ++i) {
    const ImpostorCard& card = (*cards)[i];
    const uint32_t height = options.card_pixels;
    const uint32_t width = static_cast<uint32_t>(
        std::clamp(std::lround(height * card.half_width_m / card.half_height_m), 1L, 4L * height));
    Expected<CardImage> image = options.card_renderer(plant, card, width, height);
    if (!image) return std::move(image.error());
    if (image->width == 0 || image->height == 0 || image->rgba.size() != size_t{4} * image->width * image->height)
      return file_diagnostic("", "the impostor card renderer gave " + plant.name + " an image of the wrong size");
    std::optional<std::string> png = encode_png_in_memory(image->width, image->height, 4, image->rgba);
    if (!png) return file_diagnostic("", "cannot encode the impostor card of " + plant.name + " as PNG");
    const size_t texture =
        doc.table.png_texture("card:" + std::to_string(plant_index) + ":" + std::to_string(i), std::move(*png));
    JsonWriter material;
    material.begin_object();
    material.key("alphaCutoff").number(0.5).key("alphaMode").string("MASK").key("doubleSided").boolean(true);
    material.key("name").string(plant.name + "_card_" + std::to_string(i));
    material.key("pbrMetallicRoughness").begin_object();
    material.key("baseColorTexture").begin_object().key("index").integer(texture).end_object();
    material.key("metallicFactor").number(0).key("roughnessFactor").number(1).end_object();
    material.end_object();
    // The quad: image rows from the top (glTF's t runs down the image).
    const glm::dvec3 up(0, 1, 0);
    const glm::dvec3 corner[4] = {card.centre_m - card.half_width_m * card.right + card.half_height_m * up,
                                  card.centre_m + card.half_width_m * card.right + card.half_height_m * up,
                                  card.centre_m + card.half_width_m * card.right - card.half_height_m * up,
                                  card.centre_m - card.half_width_m * card.right - card.half_height_m * up};
    std::vector<float> positions, normals, texcoords = {0, 0, 1, 0, 1, 1, 0, 1};
    for (const glm::dvec3& c : corner) append_float3(positions, c), append_unit_float3(normals, card.normal);
    size_t texcoord_0 = 0;
    std::string text = open_flat_attributes(positions, normals, texcoords, doc.buffer, &texcoord_0);
    if (rig) text += skin_attributes(std::vector<RigWeights>(4), rig->rig.joints.size(), doc.buffer);
    if (wind) text += wind_attributes(std::vector<WindVertex>(4), doc.buffer, texcoord_0);
    text += "}";
    // Counter-clockwise seen from the side the normal points to.
    const glm::dvec3 turn = glm::cross(corner[1] - corner[0], corner[3] - corner[0]);
    const std::vector<uint32_t> indices = glm::dot(turn, card.normal) < 0 ? std::vector<uint32_t>{0, 3, 2, 0, 2, 1}
                                                                           : std::vector<uint32_t>{0, 1, 2, 0, 2, 3};
    JsonWriter& json = primitives.json;
    json.begin_object();
    json.key("attributes").raw(text);
    json.key("indices").integer(doc.buffer.add_indices(indices));
    json.key("material").integer(doc.table.material(material.take()));
    json.key("mode").integer(kModeTriangles);
    json.end_object();
    ++primitives.count;
  }
  return {};
}

// The mesh (where it has primitives) and the node of one group of plants, added to `doc`;
// with `rig` (a group of one plant, plants[group.plants.front()]) the triangles are
// skinned to it instead (add_rig_nodes) and, with options.animation, sway in the clip;
// with options.lod the triangles are levels of detail NAME_LOD0 … NAME_LODN (children of
// the plant's node, or skinned scene roots with a rig).
Status add_plant_group(GltfDocument& doc, const std::vector<GltfPlant>& plants, const PlantGroup& group,
                       const GltfExportOptions& options, const Rig* rig) {
  const size_t plant_index = group.plants.front();
  const GltfPlant& plant = plants[plant_index];
  const Skeleton& sk = plant.skeleton;
  const SkinOptions skin_options = options.skin.styled(plant.skin);
  const SkinnedSkeleton skinned = skin_skeleton(sk, skin_options);
  const bool fillets = skin_options.blend_crotches;  // the crotches' fillets, on the full mesh only
  const std::optional<PlantRig> plant_rig = rig ? std::optional<PlantRig>(PlantRig{*rig, sk}) : std::nullopt;
  const PlantRig* weights = plant_rig ? &*plant_rig : nullptr;
  const std::optional<WindSource> wind_source =
      options.wind_data ? std::optional<WindSource>(WindSource{
                              sk, chain_orders(sk),
                              plant_sway_parameters(SwayParameters{.seed = options.wind_seed}, plant_index).seed})
                        : std::nullopt;
  const WindSource* wind = wind_source ? &*wind_source : nullptr;

  MeshPrimitives primitives;  // the plant node's mesh
  primitives.json.begin_array();
  if (sk.segment_count() > 0) add_skeleton_lines(sk, doc.buffer, primitives);
  // The surfaces drawn by nodes of their own: the skinned mesh, or the levels of detail.
  std::vector<std::pair<std::string, MeshPrimitives>> surfaces;
  if (options.mesh && options.lod > 0) {
    const std::vector<Skeleton> coarse_levels = lod_skeletons(sk, options.lod - 1, options.segments_around, skin_options);
    for (uint32_t level = 0; level <= options.lod; ++level) {
      MeshPrimitives& level_primitives =
          surfaces.emplace_back(plant.name + "_LOD" + std::to_string(level), MeshPrimitives{}).second;
      level_primitives.json.begin_array();
      if (level == options.lod) {
        if (Status added = add_impostor_cards(plant, plant_index, options, weights, wind, doc, level_primitives);
            !added)
          return added;
      } else if (level == 0) {
        if (Status added = add_surface(sk, skinned, fillets, plant.bark, options, weights, wind, doc, level_primitives);
            !added)
          return added;
      } else {
        GltfExportOptions level_options = options;
        level_options.segments_around = lod_columns(options.segments_around, level);
        const Skeleton& coarse = coarse_levels[level - 1];
        if (Status added = add_surface(coarse, skin_skeleton(coarse, skin_options), false, plant.bark, level_options,
                                       weights, wind, doc, level_primitives);
            !added)
          return added;
      }
      level_primitives.json.end_array();
    }
  } else if (rig) {
    MeshPrimitives& skinned_primitives = surfaces.emplace_back(plant.name + "_skin", MeshPrimitives{}).second;
    skinned_primitives.json.begin_array();
    if (Status added = add_surface(sk, skinned, fillets, plant.bark, options, weights, wind, doc, skinned_primitives);
        !added)
      return added;
    skinned_primitives.json.end_array();
  } else {
    if (Status added = add_surface(sk, skinned, fillets, plant.bark, options, weights, wind, doc, primitives); !added)
      return added;
  }
  primitives.json.end_array();

  const size_t plant_node = doc.nodes.size();
  JsonWriter node;
  node.begin_object();
  node.key("name").string(plant.name);
  if (rig) {
    node.key("children").begin_array().integer(plant_node + 1).end_array();
  } else if (!surfaces.empty()) {  // the levels of detail, placed with the plant
    node.key("children").begin_array();
    for (size_t i = 0; i < surfaces.size(); ++i) node.integer(plant_node + 1 + i);
    node.end_array();
  }
  if (primitives.count > 0) {
    JsonWriter mesh;
    mesh.begin_object();
    mesh.key("name").string(plant.name);
    mesh.key("primitives").raw(primitives.json.text());
    mesh.end_object();
    doc.meshes.push_back(mesh.take());
    node.key("mesh").integer(doc.meshes.size() - 1);
  }
  if (group.plants.size() > 1) {
    write_instancing(node, plants, group, doc.buffer);
    doc.any_instancing = true;
  } else {
    write_placement(node, plant);
  }
  write_node_extras(node, plants, group, skinned, options.extras, doc.buffer);
  node.end_object();
  doc.roots.push_back(plant_node);
  doc.nodes.push_back(node.take());
  if (rig) {
    add_rig_nodes(doc, plant, *rig, surfaces);
    if (options.animation) {
      SwayParameters sway = plant_sway_parameters(options.animation->sway, plant_index);
      sway.loop_period_s = options.animation->duration_s;
      add_clip_channels(doc, sk, *rig, plant_node + 1, *options.animation, sway);
    }
  } else {
    for (size_t i = 0; i < surfaces.size(); ++i) {
      const auto& [name, level_primitives] = surfaces[i];
      JsonWriter child;
      child.begin_object();
      if (level_primitives.count > 0) {
        JsonWriter mesh;
        mesh.begin_object().key("name").string(name).key("primitives").raw(level_primitives.json.text()).end_object();
        doc.meshes.push_back(mesh.take());
        child.key("mesh").integer(doc.meshes.size() - 1);
      }
      child.key("name").string(name);
      if (group.plants.size() > 1) write_instancing(child, plants, group, doc.buffer);
      child.end_object();
      doc.nodes.push_back(child.take());
    }
  }
  return {};
}

// Samplers, textures and images: texture i shows image i; one sampler: linear,
// mipmapped, repeating (the bark tiles). Images go into the buffer in a .glb, into data
// URIs in a .gltf.
void write_textures(JsonWriter& json, const MaterialTable& table, bool glb, BufferBuilder& buffer) {
  json.key("samplers").begin_array().begin_object();
  json.key("magFilter").integer(kFilterLinear).key("minFilter").integer(kFilterLinearMipmapLinear);
  json.key("wrapS").integer(kWrapRepeat).key("wrapT").integer(kWrapRepeat);
  json.end_object().end_array();
  json.key("textures").begin_array();
  for (size_t i = 0; i < table.images().size(); ++i)
    json.begin_object().key("sampler").integer(0).key("source").integer(i).end_object();
  json.end_array();
  json.key("images").begin_array();
  for (const EmbeddedImage& image : table.images()) {
    json.begin_object();
    if (glb)
      json.key("bufferView").integer(buffer.add_bytes(image.bytes)).key("mimeType").string(image.mime);
    else
      json.key("uri").string("data:" + std::string(image.mime) + ";base64," + base64(image.bytes));
    json.end_object();
  }
  json.end_array();
}

// The buffer layout (see the top of this file): accessors, bufferViews and the one
// buffer, in a .gltf as a data URI.
void write_buffer_layout(JsonWriter& json, const BufferBuilder& buffer, bool glb) {
  const std::string& bin = buffer.bytes();
  if (!buffer.accessors().empty()) {
    json.key("accessors").begin_array();
    for (const Accessor& a : buffer.accessors()) {
      json.begin_object();
      json.key("bufferView").integer(a.view).key("componentType").integer(a.component).key("count").integer(a.count);
      if (a.normalized) json.key("normalized").boolean(true);
      json.key("type").string(a.type);
      if (!a.min.empty()) {
        json.key("min").numbers(a.min.data(), a.min.size());
        json.key("max").numbers(a.max.data(), a.max.size());
      }
      json.end_object();
    }
    json.end_array();
  }
  if (!buffer.views().empty()) {  // extras "compact" may have views without accessors
    json.key("bufferViews").begin_array();
    for (const BufferView& v : buffer.views()) {
      json.begin_object();
      json.key("buffer").integer(v.compressed ? 1 : 0).key("byteOffset").integer(v.offset);
      json.key("byteLength").integer(v.length);
      if (v.target) json.key("target").integer(v.target);
      if (v.compressed) {
        static constexpr const char* kMode[] = {"", "ATTRIBUTES", "TRIANGLES", "INDICES"};
        json.key("extensions").begin_object().key("EXT_meshopt_compression").begin_object();
        json.key("buffer").integer(0).key("byteOffset").integer(v.encoded_offset);
        json.key("byteLength").integer(v.encoded_length).key("byteStride").integer(v.stride);
        json.key("count").integer(v.length / v.stride).key("mode").string(kMode[static_cast<int>(v.meshopt)]);
        json.end_object().end_object();
      }
      json.end_object();
    }
    json.end_array();
    json.key("buffers").begin_array().begin_object().key("byteLength").integer(bin.size());
    if (!glb) json.key("uri").string("data:application/octet-stream;base64," + base64(bin));
    json.end_object();
    if (buffer.fallback_length() > 0) {  // the encoded views' plain bytes: not in the file
      json.begin_object().key("byteLength").integer(buffer.fallback_length());
      json.key("extensions").begin_object().key("EXT_meshopt_compression").begin_object();
      json.key("fallback").boolean(true).end_object().end_object();
      json.end_object();
    }
    json.end_array();
  }
}

// The glTF JSON document of `doc`, with its newline. Arrays that would be empty are left
// out (glTF forbids empty arrays). In a .glb the images are appended to the buffer here.
std::string document_json(GltfDocument& doc, bool glb) {
  JsonWriter json;
  json.begin_object();
  json.key("asset").begin_object().key("version").string("2.0").key("generator").string("sylva").end_object();
  // The instances' placements exist only in the extension (the node has no fallback
  // transform per instance): a viewer without it would show one plant at the origin, so
  // the extension is required, not merely used (glTF 2.0 sec. 3.12).
  std::vector<const char*> required;
  if (doc.any_instancing) required.push_back("EXT_mesh_gpu_instancing");
  // Compressed views have no plain bytes in the file: a reader must decode them.
  const bool meshopt = doc.compress_meshopt && doc.buffer.has_meshopt_views();
  if (meshopt) required.push_back("EXT_meshopt_compression");
  if (!required.empty()) {
    json.key("extensionsUsed").begin_array();
    for (const char* e : required) json.string(e);
    json.end_array();
    json.key("extensionsRequired").begin_array();
    for (const char* e : required) json.string(e);
    json.end_array();
  }
  json.key("scene").integer(0);
  json.key("scenes").begin_array().begin_object().key("nodes").begin_array();
  for (size_t i : doc.roots) json.integer(i);
  json.end_array().end_object().end_array();
  json.key("nodes").begin_array();
  for (const std::string& node : doc.nodes) json.raw(node);
  json.end_array();
  if (!doc.meshes.empty()) {
    json.key("meshes").begin_array();
    for (const std::string& mesh : doc.meshes) json.raw(mesh);
    json.end_array();
  }
  if (!doc.skins.empty()) {
    json.key("skins").begin_array();
    for (const std::string& skin : doc.skins) json.raw(skin);
    json.end_array();
  }
  if (!doc.clip_channels.empty()) {
    json.key("animations").begin_array().begin_object();
    json.key("channels").begin_array();
    for (const std::string& channel : doc.clip_channels) json.raw(channel);
    json.end_array();
    json.key("name").string("wind");
    json.key("samplers").begin_array();
    for (const std::string& sampler : doc.clip_samplers) json.raw(sampler);
    json.end_array();
    json.end_object().end_array();
  }
  if (!doc.table.materials().empty()) {
    json.key("materials").begin_array();
    for (const std::string& material : doc.table.materials()) json.raw(material);
    json.end_array();
  }
  if (!doc.table.images().empty()) write_textures(json, doc.table, glb, doc.buffer);
  if (meshopt) doc.buffer.compress_meshopt();
  write_buffer_layout(json, doc.buffer, glb);
  json.end_object();
  return json.take() + "\n";
}

// The GLB container (glTF 2.0 sec. 4.4): header, the JSON chunk padded with spaces, the
// binary chunk (if any) padded with zeros.
Expected<std::string> glb_file(const std::string& text, const std::string& bin, const std::string& path) {
  std::string json_chunk = text;
  while (json_chunk.size() % 4 != 0) json_chunk += ' ';
  std::string bin_chunk = bin;
  while (bin_chunk.size() % 4 != 0) bin_chunk += '\0';
  const size_t total = 12 + 8 + json_chunk.size() + (bin_chunk.empty() ? 0 : 8 + bin_chunk.size());
  if (total > std::numeric_limits<uint32_t>::max())
    return file_diagnostic(path, "the model exceeds the 4 GiB of a GLB file");
  std::string file;
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
  return file;
}

}  // namespace

uint64_t wind_clip_intervals(const GltfWindClip& clip) {
  return std::max<uint64_t>(1, static_cast<uint64_t>(std::ceil(clip.duration_s * clip.fps - 1e-9)));
}

std::optional<std::string> wind_clip_problem(const GltfWindClip& clip) {
  if (!(clip.duration_s > 0 && clip.duration_s <= 1e6))
    return "the wind clip's duration must be a number of seconds in (0, 1e6]";
  if (!(clip.fps > 0 && clip.fps <= 1000)) return "the wind clip's fps must be a number in (0, 1000]";
  if (clip.duration_s * clip.fps > static_cast<double>(kMaxWindClipKeys))
    return "the wind clip would have more than " + std::to_string(kMaxWindClipKeys) +
           " keys (duration_s x fps): shorten it or lower fps";
  return std::nullopt;
}

Status check_bark_textures(const Bark& bark) {
  if (bark.albedo_texture) {
    Expected<EmbeddedImage> image = read_albedo_image(*bark.albedo_texture);
    if (!image) return std::move(image.error());
  }
  if (bark.height_texture) {
    Expected<HeightMap> map = read_height_map(*bark.height_texture);
    if (!map) return std::move(map.error());
  }
  return {};
}

double bark_reference_radius_m(const Skeleton& skeleton, SkinStyle skin) {
  return median_segment_radius(skin_skeleton(skeleton, SkinOptions{}.styled(skin)));
}

Status export_gltf(const std::vector<GltfPlant>& plants, const std::string& path, const GltfExportOptions& options) {
  const std::string ext = lower_case(path);
  const bool glb = ext.ends_with(".glb");
  if (!glb && !ext.ends_with(".gltf")) return file_diagnostic(path, "the output must end in .gltf or .glb");
  if (plants.empty()) return file_diagnostic(path, "no plants to export");
  if (options.segments_around < 3 || options.segments_around > 4096)
    return file_diagnostic(path, "segments around must be an integer from 3 to 4096");
  for (size_t i = 0; i < plants.size(); ++i)
    if (auto problem = plant_problem(plants[i], i)) return file_diagnostic(path, *problem);
  if (options.rig && !options.mesh) return file_diagnostic(path, "a rig skins the mesh: export the mesh too");
  if (options.rig && options.instancing)
    return file_diagnostic(path, "a rig cannot be instanced (EXT_mesh_gpu_instancing does not skin): export one or "
                                 "the other");
  if (options.rig && (options.max_joints < 1 || options.max_joints > kMaxRigJoints))
    return file_diagnostic(path, "the rig's joints must be from 1 to " + std::to_string(kMaxRigJoints));
  if (options.animation && !options.rig) return file_diagnostic(path, "the wind clip poses the rig: export the rig too");
  if (options.wind_data && !options.mesh) return file_diagnostic(path, "wind data is per mesh vertex: export the mesh too");
  if (options.lod > kMaxLodLevels)
    return file_diagnostic(path, "levels of detail must be from 1 to " + std::to_string(kMaxLodLevels));
  if (options.lod > 0 && !options.mesh) return file_diagnostic(path, "levels of detail re-mesh the plant: export the mesh too");
  if (options.lod > 0 && !options.card_renderer)
    return file_diagnostic(path, "levels of detail end in impostor cards: give a card renderer");
  if (options.lod > 0 && (options.card_pixels < 8 || options.card_pixels > 4096))
    return file_diagnostic(path, "impostor cards must be 8 to 4096 pixels tall");
  if (options.animation)
    if (auto problem = wind_clip_problem(*options.animation)) return file_diagnostic(path, *problem);
  // The rigs first: a plant that cannot be rigged writes nothing.
  std::vector<Rig> rigs;
  if (options.rig)
    for (size_t i = 0; i < plants.size(); ++i) {
      Expected<Rig> rig = build_rig(plants[i].skeleton, {.max_joints = options.max_joints});
      if (!rig)
        return file_diagnostic(path, "plant " + std::to_string(i) + " (" + json_excerpt(plants[i].name) +
                                         "): " + rig.error().message);
      rigs.push_back(std::move(*rig));
    }
  GltfDocument doc;
  doc.compress_meshopt = options.compress == GltfCompression::meshopt;
  if (options.mesh)
    if (Status loaded = doc.table.load(plants, options.materials); !loaded) return loaded;
  for (const PlantGroup& group : group_plants(plants, options))
    if (Status added = add_plant_group(doc, plants, group, options, options.rig ? &rigs[group.plants.front()] : nullptr);
        !added)
      return added;
  if (options.animation && doc.clip_channels.empty())
    return file_diagnostic(path, "the wind clip moves no joint (the wind has no horizontal part, both amplitudes "
                                 "are 0, or the rig's only joints sit at the base, where the sway does not turn: "
                                 "allow more joints): nothing to animate");
  const std::string text = document_json(doc, glb);
  if (!glb) return write_file_atomically(path, text);
  Expected<std::string> file = glb_file(text, doc.buffer.bytes(), path);
  if (!file) return std::move(file.error());
  return write_file_atomically(path, *file);
}

}  // namespace sylva
