// skeleton.cpp — the skeleton's invariants and its file format, sylva-skeleton versions 1
// and 2 (leaves) (docs/spec/skeleton.md).
//
// The reader checks the file against the schema value by value and reports the first
// problem at the place of the offending value, naming the chain and joint; anything it
// accepts also passes validate_skeleton, so later stages never re-check a file.
#include "core/geometry/skeleton.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>

#include "core/geometry/leaf_mesh.h"
#include "core/util/file_io.h"
#include "core/util/json.h"

namespace sylva {
namespace {

constexpr std::string_view kFormatName = "sylva-skeleton";
constexpr uint64_t kFormatVersion = 1;        // without leaves
constexpr uint64_t kLeavesFormatVersion = 2;  // with leaves
// Chain and joint indices are uint32 in memory, so are counts of chains and joints.
constexpr uint64_t kMaxCount = std::numeric_limits<uint32_t>::max();
constexpr const char* kJointFieldNames[5] = {"x", "y", "z", "radius", "material"};

// A double as a message shows it: shortest round-trip form, non-finite values by name.
std::string number_for_message(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "Infinity" : "-Infinity";
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  assert(error == std::errc());
  return std::string(buffer, end);
}

std::string chain_place(size_t chain) { return "chain " + std::to_string(chain); }

std::string joint_place(size_t chain, size_t joint) {
  return "chain " + std::to_string(chain) + ", joint " + std::to_string(joint);
}

std::string count_of(uint64_t count, const char* singular, const char* plural) {
  return std::to_string(count) + " " + (count == 1 ? singular : plural);
}

// What a JSON value is, for the "got ..." of a message.
std::string describe(const JsonValue& value) {
  switch (value.kind) {
    case JsonValue::Kind::Number: {
      std::string text = value.text.substr(0, 40) + (value.text.size() > 40 ? "..." : "");
      if (!std::isfinite(value.number) && value.text != "NaN" && value.text != "Infinity" &&
          value.text != "-Infinity") {
        text += " (out of range of a double)";
      }
      return text;
    }
    case JsonValue::Kind::String: return "the string " + json_excerpt(value.text);
    case JsonValue::Kind::Array:
      return "an array of " + count_of(value.elements.size(), "element", "elements");
    case JsonValue::Kind::Bool: return value.boolean ? "true" : "false";
    default: return value.kind_name();
  }
}

// `"a", "b" or "c"` for messages listing the keys an object may have.
std::string key_list(std::initializer_list<std::string_view> keys) {
  std::string out;
  size_t i = 0;
  for (const std::string_view key : keys) {
    if (i > 0) out += i + 1 == keys.size() ? " or " : ", ";
    append_json_string(out, key);
    ++i;
  }
  return out;
}

// Why a joint breaks the invariants, or nullopt if it does not.
std::optional<std::string> joint_problem(const Joint& joint) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(joint.position_m[axis])) {
      return std::string(kJointFieldNames[axis]) + " is " +
             number_for_message(joint.position_m[axis]) + "; positions must be finite";
    }
  }
  if (!std::isfinite(joint.radius_m)) {
    return "radius is " + number_for_message(joint.radius_m) + "; radii must be finite";
  }
  if (joint.radius_m < 0) {
    return "radius " + number_for_message(joint.radius_m) + " is negative; radii must be >= 0";
  }
  return std::nullopt;
}

std::string leaf_place(size_t leaf) { return "leaf " + std::to_string(leaf); }

