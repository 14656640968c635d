// skeleton.h — the skeleton every stage after the L-system consumes.
//
// Contract (../shared/spec/skeleton.md): a skeleton is a set of chains; a chain is a
// polyline of joints (position in metres, Y up; radius in metres; material index).
// Consecutive joints of a chain bound one segment, later skinned as one conical frustum.
// Stored data-oriented: all joints of all chains in one flat array, each chain a
// [first_joint, first_joint + joint_count) range of it plus its parent attachment.
//
// Invariants (checked by validate_skeleton and by the JSON reader):
//   - positions and radii are finite, radii >= 0 (a radius of 0 is a tip);
//   - chains[c].first_joint + chains[c].joint_count <= joints.size(), ranges disjoint
//     and in chain order;
//   - a parent is (chain index < c, joint index < that chain's joint_count) or none.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sylva {

// One joint: where the chain passes, how thick it is there, and the material index of
// the segment that ends at it.
struct Joint {
  double position_m[3];  // metres, Y up
  double radius_m;       // >= 0; 0 is a tip
  uint32_t material;     // material index in force for the segment ending here
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
};

// Where a skeleton came from, written into its file so it can be reproduced.
struct SkeletonSource {
  std::string grammar;                    // path of the grammar as the user gave it
  uint64_t seed = 1;                      // 64-bit seed, never passed through a double
  int64_t steps = 0;                      // derivation steps
  std::map<std::string, double> defines;  // -D overrides given by the user, by name
};

struct Skeleton {
  std::vector<Joint> joints;  // all chains' joints, chain after chain
  std::vector<Chain> chains;  // parents before children
  SkeletonSource source;

  // Number of segments: sum over chains of (joint_count - 1).
  uint64_t segment_count() const;
};

// A located problem in a skeleton file or value: "file:line:column: error: message".
// line/column are 1-based; 0 where no place in a file is known.
struct SkeletonError {
  std::string file;
  uint32_t line = 0;
  uint32_t column = 0;
  std::string message;
  std::string format() const;  // "file:line:column: error: message" (place omitted if 0)
};

// Checks the invariants above. Returns the first violation, naming chain and joint.
std::optional<SkeletonError> validate_skeleton(const Skeleton& skeleton);

// Serialises to the sylva-skeleton JSON format, version 1. Byte-identical output for
// identical input on every machine: fixed key order, numbers in the shortest decimal
// form that reads back to the same double (std::to_chars), "\n" line endings.
std::string write_skeleton_json(const Skeleton& skeleton);

// Appends chain `c` as the skeleton document writes it —
// {"parent": [chain,joint] | null, "joints": [[x,y,z,radius,material],...]} — with the
// same numbers; `compact` drops the spaces after ':' and ',' (for embedding, e.g. in
// glTF extras). One writer for every place a chain is serialised.
void append_chain_json(std::string& out, const Skeleton& skeleton, size_t c, bool compact);

// Result of reading a skeleton file: the skeleton, or the first error found.
struct SkeletonReadResult {
  std::optional<Skeleton> skeleton;
  std::optional<SkeletonError> error;
};

// Parses sylva-skeleton JSON text. `file` is only used in messages. Rejects unknown
// format or version, malformed JSON, NaN/infinity/out-of-range numbers, negative radii,
// materials that are not non-negative integers, and dangling or forward parents, with a
// message naming the chain and joint and the place in the text.
SkeletonReadResult read_skeleton_json(std::string_view text, std::string_view file);

// Reads a file from disk and parses it; an unreadable file is an error too.
SkeletonReadResult read_skeleton_file(const std::string& path);

}  // namespace sylva
