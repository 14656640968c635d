// gltf_reader.cpp — sylva's skeletons read back from a glTF 2.0 file (core/io/gltf.h).
//
// json.h's reader: strict, located, depth-limited. Only the JSON is read and, for
// "compact" extras, the bufferViews they name, and for a plant's look its materials'
// embedded images (bytes, not decoded); vertices are never read and no URI other than a
// data URI is ever resolved. Every count and index is checked before use.
#include "core/io/gltf.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <string_view>
#include <utility>

#include "core/io/gltf_format.h"
#include "core/util/file_io.h"
#include "core/util/json.h"

namespace sylva {

namespace {

using namespace gltf_format;

// An error at value `v` of the file at `path`.
Diagnostic error_at(const std::string& path, const JsonValue& v, std::string message) {
  return diagnostic_at(path, {v.line, v.column}, std::move(message));
}

// Writes a DOM value back as JSON text (numbers by their exact source text).
void write_value(JsonWriter& w, const JsonValue& v) {
  switch (v.kind) {
    case JsonValue::Kind::Null: w.null(); break;
    case JsonValue::Kind::Bool: w.boolean(v.boolean); break;
    case JsonValue::Kind::Number: w.raw(v.text); break;
    case JsonValue::Kind::String: w.string(v.text); break;
    case JsonValue::Kind::Array:
      w.begin_array();
      for (const JsonValue& element : v.elements) write_value(w, element);
      w.end_array();
      break;
    case JsonValue::Kind::Object:
      w.begin_object();
      for (const JsonMember& member : v.members) write_value(w.key(member.key.name), member.value);
      w.end_object();
      break;
  }
}

// The JSON text of a .gltf, or the JSON chunk of a .glb (checked against the file size).
Expected<std::string_view> json_text_of(const std::string& path, const std::string& bytes) {
  auto u32_at = [&](size_t offset) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + offset, 4);
    return v;
  };
  if (bytes.size() >= 4 && u32_at(0) == kGlbMagic) {
    if (bytes.size() < 20)
      return file_diagnostic(path, "truncated GLB file: " + std::to_string(bytes.size()) + " bytes, less than a header");
    if (u32_at(4) != 2)
      return file_diagnostic(path, "GLB version " + std::to_string(u32_at(4)) + " is not supported (only 2)");
    if (u32_at(8) != bytes.size())
      return file_diagnostic(path, "GLB header says " + std::to_string(u32_at(8)) + " bytes but the file has " +
                                       std::to_string(bytes.size()) + " (truncated or corrupt)");
    const uint64_t json_length = u32_at(12);
    if (u32_at(16) != kGlbChunkJson) return file_diagnostic(path, "the first GLB chunk is not JSON");
    if (20 + json_length > bytes.size())
      return file_diagnostic(path, "the GLB JSON chunk (" + std::to_string(json_length) +
                                       " bytes) runs past the end of the file");
    return std::string_view(bytes).substr(20, json_length);
  }
  size_t i = 0;
  if (bytes.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;
  while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\n' || bytes[i] == '\r')) ++i;
  if (i == bytes.size() || bytes[i] != '{')
    return file_diagnostic(path, "not a glTF file (neither GLB nor a JSON object)");
  return std::string_view(bytes);
}

// Strict base64 (RFC 4648, padding required): nullopt for anything else.
std::optional<std::string> decode_base64(std::string_view text) {
  if (text.size() % 4 != 0) return std::nullopt;
  auto digit = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (size_t i = 0; i < text.size(); i += 4) {
    const bool last = i + 4 == text.size();
    const size_t pad = last ? (text[i + 3] == '=') + (text[i + 2] == '=' && text[i + 3] == '=') : 0;
    uint32_t v = 0;
    for (size_t k = 0; k < 4; ++k) {
      const int d = k >= 4 - pad ? 0 : digit(text[i + k]);
      if (d < 0) return std::nullopt;
      v = v << 6 | static_cast<uint32_t>(d);
    }
    out.push_back(static_cast<char>(v >> 16));
    if (pad < 2) out.push_back(static_cast<char>(v >> 8 & 0xFF));
    if (pad < 1) out.push_back(static_cast<char>(v & 0xFF));
  }
  return out;
}

// Buffer 0 of a glTF file and its bufferViews, for extras "compact" (gltf_export.h):
// loaded on first use, every index, offset and length checked before a value is copied.
class BinaryViews {
 public:
  BinaryViews(const std::string& path, const std::string& bytes, const JsonValue& root)
      : path_(path), bytes_(bytes), root_(root) {}