// Why a leaf's joint is not one of the skeleton's, or nullopt.
std::optional<std::string> leaf_joint_problem(const Leaf& leaf, const Skeleton& skeleton) {
  if (!leaf.joint) return std::nullopt;
  if (leaf.joint->chain >= skeleton.chains.size())
    return "joint [" + std::to_string(leaf.joint->chain) + ", " + std::to_string(leaf.joint->joint) +
           "] refers to chain " + std::to_string(leaf.joint->chain) + " of " +
           count_of(skeleton.chains.size(), "chain", "chains");
  const uint32_t count = skeleton.chains[leaf.joint->chain].joint_count;
  if (leaf.joint->joint >= count)
    return "joint [" + std::to_string(leaf.joint->chain) + ", " + std::to_string(leaf.joint->joint) +
           "] is past the end of chain " + std::to_string(leaf.joint->chain) + " (" +
           count_of(count, "joint", "joints") + ")";
  return std::nullopt;
}

// Reads a parsed sylva-skeleton document; the first problem found stops it.
class SkeletonReader {
 public:
  explicit SkeletonReader(std::string_view file) : file_(file) {}

  Expected<Skeleton> read(std::string_view text);

 private:
  bool fail(uint32_t line, uint32_t column, std::string message) {
    error_ = diagnostic_at(file_, {line, column}, std::move(message));
    return false;
  }
  bool fail(const JsonValue& where, std::string message) {
    return fail(where.line, where.column, std::move(message));
  }

  // "<prefix>: <message>", or just the message at the top level.
  static std::string prefixed(std::string_view prefix, const std::string& message) {
    return prefix.empty() ? message : std::string(prefix) + ": " + message;
  }

  // Every key of `object` is one of `allowed`: a typo is an error, never ignored.
  bool check_keys(const JsonValue& object, std::initializer_list<std::string_view> allowed,
                  std::string_view prefix);
  // The member `key` of `object`; an error (located at the object) if it is absent.
  const JsonValue* require(const JsonValue& object, std::string_view key, std::string_view prefix);

  bool read_format_and_version(const JsonValue& root);
  bool read_source(const JsonValue& value, SkeletonSource& source);
  bool read_chains(const JsonValue& value, Skeleton& skeleton);
  bool read_chain(size_t index, const JsonValue& value, Skeleton& skeleton);
  bool read_parent(size_t index, const JsonValue& value, const Skeleton& skeleton, Chain& chain);
  bool read_joint(size_t chain, size_t index, const JsonValue& value, Joint& joint);
  bool read_leaves(const JsonValue& value, Skeleton& skeleton);
  bool read_leaf(size_t index, const JsonValue& value, const Skeleton& skeleton, Leaf& leaf);

  std::string file_;
  uint64_t version_ = kFormatVersion;
  std::optional<Diagnostic> error_;
};

Expected<Skeleton> SkeletonReader::read(std::string_view text) {
  // Non-finite numbers are let through the JSON layer so that the schema check below
  // can say which chain and joint holds them.
  JsonParseOptions options;
  options.allow_non_finite_numbers = true;
  Expected<JsonValue> parsed = parse_json(text, file_, options);
  if (!parsed) return std::move(parsed.error());
  const JsonValue& root = *parsed;
  Skeleton skeleton;
  const bool ok = [&] {
    if (!root.is_object()) {
      return fail(root, std::string("a skeleton file holds a JSON object, found ") + describe(root));
    }
    if (!read_format_and_version(root)) return false;
    if (version_ == kFormatVersion ? !check_keys(root, {"format", "version", "source", "chains"}, "")
                                   : !check_keys(root, {"format", "version", "source", "chains", "leaves"}, ""))
      return false;
    if (const JsonValue* source = root.find("source")) {
      if (!read_source(*source, skeleton.source)) return false;
    }
    const JsonValue* chains = require(root, "chains", "");
    if (chains == nullptr || !read_chains(*chains, skeleton)) return false;
    const JsonValue* leaves = root.find("leaves");
    return leaves == nullptr || read_leaves(*leaves, skeleton);
  }();
  if (!ok) return std::move(*error_);
  assert(validate_skeleton(skeleton).ok() && "the reader accepted a skeleton that breaks an invariant");
  return skeleton;
}

