// skeleton.h — the skeleton every stage after the L-system consumes.
//
// Contract (docs/spec/skeleton.md): a skeleton is a set of chains; a chain is a
// polyline of joints (position in metres, Y up; radius in metres; material index).
// Consecutive joints of a chain bound one segment, later skinned as one conical frustum.
// Stored data-oriented: all joints of all chains in one flat array, each chain a
// [first_joint, first_joint + joint_count) range of it plus its parent attachment.
//
// Invariants (checked by validate_skeleton and by the JSON reader):
//   - positions and radii are finite, radii >= 0 (a radius of 0 is a tip);
//   - chains[c].first_joint + chains[c].joint_count <= joints.size(), ranges disjoint
//     and in chain order;
//   - a parent is (chain index < c, joint index < that chain's joint_count) or none;
//   - a leaf's joint, if any, is a joint of an existing chain; its polygon passes
//     leaf_polygon_problem (at least 3 distinct finite vertices, close to planar).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/diagnostic.h"
#include "core/util/json.h"

namespace sylva {

// One joint: where the chain passes, how thick it is there, and the material index of
// the segment that ends at it.
struct Joint {
  double position_m[3];  // metres, Y up
  double radius_m;       // >= 0; 0 is a tip
  uint32_t material;     // material index in force for the segment ending here
  bool operator==(const Joint&) const = default;
};

// Where a chain is attached: a joint of an earlier chain.
struct ChainParent {
  uint32_t chain;  // index of the parent chain, always < the child's index
  uint32_t joint;  // joint index within the parent chain
  bool operator==(const ChainParent&) const = default;
};

// One botanical axis: a range of the flat joint array.
struct Chain {
  uint32_t first_joint;   // index into Skeleton::joints
  uint32_t joint_count;   // >= 1; segments = joint_count - 1
  std::optional<ChainParent> parent;  // none for a root chain
  bool operator==(const Chain&) const = default;
};

// A leaf (docs/spec/skeleton.md "Leaves"): the flat, two-sided polygon of one `{ . . . }` of the
// grammar, hanging from the joint the turtle stood on at `{` so that it moves with it.
struct Leaf {
  std::optional<ChainParent> joint;               // (chain, joint index); none: before the first F
  uint32_t material = 0;                          // the material index in force at `}`
  std::vector<std::array<double, 3>> vertices_m;  // metres, Y up, in the order recorded
  // A double-sided leaf's back (docs/leaves.md "Two colours"): the material seen from behind,
  // the side its Newell normal points away from; `material` is then its front's. None: one
  // material on both sides. A cpfg double-sided surface's (docs/cpfg.md).
  std::optional<uint32_t> back_material;
  bool operator==(const Leaf&) const = default;
};

// How far from planar a leaf may be: its vertices' largest distance from their plane
// (through the centroid, along the Newell normal), as a share of its bounding box's
// diagonal. A turtle's polygon is planar up to rounding; 2 % allows a leaf drawn with a
// slight twist, not a fold.
constexpr double kLeafMaxNonPlanarity = 0.02;

// Why `vertices` cannot be a leaf, nullopt when they can: a vertex that is not finite,
// fewer than 3 distinct vertices (closer than 1e-9 of the diagonal counts as the same),
// no area (all on one line), or farther from planar than kLeafMaxNonPlanarity.
std::optional<std::string> leaf_polygon_problem(std::span<const std::array<double, 3>> vertices);

// Where a skeleton came from, written into its file so it can be reproduced.
struct SkeletonSource {
  std::string grammar;                    // path of the grammar as the user gave it
  uint64_t seed = 1;                      // 64-bit seed, never passed through a double
  int64_t steps = 0;                      // derivation steps
  std::map<std::string, double> defines;  // -D overrides given by the user, by name
  bool operator==(const SkeletonSource&) const = default;
};

struct Skeleton {
  std::vector<Joint> joints;  // all chains' joints, chain after chain
  std::vector<Chain> chains;  // parents before children
  std::vector<Leaf> leaves;   // in the order the grammar closes them
  SkeletonSource source;

  // Number of segments: sum over chains of (joint_count - 1).
  uint64_t segment_count() const;
  bool operator==(const Skeleton&) const = default;
};

// Checks the invariants above. Returns the first violation, naming chain and joint (a
// Diagnostic without file or place: the skeleton is a value, not a file).
Status validate_skeleton(const Skeleton& skeleton);

// How write_skeleton_members lays the document out.
struct SkeletonJsonStyle {
  bool compact = false;         // no spaces or line breaks (for embedding, e.g. glTF extras)
  bool seed_as_string = false;  // "seed": "18446744073709551615", for JSON consumers that
                                //   read every number as a double (glTF extras)
  bool header_only = false;     // only "format", "version" (2 with leaves) and "source": the
                                //   chains and leaves go elsewhere (glTF extras "compact",
                                //   gltf_export.h)
};

// Writes the members of the sylva-skeleton document — "format", "version", "source"
// {grammar, seed, steps, defines}, "chains" [{"parent": [chain,joint] | null, "joints":
// [[x,y,z,radius,material],...]}] — into the object open in `w`. The one serialiser of
// a skeleton: write_skeleton_json and the glTF node extras (gltf_export.h) both use it.
// With leaves: "version" 2 and "leaves" [{"joint": [chain,joint] | null, "material": m,
// "vertices": [[x,y,z],...]}] after "chains".
// Precondition: validate_skeleton(skeleton) succeeds.
void write_skeleton_members(JsonWriter& w, const Skeleton& skeleton, const SkeletonJsonStyle& style = {});

// Serialises to the sylva-skeleton JSON format: version 1 without leaves, version 2 (its
// "leaves" after "chains", one leaf per line) with them. Byte-identical output for
// identical input on every machine: fixed key order, numbers in the shortest decimal
// form that reads back to the same double (std::to_chars), "\n" line endings; one key
// per line at the top, one chain per line.
std::string write_skeleton_json(const Skeleton& skeleton);

// Parses sylva-skeleton JSON text, version 1 or 2 ("leaves" in version 2 only). `file` is
// only used in messages. Rejects unknown format or version, a bad leaf (its joint not
// one of the chains', leaf_polygon_problem), malformed JSON, NaN/infinity/out-of-range numbers, negative radii,
// materials that are not non-negative integers, and dangling or forward parents, with a
// message naming the chain and joint and the place in the text (no source line).
Expected<Skeleton> read_skeleton_json(std::string_view text, std::string_view file);

// Reads a file from disk and parses it; an unreadable file is an error too.
Expected<Skeleton> read_skeleton_file(const std::string& path);

}  // namespace sylva