  // The `elements` values of type T in the bufferView whose index is `index` (a JSON
  // value of extras.sylva); `where` names that key in messages.
  template <class T>
  Expected<std::vector<T>> read(const JsonValue& index, uint64_t elements, const std::string& where) {
    if (Status loaded = load(index); !loaded) return std::move(loaded.error());
    const std::optional<uint64_t> i = index.as_uint64();
    const JsonValue* views = root_.find("bufferViews");
    const size_t view_count = views && views->is_array() ? views->elements.size() : 0;
    if (!i || *i >= view_count)
      return error_at(path_, index, where + " must be the index of one of the file's " + std::to_string(view_count) +
                                        " bufferViews, got " + json_excerpt(index.is_number() || index.is_string()
                                                                                ? index.text
                                                                                : std::string(index.kind_name())));
    const JsonValue& view = views->elements[*i];
    const std::string vwhere = where + ": bufferView " + std::to_string(*i);
    if (!view.is_object()) return error_at(path_, view, vwhere + " is " + view.kind_name() + ", expected an object");
    const JsonValue* buffer = view.find("buffer");
    if (!buffer || buffer->as_uint64() != uint64_t{0})
      return error_at(path_, view, vwhere + " must be in buffer 0 (the one sylva writes)");
    if (view.find("byteStride")) return error_at(path_, view, vwhere + " must be tightly packed (no byteStride)");
    const JsonValue* offset_value = view.find("byteOffset");
    const JsonValue* length_value = view.find("byteLength");
    const std::optional<uint64_t> offset = offset_value ? offset_value->as_uint64() : uint64_t{0};
    const std::optional<uint64_t> length = length_value ? length_value->as_uint64() : std::nullopt;
    if (!offset || !length)
      return error_at(path_, view, vwhere + " needs a byteLength and an optional byteOffset, non-negative integers");
    if (*offset > data_.size() || *length > data_.size() - *offset)
      return error_at(path_, view, vwhere + " (byteOffset " + std::to_string(*offset) + ", byteLength " +
                                       std::to_string(*length) + ") runs past the end of buffer 0 (" +
                                       std::to_string(data_.size()) + " bytes)");
    if (*length % sizeof(T) != 0 || *length / sizeof(T) != elements)
      return error_at(path_, view, vwhere + " holds " + std::to_string(*length) + " bytes; expected " +
                                       std::to_string(elements) + " values of " + std::to_string(sizeof(T)) +
                                       " bytes (the counts in extras.sylva)");
    std::vector<T> values(static_cast<size_t>(elements));
    if (elements) std::memcpy(values.data(), data_.data() + *offset, static_cast<size_t>(*length));
    return values;
  }

 private:
  // Buffer 0's bytes: the GLB's BIN chunk or a .gltf's base64 data URI.
  Status load(const JsonValue& at) {
    if (loaded_) return {};
    const JsonValue* buffers = root_.find("buffers");
    const JsonValue* buffer = buffers && buffers->is_array() && !buffers->elements.empty() ? &buffers->elements[0] : nullptr;
    if (!buffer || !buffer->is_object())
      return error_at(path_, buffers ? *buffers : at, "extras.sylva refers to bufferViews but the file has no buffer 0");
    const JsonValue* length_value = buffer->find("byteLength");
    const std::optional<uint64_t> length = length_value ? length_value->as_uint64() : std::nullopt;
    if (!length) return error_at(path_, *buffer, "buffer 0 needs a byteLength, a non-negative integer");
    std::string_view data;
    uint32_t magic = 0;
    if (bytes_.size() >= 4) std::memcpy(&magic, bytes_.data(), 4);
    if (magic == kGlbMagic) {
      // json_text_of checked the header and the JSON chunk; the BIN chunk follows it.
      uint32_t json_length = 0, bin_length = 0, bin_type = 0;
      std::memcpy(&json_length, bytes_.data() + 12, 4);
      const uint64_t bin_header = 20 + uint64_t{json_length};
      if (bin_header + 8 > bytes_.size())
        return file_diagnostic(path_, "extras.sylva refers to bufferViews but the GLB file has no BIN chunk");
      std::memcpy(&bin_length, bytes_.data() + bin_header, 4);
      std::memcpy(&bin_type, bytes_.data() + bin_header + 4, 4);
      if (bin_type != kGlbChunkBin) return file_diagnostic(path_, "the second GLB chunk is not BIN");
      if (bin_header + 8 + bin_length > bytes_.size())
        return file_diagnostic(path_, "the GLB BIN chunk (" + std::to_string(bin_length) +
                                          " bytes) runs past the end of the file");
      data = std::string_view(bytes_).substr(static_cast<size_t>(bin_header + 8), bin_length);
    } else {
      const JsonValue* uri = buffer->find("uri");
      constexpr std::string_view kPrefix = "data:application/octet-stream;base64,";
      if (!uri || !uri->is_string() || uri->text.compare(0, kPrefix.size(), kPrefix) != 0)
        return error_at(path_, uri ? *uri : *buffer,
                        "buffer 0 must be embedded as a \"data:application/octet-stream;base64,\" URI "
                        "(sylva resolves no other URI)");
      std::optional<std::string> decoded = decode_base64(std::string_view(uri->text).substr(kPrefix.size()));
      if (!decoded) return error_at(path_, *uri, "buffer 0's data URI is not valid base64");
      decoded_ = std::move(*decoded);
      data = decoded_;
    }
    if (*length > data.size())
      return error_at(path_, *buffer, "buffer 0's byteLength " + std::to_string(*length) + " is more than its " +
                                          std::to_string(data.size()) + " bytes of data");
    data_ = data.substr(0, static_cast<size_t>(*length));
    loaded_ = true;
    return {};
  }