bool SkeletonReader::check_keys(const JsonValue& object,
                                std::initializer_list<std::string_view> allowed,
                                std::string_view prefix) {
  for (const JsonMember& member : object.members) {
    bool known = false;
    for (const std::string_view key : allowed) known = known || member.key.name == key;
    if (!known) {
      return fail(member.key.line, member.key.column,
                  prefixed(prefix, "unknown key " + json_excerpt(member.key.name) +
                                       (prefix.empty() ? " at the top level" : "") +
                                       "; expected " + key_list(allowed)));
    }
  }
  return true;
}

const JsonValue* SkeletonReader::require(const JsonValue& object, std::string_view key,
                                         std::string_view prefix) {
  const JsonValue* value = object.find(key);
  if (value == nullptr) {
    std::string quoted;
    append_json_string(quoted, key);
    fail(object, prefixed(prefix, "missing required key " + quoted));
  }
  return value;
}

// Format and version come first: a file of another kind should be named as such, not
// reported as a list of unknown keys.
bool SkeletonReader::read_format_and_version(const JsonValue& root) {
  const JsonValue* format = root.find("format");
  if (format != nullptr) {
    if (!format->is_string()) {
      return fail(*format, "format must be the string \"sylva-skeleton\", got " + describe(*format));
    }
    if (format->text != kFormatName) {
      return fail(*format, "unknown format " + json_excerpt(format->text) +
                               "; this reader reads \"sylva-skeleton\"");
    }
  }
  const JsonValue* version = root.find("version");
  if (version != nullptr) {
    const std::optional<uint64_t> number = version->as_uint64();
    if (!number) return fail(*version, "version must be an integer, got " + describe(*version));
    if (*number != kFormatVersion && *number != kLeavesFormatVersion) {
      return fail(*version, "unsupported version " + version->text + " of \"sylva-skeleton\"; " +
                                "this reader reads versions 1 and 2");
    }
    version_ = *number;
  }
  if (format == nullptr) {
    return fail(root, "missing required key \"format\" (a skeleton file starts with "
                      "\"format\": \"sylva-skeleton\")");
  }
  if (version == nullptr) {
    require(root, "version", "");  // records the error
    return false;
  }
  return true;
}

bool SkeletonReader::read_source(const JsonValue& value, SkeletonSource& source) {
  const char* prefix = "source";
  if (!value.is_object()) {
    return fail(value, "source must be an object {\"grammar\", \"seed\", \"steps\", \"defines\"}, got " +
                           describe(value));
  }
  if (!check_keys(value, {"grammar", "seed", "steps", "defines"}, prefix)) return false;
  const JsonValue* grammar = require(value, "grammar", prefix);
  const JsonValue* seed = grammar ? require(value, "seed", prefix) : nullptr;
  const JsonValue* steps = seed ? require(value, "steps", prefix) : nullptr;
  const JsonValue* defines = steps ? require(value, "defines", prefix) : nullptr;
  if (defines == nullptr) return false;

  if (!grammar->is_string()) {
    return fail(*grammar, "source: grammar must be a string, got " + describe(*grammar));
  }
  source.grammar = grammar->text;

  const std::optional<uint64_t> seed_value = seed->as_uint64();  // exact, never via double
  if (!seed_value) {
    return fail(*seed, "source: seed must be an integer from 0 to 18446744073709551615, got " +
                           describe(*seed));
  }
  source.seed = *seed_value;

  const std::optional<uint64_t> steps_value = steps->as_uint64();
  if (!steps_value || *steps_value > uint64_t{std::numeric_limits<int64_t>::max()}) {
    return fail(*steps, "source: steps must be an integer from 0 to 9223372036854775807, got " +
                            describe(*steps));
  }
  source.steps = static_cast<int64_t>(*steps_value);

  if (!defines->is_object()) {
    return fail(*defines, "source: defines must be an object of name: number, got " + describe(*defines));
  }
  for (const JsonMember& define : defines->members) {
    if (define.key.name.empty()) {
      return fail(define.key.line, define.key.column, "source: a define name must not be empty");
    }
    if (!define.value.is_number() || !std::isfinite(define.value.number)) {
      return fail(define.value, "source: define " + json_excerpt(define.key.name) +
                                    " must be a finite number, got " + describe(define.value));
    }
    source.defines.emplace(define.key.name, define.value.number);  // keys are unique
  }
  return true;
}

