// turtle.h — the 3D turtle of docs/spec/grammar.md that turns a derived word into a Skeleton.
//
// Frame: the turtle starts at the origin with heading H = +Y, left L = −X, up U = +Z
// (right-handed, H × L = U). Angles in degrees; the grammar's header gives the defaults
// (angle, step, width as a radius, width decrement, tropism). Chains are built exactly as
// docs/spec/skeleton.md says: the first F (and the first F after f) starts a root chain; the first
// F after '[' starts a chain attached to the joint the turtle stands on; after ']' the
// turtle continues its chain if its joint is still that chain's last, else branches.
// Tropism (ABOP 2.2) bends H toward T by e·|H × T| after every F; `@T(e)` sets e and
// `@Tp(x, y, z)` T, for the rest of the branch. Zero-length moves make
// no joint and are counted.
// Polygons (docs/spec/grammar.md, ABOP 1.10 and 5.1): `{` opens one (they nest), `.` records the
// turtle's position as its next vertex (outside a polygon it records nothing), `}` closes
// it into a Leaf hanging from the joint the turtle stood on at `{` with the material in
// force at `}`; inside a polygon `f` does not end the chain. `G` moves without drawing
// and without ending the chain.
//
// Errors (a Diagnostic naming the module and its index in the word): a position that is
// no longer finite, a negative radius, a material that is not a non-negative integer,
// ']' without '[', '}' without '{' (and the reverse), a polygon that cannot be a leaf
// (leaf_polygon_problem: fewer than 3 distinct vertices, far from planar), named at its '}'. Nothing recurses: the branch stack is an explicit array.
// Long words: progress and cancellation through a Progress (core/util/progress.h).
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "core/geometry/skeleton.h"
#include "core/util/progress.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

namespace sylva {

struct TurtleStats {
  uint64_t zero_length_moves = 0;  // F/f with length 0: no joint made
  uint64_t modules_read = 0;
  double seconds = 0;
};

// Interprets `word` (the interpreted word: homomorphism already applied) with the turtle
// settings of `grammar`. `progress` (progress.h) is checked and told the fraction of the
// word read every 64 Ki modules; cancelled: cancelled_diagnostic(). `queries`, when
// given, receives the turtle's position at each light query `?E` of the word, in word
// order (docs/spec/light.md: where the query's sensor sits). `turtle_queries`, when given,
// receives the answer of each turtle query of the word, in word order (CPFG manual 6.9):
// the position for ?P, the heading for ?H, the left vector for ?L, the up vector for ?U,
// in the skeleton's frame (metres; unit vectors).
Expected<Skeleton> build_skeleton(const lsys::Word& word, const lsys::Grammar& grammar,
                                  TurtleStats* stats = nullptr, const Progress& progress = {},
                                  std::vector<glm::dvec3>* queries = nullptr,
                                  std::vector<glm::dvec3>* turtle_queries = nullptr);

}  // namespace sylva