  const std::string& path_;
  const std::string& bytes_;
  const JsonValue& root_;
  bool loaded_ = false;
  std::string decoded_;
  std::string_view data_;
};

// The looks of the plants (GltfLook, gltf.h): the materials sylva wrote on the triangles
// drawn for a plant's node, their extras and embedded images. Each image is decoded from
// the file once and shared.
class LookReader {
 public:
  LookReader(const std::string& path, const JsonValue& root, BinaryViews& views)
      : path_(path), root_(root), views_(views) {}

  // The look of the plant whose extras sit on `node` (named `name`): none where no
  // triangles with a sylva material are drawn for it.
  Expected<std::optional<GltfLook>> look_of(const JsonValue& node, const std::string& name) {
    const JsonValue* mesh = mesh_of(node, name);
    if (!mesh) return std::optional<GltfLook>();
    const JsonValue* primitives = mesh->find("primitives");
    if (!primitives || !primitives->is_array()) return std::optional<GltfLook>();
    GltfLook look;
    bool any = false;
    std::map<uint32_t, GltfLook::Material> materials;
    for (const JsonValue& primitive : primitives->elements) {
      const JsonValue* index = primitive.is_object() ? primitive.find("material") : nullptr;
      if (!index) continue;
      Expected<const JsonValue*> material = element("materials", *index);
      if (!material) return std::move(material.error());
      const JsonValue* extras = (*material)->find("extras");
      const JsonValue* sylva = extras && extras->is_object() ? extras->find("sylva") : nullptr;
      const JsonValue* k_value = sylva && sylva->is_object() ? sylva->find("material_index") : nullptr;
      const std::optional<uint64_t> k = k_value ? k_value->as_uint64() : std::nullopt;
      if (!k || *k > UINT32_MAX) continue;
      any = true;
      const JsonValue* pbr = (*material)->find("pbrMetallicRoughness");
      const JsonValue* texture = pbr && pbr->is_object() ? pbr->find("baseColorTexture") : nullptr;
      std::optional<GltfLook::Image> image;
      if (texture && texture->is_object()) {
        Expected<std::optional<GltfLook::Image>> read = image_of(*texture);
        if (!read) return std::move(read.error());
        image = std::move(*read);
      }
      const std::optional<glm::dvec3> factor = pbr && pbr->is_object() ? rgb(pbr->find("baseColorFactor")) : std::nullopt;
      const JsonValue* leaf = sylva->find("leaf");
      const bool is_leaf = leaf && leaf->kind == JsonValue::Kind::Bool && leaf->boolean;
      if (*k == 0 && !is_leaf) {
        look.bark.u_repeat = positive(sylva->find("u_repeat")).value_or(1);
        look.bark.v_per_metre = positive(sylva->find("v_per_metre")).value_or(1);
        if (const JsonValue* depth = sylva->find("relief_depth_m"); depth && depth->is_number() && depth->number >= 0)
          look.bark.relief_depth_m = depth->number;
        look.bark.albedo_rgb = rgb(sylva->find("albedo"));
        if (const JsonValue* height = sylva->find("height"); height && height->is_string()) look.bark_height = height->text;
        look.bark_albedo = std::move(image);
        continue;
      }
      GltfLook::Material& m = materials[static_cast<uint32_t>(*k)];
      m.index = static_cast<uint32_t>(*k);
      if (image && (is_leaf || !m.image)) m.image = std::move(image);
      else if (!image && factor && !m.material.albedo_rgb) m.material.albedo_rgb = factor;
      if (const JsonValue* specular = sylva->find("specular"); specular && specular->is_number())
        m.material.specular = std::clamp(specular->number, 0.0, 1.0);
      if (is_leaf) {
        const JsonValue* two_sided = (*material)->find("doubleSided");
        m.material.two_sided = two_sided && two_sided->kind == JsonValue::Kind::Bool && two_sided->boolean;
      }
      if (const JsonValue* segment = sylva->find("segment_texture"); segment && segment->is_object())
        m.material.segment_repeat = SegmentRepeat{positive(segment->find("u_repeat")).value_or(1),
                                                  positive(segment->find("v_per_metre")).value_or(1)};
    }
    for (auto& [k, m] : materials) look.materials.push_back(std::move(m));
    return any ? std::optional<GltfLook>(std::move(look)) : std::nullopt;
  }