bool SkeletonReader::read_chains(const JsonValue& value, Skeleton& skeleton) {
  if (!value.is_array()) return fail(value, "chains must be an array, got " + describe(value));
  if (value.elements.size() > kMaxCount) {
    return fail(value, "too many chains; a skeleton holds at most 4294967295");
  }
  skeleton.chains.reserve(value.elements.size());
  for (size_t c = 0; c < value.elements.size(); ++c) {
    if (!read_chain(c, value.elements[c], skeleton)) return false;
  }
  return true;
}

bool SkeletonReader::read_chain(size_t index, const JsonValue& value, Skeleton& skeleton) {
  const std::string prefix = chain_place(index);
  if (!value.is_object()) {
    return fail(value, prefix + " must be an object {\"parent\": ..., \"joints\": [...]}, got " +
                           describe(value));
  }
  if (!check_keys(value, {"parent", "joints"}, prefix)) return false;
  const JsonValue* parent = require(value, "parent", prefix);
  const JsonValue* joints = parent ? require(value, "joints", prefix) : nullptr;
  if (joints == nullptr) return false;

  Chain chain{};
  if (!read_parent(index, *parent, skeleton, chain)) return false;

  if (!joints->is_array()) {
    return fail(*joints, prefix + ": joints must be an array of [x, y, z, radius, material], got " +
                             describe(*joints));
  }
  if (joints->elements.empty()) {
    return fail(*joints, prefix + " has no joints; a chain needs at least one");
  }
  if (skeleton.joints.size() + joints->elements.size() > kMaxCount) {
    return fail(*joints, prefix + ": too many joints; a skeleton holds at most 4294967295");
  }
  chain.first_joint = static_cast<uint32_t>(skeleton.joints.size());
  chain.joint_count = static_cast<uint32_t>(joints->elements.size());
  for (size_t j = 0; j < joints->elements.size(); ++j) {
    Joint joint{};
    if (!read_joint(index, j, joints->elements[j], joint)) return false;
    skeleton.joints.push_back(joint);
  }
  skeleton.chains.push_back(chain);
  return true;
}

bool SkeletonReader::read_parent(size_t index, const JsonValue& value, const Skeleton& skeleton,
                                 Chain& chain) {
  const std::string prefix = chain_place(index);
  if (value.is_null()) return true;  // a root chain
  if (!value.is_array() || value.elements.size() != 2) {
    return fail(value, prefix + ": parent must be null or [chain index, joint index], got " +
                           describe(value));
  }
  const JsonValue& chain_value = value.elements[0];
  const JsonValue& joint_value = value.elements[1];
  const std::optional<uint64_t> parent_chain = chain_value.as_uint64();
  if (!parent_chain || *parent_chain > kMaxCount) {
    return fail(chain_value, prefix + ": parent chain index must be an integer from 0 to " +
                                 "4294967295, got " + describe(chain_value));
  }
  const std::optional<uint64_t> parent_joint = joint_value.as_uint64();
  if (!parent_joint || *parent_joint > kMaxCount) {
    return fail(joint_value, prefix + ": parent joint index must be an integer from 0 to " +
                                 "4294967295, got " + describe(joint_value));
  }
  const std::string shown =
      "[" + std::to_string(*parent_chain) + ", " + std::to_string(*parent_joint) + "]";
  if (*parent_chain >= index) {
    return fail(chain_value, prefix + ": parent " + shown + " refers to chain " +
                                 std::to_string(*parent_chain) + ", which does not come before " +
                                 prefix + " (parents come before their children)");
  }
  const uint32_t parent_joint_count = skeleton.chains[*parent_chain].joint_count;
  if (*parent_joint >= parent_joint_count) {
    return fail(joint_value, prefix + ": parent " + shown + " refers to joint " +
                                 std::to_string(*parent_joint) + " of chain " +
                                 std::to_string(*parent_chain) + ", which has " +
                                 count_of(parent_joint_count, "joint", "joints"));
  }
  chain.parent = ChainParent{static_cast<uint32_t>(*parent_chain), static_cast<uint32_t>(*parent_joint)};
  return true;
}

bool SkeletonReader::read_joint(size_t chain, size_t index, const JsonValue& value, Joint& joint) {
  const std::string prefix = joint_place(chain, index);
  if (!value.is_array() || value.elements.size() != 5) {
    return fail(value, prefix + ": a joint must be an array of 5 numbers [x, y, z, radius, " +
                           "material], got " + describe(value));
  }
  double numbers[4];
  for (int k = 0; k < 4; ++k) {
    const JsonValue& element = value.elements[static_cast<size_t>(k)];
    const std::string name = kJointFieldNames[k];
    if (!element.is_number()) {
      return fail(element, prefix + ": " + name + " must be a number, got " + describe(element));
    }
    if (!std::isfinite(element.number)) {
      return fail(element, prefix + ": " + name + " must be a finite number, got " + describe(element));
    }
    numbers[k] = element.number;
  }
  if (numbers[3] < 0) {
    return fail(value.elements[3], prefix + ": radius " + value.elements[3].text +
                                       " is negative; radii must be >= 0");
  }
  const JsonValue& material = value.elements[4];
  const std::optional<uint64_t> material_index = material.as_uint64();
  if (!material_index || *material_index > kMaxCount) {
    return fail(material, prefix + ": material must be an integer from 0 to 4294967295, got " +
                              describe(material));
  }
  joint = Joint{{numbers[0], numbers[1], numbers[2]}, numbers[3], static_cast<uint32_t>(*material_index)};
  return true;
}

bool SkeletonReader::read_leaves(const JsonValue& value, Skeleton& skeleton) {
  if (!value.is_array()) return fail(value, "leaves must be an array, got " + describe(value));
  if (value.elements.size() > kMaxCount) return fail(value, "too many leaves; a skeleton holds at most 4294967295");
  skeleton.leaves.resize(value.elements.size());
  for (size_t i = 0; i < value.elements.size(); ++i)
    if (!read_leaf(i, value.elements[i], skeleton, skeleton.leaves[i])) return false;
  return true;
}