 private:
  // The mesh drawn for the node: its own, else that of the node NAME_LOD0 (levels of
  // detail) or NAME_skin (a rig) that the export adds.
  const JsonValue* mesh_of(const JsonValue& node, const std::string& name) {
    auto mesh_at = [&](const JsonValue& n) -> const JsonValue* {
      const JsonValue* index = n.find("mesh");
      if (!index) return nullptr;
      Expected<const JsonValue*> mesh = element("meshes", *index);
      return mesh ? *mesh : nullptr;
    };
    if (const JsonValue* own = mesh_at(node)) {
      const JsonValue* primitives = own->find("primitives");
      if (primitives && primitives->is_array())
        for (const JsonValue& p : primitives->elements)
          if (p.is_object() && p.find("material")) return own;  // not only the skeleton's lines
    }
    if (!named_) {  // the nodes by name, once
      named_.emplace();
      if (const JsonValue* nodes = root_.find("nodes"); nodes && nodes->is_array())
        for (const JsonValue& other : nodes->elements)
          if (const JsonValue* n = other.is_object() ? other.find("name") : nullptr; n && n->is_string())
            named_->emplace(n->text, &other);
    }
    for (const char* suffix : {"_LOD0", "_skin"})
      if (auto found = named_->find(name + suffix); found != named_->end())
        if (const JsonValue* mesh = mesh_at(*found->second)) return mesh;
    return nullptr;
  }

  // Element `index` of the top-level array `key`, or an error at the index.
  Expected<const JsonValue*> element(const char* key, const JsonValue& index) {
    const JsonValue* array = root_.find(key);
    const size_t count = array && array->is_array() ? array->elements.size() : 0;
    const std::optional<uint64_t> i = index.as_uint64();
    if (!i || *i >= count || !array->elements[*i].is_object())
      return error_at(path_, index, std::string("must be the index of one of the file's ") + std::to_string(count) +
                                        " " + key);
    return &array->elements[*i];
  }

  // The image a textureInfo ({"index": t}) shows: PNG or JPEG, embedded; none otherwise.
  Expected<std::optional<GltfLook::Image>> image_of(const JsonValue& info) {
    const JsonValue* t = info.find("index");
    if (!t) return std::optional<GltfLook::Image>();
    Expected<const JsonValue*> texture = element("textures", *t);
    if (!texture) return std::move(texture.error());
    const JsonValue* source = (*texture)->find("source");
    if (!source) return std::optional<GltfLook::Image>();
    Expected<const JsonValue*> image = element("images", *source);
    if (!image) return std::move(image.error());
    const uint64_t key = *source->as_uint64();
    if (auto found = images_.find(key); found != images_.end()) return std::optional<GltfLook::Image>(found->second);
    GltfLook::Image out;
    if (const JsonValue* uri = (*image)->find("uri"); uri && uri->is_string()) {
      for (const char* mime : {"image/png", "image/jpeg"}) {
        const std::string prefix = std::string("data:") + mime + ";base64,";
        if (uri->text.compare(0, prefix.size(), prefix) != 0) continue;
        std::optional<std::string> decoded = decode_base64(std::string_view(uri->text).substr(prefix.size()));
        if (!decoded) return error_at(path_, *uri, "an image's data URI is not valid base64");
        out = {mime, std::make_shared<const std::string>(std::move(*decoded))};
      }
    } else if (const JsonValue* view = (*image)->find("bufferView")) {
      const JsonValue* mime = (*image)->find("mimeType");
      if (!mime || !mime->is_string() || (mime->text != "image/png" && mime->text != "image/jpeg"))
        return std::optional<GltfLook::Image>();
      Expected<const JsonValue*> view_object = element("bufferViews", *view);
      if (!view_object) return std::move(view_object.error());
      const JsonValue* length = (*view_object)->find("byteLength");
      const std::optional<uint64_t> bytes = length ? length->as_uint64() : std::nullopt;
      if (!bytes) return error_at(path_, **view_object, "an image's bufferView needs a byteLength");
      Expected<std::vector<char>> read = views_.read<char>(*view, *bytes, "images[" + std::to_string(key) + "]");
      if (!read) return std::move(read.error());
      out = {mime->text, std::make_shared<const std::string>(read->begin(), read->end())};
    }
    if (!out.bytes) return std::optional<GltfLook::Image>();  // an external URI: never resolved
    images_.emplace(key, out);
    return std::optional<GltfLook::Image>(std::move(out));
  }