bool SkeletonReader::read_leaf(size_t index, const JsonValue& value, const Skeleton& skeleton, Leaf& leaf) {
  const std::string prefix = leaf_place(index);
  if (!value.is_object()) {
    return fail(value, prefix + " must be an object {\"joint\": ..., \"material\": ..., \"vertices\": [...]}, got " +
                           describe(value));
  }
  if (!check_keys(value, {"joint", "material", "back_material", "vertices"}, prefix)) return false;
  const JsonValue* joint = require(value, "joint", prefix);
  const JsonValue* material = joint ? require(value, "material", prefix) : nullptr;
  const JsonValue* vertices = material ? require(value, "vertices", prefix) : nullptr;
  if (vertices == nullptr) return false;
  if (!joint->is_null()) {
    const bool pair = joint->is_array() && joint->elements.size() == 2;
    const std::optional<uint64_t> c = pair ? joint->elements[0].as_uint64() : std::nullopt;
    const std::optional<uint64_t> j = pair ? joint->elements[1].as_uint64() : std::nullopt;
    if (!c || !j || *c > kMaxCount || *j > kMaxCount)
      return fail(*joint, prefix + ": joint must be null or [chain index, joint index], got " + describe(*joint));
    leaf.joint = ChainParent{static_cast<uint32_t>(*c), static_cast<uint32_t>(*j)};
    if (auto problem = leaf_joint_problem(leaf, skeleton)) return fail(*joint, prefix + ": " + *problem);
  }
  const std::optional<uint64_t> m = material->as_uint64();
  if (!m || *m > kMaxCount)
    return fail(*material, prefix + ": material must be an integer from 0 to 4294967295, got " + describe(*material));
  leaf.material = static_cast<uint32_t>(*m);
  if (const JsonValue* back = value.find("back_material")) {  // a double-sided leaf's (docs/leaves.md)
    const std::optional<uint64_t> b = back->as_uint64();
    if (!b || *b > kMaxCount)
      return fail(*back, prefix + ": back_material must be an integer from 0 to 4294967295, got " + describe(*back));
    leaf.back_material = static_cast<uint32_t>(*b);
  }
  if (!vertices->is_array())
    return fail(*vertices, prefix + ": vertices must be an array of [x, y, z], got " + describe(*vertices));
  for (size_t v = 0; v < vertices->elements.size(); ++v) {
    const JsonValue& e = vertices->elements[v];
    if (!e.is_array() || e.elements.size() != 3)
      return fail(e, prefix + ": vertex " + std::to_string(v) + " must be an array of 3 numbers [x, y, z], got " +
                         describe(e));
    std::array<double, 3> p{};
    for (size_t k = 0; k < 3; ++k) {
      if (!e.elements[k].is_number() || !std::isfinite(e.elements[k].number))
        return fail(e.elements[k], prefix + ": vertex " + std::to_string(v) + ": " + kJointFieldNames[k] +
                                       " must be a finite number, got " + describe(e.elements[k]));
      p[k] = e.elements[k].number;
    }
    leaf.vertices_m.push_back(p);
  }
  if (auto problem = leaf_polygon_problem(leaf.vertices_m)) return fail(*vertices, prefix + ": " + *problem);
  return true;
}

}  // namespace

std::optional<std::string> leaf_polygon_problem(std::span<const std::array<double, 3>> vertices) {
  for (size_t v = 0; v < vertices.size(); ++v)
    for (size_t k = 0; k < 3; ++k)
      if (!std::isfinite(vertices[v][k]))
        return "vertex " + std::to_string(v) + " is not finite; a leaf's vertices must be";
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, centroid[3] = {0, 0, 0};
  for (size_t k = 0; k < 3 && !vertices.empty(); ++k) lo[k] = hi[k] = vertices[0][k];
  for (const auto& p : vertices)
    for (size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
      centroid[k] += p[k] / static_cast<double>(vertices.size());
    }
  const double diagonal = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  // Distinct vertices: each closer than 1e-9 of the diagonal to an earlier one is the same.
  size_t distinct = 0;
  for (size_t v = 0; v < vertices.size() && distinct < 3; ++v) {
    bool seen = false;
    for (size_t u = 0; u < v && !seen; ++u)
      seen = std::hypot(vertices[v][0] - vertices[u][0], vertices[v][1] - vertices[u][1],
                        vertices[v][2] - vertices[u][2]) <= 1e-9 * diagonal;
    distinct += seen ? 0 : 1;
  }
  if (distinct < 3)
    return "a leaf needs at least 3 distinct vertices, this polygon has " + std::to_string(distinct) + " (" +
           count_of(vertices.size(), "vertex", "vertices") + ")";
  // Newell's normal: twice the vector area of the polygon, whatever its shape.
  const glm::dvec3 newell = polygon_newell_normal(vertices);
  const double n[3] = {newell.x, newell.y, newell.z};
  const double length = glm::length(newell);
  if (!(length > 1e-12 * diagonal * diagonal)) return "the polygon has no area (its vertices lie on one line)";
  double off = 0;
  size_t worst = 0;
  for (size_t v = 0; v < vertices.size(); ++v) {
    double d = 0;
    for (size_t k = 0; k < 3; ++k) d += (vertices[v][k] - centroid[k]) * n[k] / length;
    if (std::abs(d) > off) off = std::abs(d), worst = v;
  }
  if (off > kLeafMaxNonPlanarity * diagonal)
    return "the polygon is not planar: vertex " + std::to_string(worst) + " lies " + number_for_message(off) +
           " m off its plane, more than " + number_for_message(kLeafMaxNonPlanarity * 100) + " % of its size " +
           number_for_message(diagonal) + " m";
  return std::nullopt;
}

uint64_t Skeleton::segment_count() const {
  uint64_t segments = 0;
  for (const Chain& chain : chains) {
    if (chain.joint_count > 0) segments += chain.joint_count - 1;
  }
  return segments;
}

Status validate_skeleton(const Skeleton& skeleton) {
  auto error = [](std::string message) { return file_diagnostic("", std::move(message)); };
  if (skeleton.chains.size() > kMaxCount) {
    return error("too many chains (" + std::to_string(skeleton.chains.size()) + "); at most 4294967295");
  }
  if (skeleton.joints.size() > kMaxCount) {
    return error("too many joints (" + std::to_string(skeleton.joints.size()) + "); at most 4294967295");
  }

  uint64_t next_free_joint = 0;  // ranges must be disjoint and in chain order
  for (size_t c = 0; c < skeleton.chains.size(); ++c) {
    const Chain& chain = skeleton.chains[c];
    if (chain.joint_count == 0) return error(chain_place(c) + " has no joints; a chain needs at least one");
    const uint64_t end = uint64_t{chain.first_joint} + chain.joint_count;
    if (end > skeleton.joints.size()) {
      return error(chain_place(c) + ": joints " + std::to_string(chain.first_joint) + " to " +
                   std::to_string(end - 1) + " run past the end of the joint array (" +
                   count_of(skeleton.joints.size(), "joint", "joints") + ")");
    }
    if (chain.first_joint < next_free_joint) {
      return error(chain_place(c) + ": joints start at " + std::to_string(chain.first_joint) +
                   ", inside an earlier chain's range; ranges must be disjoint and in chain order");
    }
    next_free_joint = end;
    if (chain.parent) {
      const ChainParent& parent = *chain.parent;
      if (parent.chain >= c) {
        return error(chain_place(c) + ": parent chain " + std::to_string(parent.chain) +
                     " does not come before it (parents come before their children)");
      }
      const uint32_t parent_joint_count = skeleton.chains[parent.chain].joint_count;
      if (parent.joint >= parent_joint_count) {
        return error(chain_place(c) + ": parent joint " + std::to_string(parent.joint) +
                     " is past the end of chain " + std::to_string(parent.chain) + " (" +
                     count_of(parent_joint_count, "joint", "joints") + ")");
      }
    }
    for (uint32_t j = 0; j < chain.joint_count; ++j) {
      if (auto problem = joint_problem(skeleton.joints[chain.first_joint + j])) {
        return error(joint_place(c, j) + ": " + *problem);
      }
    }
  }

  // Joints between or after the chains' ranges belong to no chain; stages that scan the
  // flat array still see them, so they must be finite too.
  size_t next = 0;
  auto check_unowned = [&](size_t end) -> Status {
    for (; next < end; ++next) {
      if (auto problem = joint_problem(skeleton.joints[next])) {
        return error("joint " + std::to_string(next) + " (in no chain): " + *problem);
      }
    }
    return {};
  };
  for (const Chain& chain : skeleton.chains) {
    if (Status problem = check_unowned(chain.first_joint); !problem) return problem;
    next = chain.first_joint + size_t{chain.joint_count};
  }
  if (Status problem = check_unowned(skeleton.joints.size()); !problem) return problem;

  for (size_t l = 0; l < skeleton.leaves.size(); ++l) {
    if (auto problem = leaf_joint_problem(skeleton.leaves[l], skeleton)) return error(leaf_place(l) + ": " + *problem);
    if (auto problem = leaf_polygon_problem(skeleton.leaves[l].vertices_m))
      return error(leaf_place(l) + ": " + *problem);
  }

  if (skeleton.source.steps < 0) {
    return error("source: steps is " + std::to_string(skeleton.source.steps) + "; must be >= 0");
  }
  for (const auto& [name, value] : skeleton.source.defines) {
    if (name.empty()) return error("source: a define name must not be empty");
    if (!std::isfinite(value)) {
      return error("source: define " + json_excerpt(name) + " is " + number_for_message(value) +
                   "; defines must be finite");
    }
  }
  return {};
}