  static std::optional<glm::dvec3> rgb(const JsonValue* v) {
    if (!v || !v->is_array() || v->elements.size() < 3) return std::nullopt;
    glm::dvec3 c;
    for (int i = 0; i < 3; ++i) {
      if (!v->elements[i].is_number() || !(v->elements[i].number >= 0 && v->elements[i].number <= 1e6))
        return std::nullopt;
      c[i] = v->elements[i].number;
    }
    return c;
  }
  static std::optional<double> positive(const JsonValue* v) {
    return v && v->is_number() && v->number > 0 && v->number < 1e9 ? std::optional<double>(v->number) : std::nullopt;
  }

  const std::string& path_;
  const JsonValue& root_;
  BinaryViews& views_;
  std::map<uint64_t, GltfLook::Image> images_;
  std::optional<std::multimap<std::string, const JsonValue*>> named_;
};

// One plant's placement as extras.sylva.instances gives it.
struct Placement {
  std::string name;
  double position_m[3] = {0, 0, 0};
  double rotate_y_deg = 0;
  double scale = 1;
};

// A count of extras "compact": a non-negative integer that fits uint32.
Expected<uint32_t> compact_count(const std::string& path, const JsonValue& object, const std::string& where) {
  const JsonValue* count = object.find("count");
  const std::optional<uint64_t> n = count ? count->as_uint64() : std::nullopt;
  if (!n || *n > std::numeric_limits<uint32_t>::max())
    return error_at(path, count ? *count : object, where + ".count must be an integer from 0 to 4294967295");
  return static_cast<uint32_t>(*n);
}

// The bufferView `key` of `object` (a "compact" array of `elements` values). With
// `elements` 0 the key may be left out (what the writer does); a key that is there must
// name a view of exactly that size, so that data the counts leave out (a count of 0 over
// full views) is an error rather than a silently empty plant.
template <class T>
Expected<std::vector<T>> compact_array(BinaryViews& views, const std::string& path, const JsonValue& object,
                                       const char* key, uint64_t elements, const std::string& where) {
  const JsonValue* index = object.find(key);
  if (!index && elements == 0) return std::vector<T>();
  if (!index) return error_at(path, object, where + ": missing key \"" + key + "\" (a bufferView index)");
  return views.read<T>(*index, elements, where + "." + key);
}

std::optional<ChainParent> joint_ref(uint32_t chain, uint32_t joint) {
  if (chain == kNoIndex && joint == kNoIndex) return std::nullopt;
  return ChainParent{chain, joint};
}

// Extras "compact": the chains and leaves objects into `sk` (then validated).
Status read_compact_skeleton(const std::string& path, const JsonValue& sylva, const std::string& where,
                             BinaryViews& views, Skeleton* sk) {
  const JsonValue& chains = *sylva.find("chains");
  const std::string cwhere = where + ".chains";
  Expected<uint32_t> c = compact_count(path, chains, cwhere);
  if (!c) return std::move(c.error());
  auto counts = compact_array<uint32_t>(views, path, chains, "joint_count", *c, cwhere);
  if (!counts) return std::move(counts.error());
  auto parents = compact_array<uint32_t>(views, path, chains, "parent", 2 * uint64_t{*c}, cwhere);
  if (!parents) return std::move(parents.error());
  uint64_t joint_total = 0;
  for (uint32_t n : *counts) joint_total += n;
  if (joint_total > std::numeric_limits<uint32_t>::max())
    return error_at(path, chains, cwhere + ": more than 4294967295 joints");
  auto joints = compact_array<double>(views, path, chains, "joints", 4 * joint_total, cwhere);
  if (!joints) return std::move(joints.error());
  auto materials = compact_array<uint32_t>(views, path, chains, "material", joint_total, cwhere);
  if (!materials) return std::move(materials.error());
  sk->joints.resize(static_cast<size_t>(joint_total));
  for (size_t j = 0; j < sk->joints.size(); ++j) {
    const double* v = joints->data() + 4 * j;
    sk->joints[j] = Joint{{v[0], v[1], v[2]}, v[3], (*materials)[j]};
  }
  uint32_t first = 0;
  for (uint32_t k = 0; k < *c; ++k) {
    sk->chains.push_back({first, (*counts)[k], joint_ref((*parents)[2 * k], (*parents)[2 * k + 1])});
    first += (*counts)[k];
  }

  const JsonValue* leaves = sylva.find("leaves");
  const JsonValue* version = sylva.find("version");
  if (!leaves) return {};
  const std::string lwhere = where + ".leaves";
  if (!leaves->is_object())
    return error_at(path, *leaves, lwhere + " is " + leaves->kind_name() + ", expected an object (\"compact\")");
  if (!version || version->as_uint64() != uint64_t{2})
    return error_at(path, *leaves, lwhere + ": leaves need version 2 of the skeleton document");
  Expected<uint32_t> l = compact_count(path, *leaves, lwhere);
  if (!l) return std::move(l.error());
  auto vertex_counts = compact_array<uint32_t>(views, path, *leaves, "vertex_count", *l, lwhere);
  if (!vertex_counts) return std::move(vertex_counts.error());
  auto leaf_joints = compact_array<uint32_t>(views, path, *leaves, "joint", 2 * uint64_t{*l}, lwhere);
  if (!leaf_joints) return std::move(leaf_joints.error());
  auto leaf_materials = compact_array<uint32_t>(views, path, *leaves, "material", *l, lwhere);
  if (!leaf_materials) return std::move(leaf_materials.error());
  // Double-sided leaves' backs (docs/leaves.md), where the writer had any: one the same as
  // its front is none.
  std::optional<std::vector<uint32_t>> back_materials;
  if (leaves->find("back_material")) {
    auto backs = compact_array<uint32_t>(views, path, *leaves, "back_material", *l, lwhere);
    if (!backs) return std::move(backs.error());
    back_materials = std::move(*backs);
  }
  uint64_t vertex_total = 0;
  for (uint32_t n : *vertex_counts) vertex_total += n;
  auto vertices = compact_array<double>(views, path, *leaves, "vertices", 3 * vertex_total, lwhere);
  if (!vertices) return std::move(vertices.error());
  size_t next = 0;
  for (uint32_t k = 0; k < *l; ++k) {
    Leaf leaf;
    leaf.joint = joint_ref((*leaf_joints)[2 * k], (*leaf_joints)[2 * k + 1]);
    leaf.material = (*leaf_materials)[k];
    if (back_materials && (*back_materials)[k] != leaf.material) leaf.back_material = (*back_materials)[k];
    leaf.vertices_m.resize((*vertex_counts)[k]);
    for (auto& v : leaf.vertices_m) {
      for (double& x : v) x = (*vertices)[next++];
    }
    sk->leaves.push_back(std::move(leaf));
  }
  return {};
}

// Extras "compact": extras.sylva.instances into placements.
Status read_compact_instances(const std::string& path, const JsonValue& instances, const std::string& where,
                              BinaryViews& views, std::vector<Placement>* out) {
  Expected<uint32_t> k = compact_count(path, instances, where);
  if (!k) return std::move(k.error());
  if (*k == 0) return error_at(path, instances, where + ".count must be at least 1");
  const JsonValue* names = instances.find("names");
  if (!names || !names->is_array() || names->elements.size() != *k)
    return error_at(path, names ? *names : instances, where + ".names must be an array of " + std::to_string(*k) +
                                                          " strings (count)");
  auto placement = compact_array<double>(views, path, instances, "placement", 5 * uint64_t{*k}, where);
  if (!placement) return std::move(placement.error());
  for (uint32_t i = 0; i < *k; ++i) {
    const std::string iwhere = where + "[" + std::to_string(i) + "]";
    if (!names->elements[i].is_string()) return error_at(path, names->elements[i], iwhere + ".name must be a string");
    const double* v = placement->data() + 5 * i;
    for (int c = 0; c < 5; ++c)
      if (!std::isfinite(v[c])) return error_at(path, instances, iwhere + ": a placement value is not finite");
    if (!(v[4] > 0)) return error_at(path, instances, iwhere + ".scale must be > 0");
    Placement p;
    p.name = names->elements[i].text;
    std::copy(v, v + 3, p.position_m);
    p.rotate_y_deg = v[3];
    p.scale = v[4];
    out->push_back(std::move(p));
  }
  return {};
}

// One node's extras.sylva back into plants (one per instance), "full" or "compact".
Status read_sylva_extras(const std::string& path, const JsonValue& node, size_t node_index, const JsonValue& sylva,
                         BinaryViews& views, LookReader& looks, std::vector<GltfPlant>* plants) {
  const JsonValue* name_value = node.find("name");
  const std::string node_name = name_value && name_value->is_string() ? name_value->text : "";
  const std::string where = "node " + std::to_string(node_index) +
                            (node_name.empty() ? "" : " (" + json_excerpt(node_name) + ")") + " extras.sylva";
  if (!sylva.is_object()) return error_at(path, sylva, where + " is " + sylva.kind_name() + ", expected an object");

  // Rebuild the skeleton document (seed string back to an integer) and read it with the
  // skeleton reader, which checks every value. "compact": the header alone, then the
  // arrays from the bufferViews, checked by validate_skeleton.
  const JsonValue* chains_value = sylva.find("chains");
  const bool compact = chains_value && chains_value->is_object();
  JsonWriter text;
  text.begin_object();
  for (const char* key : {"format", "version", "source", "chains"}) {
    const JsonValue* v = sylva.find(key);
    if (!v) return error_at(path, sylva, where + ": missing key \"" + key + "\"");
    text.key(key);
    if (compact && std::string_view(key) == "chains") {
      text.begin_array().end_array();
      continue;
    }
    if (std::string_view(key) != "source") {
      write_value(text, *v);
      continue;
    }
    if (!v->is_object()) return error_at(path, *v, where + ".source is " + v->kind_name() + ", expected an object");
    text.begin_object();
    for (const JsonMember& member : v->members) {
      text.key(member.key.name);
      if (member.key.name == "seed") {
        const JsonValue& seed = member.value;
        bool digits = seed.is_string() && !seed.text.empty() && seed.text.size() <= 20;
        for (char c : seed.text) digits = digits && c >= '0' && c <= '9';
        if (!digits) return error_at(path, seed, where + ".source.seed must be a string of decimal digits (a 64-bit seed)");
        text.raw(seed.text);  // range checked by the skeleton reader
      } else {
        write_value(text, member.value);
      }
    }
    text.end_object();
  }
  if (const JsonValue* leaves = sylva.find("leaves"); leaves && !compact)
    write_value(text.key("leaves"), *leaves);  // version 2
  text.end_object();
  Expected<Skeleton> read = read_skeleton_json(text.text(), path);
  if (!read) return error_at(path, sylva, where + ": " + read.error().message);
  if (compact) {
    if (Status arrays = read_compact_skeleton(path, sylva, where, views, &*read); !arrays) return arrays;
    if (Status valid = validate_skeleton(*read); !valid) return error_at(path, sylva, where + ": " + valid.error().message);
  }

  // The skin its frusta were written with (files from before the key: smooth, the only one).
  SkinStyle skin = SkinStyle::smooth;
  if (const JsonValue* skinning = sylva.find("skinning"); skinning && skinning->is_object())
    if (const JsonValue* style = skinning->find("skin")) {
      const std::optional<SkinStyle> parsed = style->is_string() ? parse_skin_style(style->text) : std::nullopt;
      if (!parsed) return error_at(path, *style, where + ".skinning.skin must be \"smooth\" or \"paper\"");
      skin = *parsed;
    }

  const JsonValue* instances = sylva.find("instances");
  std::vector<Placement> placements;
  if (!instances) {
    placements.push_back({node_name});
  } else if (compact && instances->is_object()) {
    if (Status read_instances = read_compact_instances(path, *instances, where + ".instances", views, &placements);
        !read_instances)
      return read_instances;
  } else if (!instances->is_array() || instances->elements.empty()) {
    return error_at(path, *instances, where + ".instances must be a non-empty array");
  }
  const size_t copies = instances && instances->is_array() ? instances->elements.size() : placements.size();
  // Each instance is a copy of the skeleton: a few bytes of instance record must not
  // become gigabytes of joints (docs/limits.md "Inputs").
  uint64_t joints = 0;
  for (const GltfPlant& p : *plants) joints += p.skeleton.joints.size();
  const uint64_t more = uint64_t{read->joints.size()} * copies;
  if (joints + more > kMaxImportedJoints)
    return error_at(path, instances ? *instances : sylva,
                    where + ".instances: " + std::to_string(copies) + " copies of a skeleton of " +
                        std::to_string(read->joints.size()) + " joints would make the file's plants hold " +
                        std::to_string(joints + more) + " joints, more than the limit of " +
                        std::to_string(kMaxImportedJoints) + " for one glTF file");
  for (size_t k = 0; instances && instances->is_array() && k < instances->elements.size(); ++k) {
    const JsonValue& inst = instances->elements[k];
    const std::string iwhere = where + ".instances[" + std::to_string(k) + "]";
    if (!inst.is_object()) return error_at(path, inst, iwhere + " must be an object");
    Placement p;
    const JsonValue* name = inst.find("name");
    const JsonValue* position = inst.find("position_m");
    const JsonValue* rotate = inst.find("rotate_y_deg");
    const JsonValue* scale = inst.find("scale");
    if (!name || !name->is_string()) return error_at(path, inst, iwhere + ".name must be a string");
    p.name = name->text;
    if (!position || !position->is_array() || position->elements.size() != 3)
      return error_at(path, inst, iwhere + ".position_m must be an array of 3 numbers");
    for (size_t c = 0; c < 3; ++c) {
      if (!position->elements[c].is_number())
        return error_at(path, position->elements[c], iwhere + ".position_m must hold numbers");
      p.position_m[c] = position->elements[c].number;
    }
    if (!rotate || !rotate->is_number()) return error_at(path, inst, iwhere + ".rotate_y_deg must be a number");
    p.rotate_y_deg = rotate->number;
    if (!scale || !scale->is_number() || !(scale->number > 0))
      return error_at(path, inst, iwhere + ".scale must be a number > 0");
    p.scale = scale->number;
    placements.push_back(std::move(p));
  }
  Expected<std::optional<GltfLook>> look = looks.look_of(node, node_name);
  if (!look) return std::move(look.error());
  for (Placement& placement : placements) {
    GltfPlant p;
    p.look = *look;
    p.name = std::move(placement.name);
    p.skeleton = *read;
    std::copy(placement.position_m, placement.position_m + 3, p.position_m);
    p.rotate_y_deg = placement.rotate_y_deg;
    p.scale = placement.scale;
    p.skin = skin;
    plants->push_back(std::move(p));
  }
  return {};
}

}  // namespace

Expected<std::vector<GltfPlant>> import_gltf_skeletons(const std::string& path) {
  Expected<std::string> file = read_text_file(path);
  if (!file) return std::move(file.error());
  return parse_gltf_skeletons(*file, path);
}

Expected<std::vector<GltfPlant>> parse_gltf_skeletons(const std::string& bytes, const std::string& path) {
  Expected<std::string_view> json = json_text_of(path, bytes);
  if (!json) return std::move(json.error());
  Expected<JsonValue> parsed = parse_json(*json, path);
  if (!parsed) return std::move(parsed.error());
  const JsonValue& root = *parsed;
  if (!root.is_object()) return error_at(path, root, "a glTF document is a JSON object");
  const JsonValue* asset = root.find("asset");
  const JsonValue* version = asset && asset->is_object() ? asset->find("version") : nullptr;
  if (!version || !version->is_string() || version->text.rfind("2.", 0) != 0)
    return error_at(path, asset ? *asset : root, "not a glTF 2.0 file (asset.version \"2.x\" missing)");
  const JsonValue* nodes = root.find("nodes");
  if (nodes && !nodes->is_array())
    return error_at(path, *nodes, std::string("\"nodes\" is ") + nodes->kind_name() + ", expected an array");
  std::vector<GltfPlant> plants;
  BinaryViews views(path, bytes, root);
  LookReader looks(path, root, views);
  for (size_t n = 0; nodes && n < nodes->elements.size(); ++n) {
    const JsonValue& node = nodes->elements[n];
    if (!node.is_object()) continue;
    const JsonValue* extras = node.find("extras");
    const JsonValue* sylva = extras && extras->is_object() ? extras->find("sylva") : nullptr;
    if (!sylva) continue;
    if (Status read = read_sylva_extras(path, node, n, *sylva, views, looks, &plants); !read) return std::move(read.error());
  }
  if (plants.empty())
    return file_diagnostic(path, "no sylva skeleton in this glTF file (no node has extras.sylva; "
                                 "files written by 'sylva export' have one per plant unless written with "
                                 "--extras none)");
  return plants;
}

}  // namespace sylva