void write_skeleton_members(JsonWriter& w, const Skeleton& skeleton, const SkeletonJsonStyle& style) {
  assert(validate_skeleton(skeleton).ok() &&
         "write_skeleton_members: the skeleton breaks an invariant; see validate_skeleton");
  using Layout = JsonWriter::Layout;
  const Layout inline_layout = style.compact ? Layout::compact : Layout::spaced;
  const SkeletonSource& source = skeleton.source;
  w.key("format").string(kFormatName);
  w.key("version").integer(skeleton.leaves.empty() ? kFormatVersion : kLeavesFormatVersion);
  w.key("source").begin_object(inline_layout);
  w.key("grammar").string(source.grammar);
  if (style.seed_as_string) w.key("seed").string(std::to_string(source.seed));
  else w.key("seed").integer(source.seed);
  w.key("steps").integer(source.steps);
  w.key("defines").begin_object(inline_layout);
  for (const auto& [name, value] : source.defines) w.key(name).number(value);  // std::map: sorted by name
  w.end_object();
  w.end_object();
  if (style.header_only) return;
  // A chain's parent and a leaf's joint: [chain, joint] or null.
  auto write_joint_ref = [&w](const char* key, const std::optional<ChainParent>& ref) {
    w.key(key);
    if (ref) w.begin_array().integer(ref->chain).integer(ref->joint).end_array();
    else w.null();
  };
  // One chain per line in the file; its joints stay dense (they are most of the bytes).
  w.key("chains").begin_array(style.compact ? Layout::compact : Layout::lines);
  for (const Chain& chain : skeleton.chains) {
    w.begin_object(inline_layout);
    write_joint_ref("parent", chain.parent);
    w.key("joints").begin_array();
    for (uint32_t j = 0; j < chain.joint_count; ++j) {
      const Joint& joint = skeleton.joints[chain.first_joint + j];
      w.begin_array();
      for (const double coordinate : joint.position_m) w.number(coordinate);
      w.number(joint.radius_m).integer(joint.material).end_array();
    }
    w.end_array();
    w.end_object();
  }
  w.end_array();
  if (skeleton.leaves.empty()) return;  // version 1
  w.key("leaves").begin_array(style.compact ? Layout::compact : Layout::lines);
  for (const Leaf& leaf : skeleton.leaves) {
    w.begin_object(inline_layout);
    write_joint_ref("joint", leaf.joint);
    w.key("material").integer(leaf.material);
    if (leaf.back_material) w.key("back_material").integer(*leaf.back_material);
    w.key("vertices").begin_array();
    for (const auto& p : leaf.vertices_m) w.begin_array().number(p[0]).number(p[1]).number(p[2]).end_array();
    w.end_array();
    w.end_object();
  }
  w.end_array();
}

std::string write_skeleton_json(const Skeleton& skeleton) {
  JsonWriter w;
  w.begin_object(JsonWriter::Layout::lines);
  write_skeleton_members(w, skeleton);
  w.end_object();
  return w.take() + "\n";
}

Expected<Skeleton> read_skeleton_json(std::string_view text, std::string_view file) {
  return SkeletonReader(file).read(text);
}

Expected<Skeleton> read_skeleton_file(const std::string& path) {
  Expected<std::string> file = read_text_file(path);
  if (!file) return std::move(file.error());
  return read_skeleton_json(*file, path);
}

}  // namespace sylva
