// turtle.cpp — the 3D turtle (ABOP ch. 1.5, 2.2) building skeleton chains (docs/spec/skeleton.md).
#include "core/grow/turtle.h"

#include <algorithm>
#include <array>
#include <map>
#include <chrono>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/util/limits.h"
#include "core/util/math.h"
#include "lsystem/expr.h"

namespace sylva {

namespace {

using glm::dvec3;

// Cancellation is checked, and progress reported, once per 64 Ki modules.
constexpr size_t kProgressChunkMask = (size_t{1} << 16) - 1;

struct TurtleState {
  dvec3 position{0, 0, 0};
  dvec3 heading{0, 1, 0};
  dvec3 left{-1, 0, 0};
  dvec3 up{0, 0, 1};
  double radius = 0.05;
  uint32_t material = 0;
  uint32_t back_material = 0;  // cpfg's back colour (@; @,), drawn where surfaces are double-sided
  double tropism_e = 0;
  dvec3 tropism{0, 0, 0};      // T (the header's, or @Tp's for the rest of the branch)
  int64_t chain = -1;          // chain the turtle stands on, or -1
  int64_t joint = -1;          // joint index within that chain
  bool branch_pending = false; // set by '[': the next F starts a new chain
  double scale = 1;            // cpfg's turtle scale (@D, @Di, @Dd; CPFG manual 6.3): lengths and set widths
  // A cpfg file's frame of the last drawn segment (cpfg's prev_heading, prev_up: set after
  // every F and G, and by @Tf): what @R and the view file's tropism turn the up vector from.
  dvec3 prev_heading{0, 1, 0};
  dvec3 prev_up{0, 0, 1};
  // A cpfg file's elasticity of each view-file tropism (by id − 1): @Ti, @Td, @Ts change it
  // for the rest of the branch.
  std::array<double, lsys::kMaxViewTropisms> elasticity{};
  // A cpfg file's generalized cylinder (CPFG manual 6.7.3; docs/cpfg.md): the open one's
  // index in build_skeleton's pool, or -1 (a branch draws on a copy, as cpfg's spline
  // stack); whether f and F set its control points ({(type)) or not (@Gs); and the
  // Hermite tangent coefficients @Gt sets.
  int32_t cylinder = -1;
  bool cylinder_moves = false;
  double tangent_start = 1.2, tangent_end = 1.2;
  // The contour @#(id) selects for the cylinders (0: the circle, drawn as frusta) and the
  // points around one @!(n) sets (-1: the view file's `contour sides:`).
  int contour = 0;
  int contour_sides = -1;
  // @Gr's radius tangents, at a piece's start and end ((0, 0): the radius changes linearly),
  // and whether they are stretched by the piece's length (@Gr(flag)).
  std::array<glm::dvec2, 2> radius_tangent{};
  bool scale_radius_tangents = false;
};

// A control point of a generalized cylinder: where the turtle was, its heading, width and
// colour.
struct ControlPoint {
  dvec3 position{0}, heading{0, 1, 0}, up{0, 0, 1};
  double radius = 0;
  uint32_t material = 0;
  int contour = 0;  // TurtleState::contour
  int sides = 8;    // the points around its contour
  std::array<glm::dvec2, 2> radius_tangent{};  // TurtleState's
  bool scale_radius_tangents = false;
};

// A piece's radius along it (CPFG manual 6.7.3 @Gr, cpfg's interpolate_connection): with its
// start and end radius tangents (t, r) — a's second and b's first, the r parts times the
// piece's length where b asks — the pair (curve parameter, radius) is a Hermite curve in the
// piece's fraction s from (0, r0) to (1, r1); a zero tangent is (1, r1 − r0), so without @Gr
// the parameter is s and the radius linear in it.
struct RadiusProfile {
  double c[4][2] = {};  // cubic coefficients in s of the parameter and the radius
  RadiusProfile(const ControlPoint& a, const ControlPoint& b, double length) {
    const double r0 = a.radius, dr = b.radius - a.radius;
    glm::dvec2 ta = a.radius_tangent[1], tb = b.radius_tangent[0];
    if (b.scale_radius_tangents) ta.y *= length, tb.y *= length;
    if (ta == glm::dvec2(0)) ta = {1, dr};
    if (tb == glm::dvec2(0)) tb = {1, dr};
    const double start[2] = {0, r0}, delta[2] = {1, dr}, t0[2] = {ta.x, ta.y}, t1[2] = {tb.x, tb.y};
    for (int k = 0; k < 2; ++k) {
      c[0][k] = start[k];
      c[1][k] = t0[k];
      c[2][k] = 3 * delta[k] - 2 * t0[k] - t1[k];
      c[3][k] = -2 * delta[k] + t0[k] + t1[k];
    }
  }
  // (curve parameter clamped to [0, 1], radius not below 0) at fraction s.
  std::pair<double, double> at(double s) const {
    const double u = ((c[3][0] * s + c[2][0]) * s + c[1][0]) * s + c[0][0];
    const double r = ((c[3][1] * s + c[2][1]) * s + c[1][1]) * s + c[0][1];
    return {std::clamp(u, 0.0, 1.0), std::max(r, 0.0)};
  }
};

// An open generalized cylinder: a Hermite curve through its control points (tangents along
// the turtle's heading, length × the @Gt coefficients) or a uniform cubic B-spline over
// them, open or closed, drawn as one chain of frusta, `strips` a segment.
struct GenCylinder {
  bool bspline = false, closed = false;
  int default_strips = 1;               // per segment when the point gives none
  std::optional<ChainParent> parent;    // the joint the turtle stood on when it started
  std::array<ControlPoint, 3> last{};   // the newest control points (Hermite: 1, B-spline: 3)
  int count = 0;
  std::array<ControlPoint, 3> first{};  // a closed curve's first points, drawn again at its end
  int first_count = 0;
  int64_t chain = -1, joint = -1;       // the chain drawn so far and its last joint
};

// A polygon between `{` and `}` (docs/spec/grammar.md, ABOP 1.10 and 5.1; cpfg): the joint the
// turtle stood on at `{`, where it stood, and the vertices `.`, `F` and `f` recorded.
struct OpenPolygon {
  size_t module;                          // the `{`'s index in the word, for messages
  std::optional<ChainParent> joint;
  dvec3 opened;                           // the turtle's position at `{`
  std::vector<std::array<double, 3>> vertices;
};

// Two recorded vertices are "equal" (docs/spec/grammar.md: a repeat is recorded once) when
// they differ by rounding only: 1e-9 of their magnitude, or 1e-12 m near the origin. A turtle
// that walks a polygon's outline back to its start (`{.-f+f+f-|-f+f+f}`) lands there up to
// rounding, never bit for bit.
bool same_vertex(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  double scale = 0, gap = 0;
  for (int k = 0; k < 3; ++k) {
    scale = std::max({scale, std::abs(a[k]), std::abs(b[k])});
    gap = std::max(gap, std::abs(a[k] - b[k]));
  }
  return gap <= 1e-12 + 1e-9 * scale;
}

void record_vertex(OpenPolygon& polygon, const dvec3& p) {
  const std::array<double, 3> v{p.x, p.y, p.z};
  if (polygon.vertices.empty() || !same_vertex(polygon.vertices.back(), v)) polygon.vertices.push_back(v);
}

// Closes a polygon's vertex list as cpfg draws it: a last vertex equal to the first is
// dropped, and the list is turned (its cyclic order kept) so that the vertex nearest to where
// `{` opened comes first: the petiole (leaf_mesh.h). Of vertices equally near (within 1e-9),
// the first recorded is taken, so a symmetric blade keeps its order.
std::vector<std::array<double, 3>> closed_polygon(OpenPolygon& polygon) {
  std::vector<std::array<double, 3>> v = std::move(polygon.vertices);
  if (v.size() > 1 && same_vertex(v.front(), v.back())) v.pop_back();
  if (v.empty()) return v;
  std::vector<double> distance(v.size());
  double nearest = INFINITY;
  for (size_t k = 0; k < v.size(); ++k) {
    distance[k] = glm::length(dvec3(v[k][0], v[k][1], v[k][2]) - polygon.opened);
    nearest = std::min(nearest, distance[k]);
  }
  size_t first = 0;
  while (distance[first] > nearest + 1e-9 * std::max(nearest, glm::length(polygon.opened))) ++first;
  std::rotate(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(first), v.end());
  return v;
}

struct PendingJoint {
  uint32_t chain;
  Joint joint;
};

struct TurtleFailure {
  std::string message;
};

// Positions stay within the coordinate limit (docs/limits.md), finite a fortiori.
void check_position(const dvec3& p) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    throw TurtleFailure{"the turtle's position is no longer finite"};
  if (std::abs(p.x) > kMaxCoordinateM || std::abs(p.y) > kMaxCoordinateM || std::abs(p.z) > kMaxCoordinateM)
    throw TurtleFailure{"the turtle's position exceeds the limit of 1e12 m from the origin (docs/limits.md)"};
}

// Keeps the frame orthonormal and right-handed after a rotation (cheap Gram–Schmidt).
void orthonormalize(TurtleState& t) {
  t.heading = glm::normalize(t.heading);
  t.left = glm::normalize(t.left - glm::dot(t.left, t.heading) * t.heading);
  t.up = glm::cross(t.heading, t.left);
}

// Cosine and sine of a turn: the grammar's default angle is computed once.
struct Turn {
  double c, s;
};
Turn turn_of(double angle_deg) { return {lsys::cos_deg(angle_deg), lsys::sin_deg(angle_deg)}; }

// Rotates the pair (a, b) in their plane by a turn, turning a toward b.
void rotate_pair(dvec3& a, dvec3& b, Turn t) {
  const double c = t.c, s = t.s;
  const dvec3 a2 = a * c + b * s;
  const dvec3 b2 = b * c - a * s;
  a = a2;
  b = b2;
}

// Rodrigues rotation of v about unit axis k by angle (radians).
dvec3 rotate_about(const dvec3& v, const dvec3& k, double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1 - c);
}

// The least rotation of the frame that takes its heading to `heading` (about old × new by
// their angle, atan2 of |cross| and dot, exact near 0 and 180 degrees); a reversal turns
// about U, as |.
void turn_heading_least(TurtleState& t, const dvec3& heading) {
  const dvec3 axis = glm::cross(t.heading, heading);
  const double sin_a = glm::length(axis), cos_a = glm::dot(t.heading, heading);
  if (sin_a > 1e-15) {
    const dvec3 k = axis / sin_a;
    t.left = rotate_about(t.left, k, std::atan2(sin_a, cos_a));
  } else if (cos_a < 0) {
    t.left = -t.left;  // 180 degrees about U, as |
  }
  t.heading = heading;
  orthonormalize(t);
}

// cpfg's adjust_up_and_left (cpfg/turtle.c), after the heading was set or bent: where the
// heading has moved from the last drawn segment's (|prev H × H| > 1e-6), up is that
// segment's up turned by the least rotation from its heading to the current one — so a
// roll (/ \) since that segment is undone, as in cpfg (its @Tf keeps one); otherwise up
// stays. Left = up × heading in sylva's frame. An up left parallel to the heading (a
// degenerate case cpfg does not guard) falls back to the least rotation of the frame.
void adjust_up_and_left(TurtleState& t, const dvec3& old_heading) {
  const dvec3 axis = glm::cross(t.prev_heading, t.heading);
  const double sin_a = glm::length(axis);
  dvec3 up = t.up;
  if (sin_a > 1e-6) up = rotate_about(t.prev_up, axis / sin_a, std::atan2(sin_a, glm::dot(t.prev_heading, t.heading)));
  up -= glm::dot(up, t.heading) * t.heading;
  const double ul = glm::length(up);
  if (!(ul > 1e-9)) {
    const dvec3 heading = t.heading;
    t.heading = old_heading;
    turn_heading_least(t, heading);
    return;
  }
  t.up = up / ul;
  t.left = glm::cross(t.up, t.heading);
}

// The view file's torques (CPFG manual 8.1.8) after its tropisms, as cpfg's movement_adjust
// twists (cpfg/movements.c, rotate_to_vector): with D the torques' Σ e·T, not along H, the
// desired direction is |D| times D's part across H, of length sin(H, D), and the up vector
// turns about H by |U × desired| (at most 1) radians. cpfg's own up vector turns away from
// the desired direction (its quaternion's sign; its comment says "towards"); cpfg's up is
// sylva's reversed (cpfg starts with U = −z), so sylva's turns toward it and comes to rest
// along T's projection. The heading stays; left = up × heading; this frame becomes the last
// segment's for later turns, as in cpfg.
void cpfg_twist(TurtleState& t, const dvec3& twist) {
  const double length = glm::length(twist);
  if (!(length > 0)) return;
  const dvec3 across = glm::cross(t.heading, twist / length);
  if (!(glm::dot(across, across) > 1e-8)) return;  // D along H: no twist
  const dvec3 desired = glm::cross(across, t.heading) * length;
  const dvec3 axis = glm::cross(t.up, desired);
  double angle = glm::length(axis);
  if (angle < 1e-7) return;
  const dvec3 k = axis / angle;
  angle = std::min(angle, 1.0);
  t.up = glm::normalize(rotate_about(t.up, k, angle));
  t.up = glm::normalize(t.up - glm::dot(t.up, t.heading) * t.heading);
  t.left = glm::cross(t.up, t.heading);
  t.prev_heading = t.heading;
  t.prev_up = t.up;
}

// The view file's tropisms (CPFG manual 8.1.8) as cpfg's movement_adjust applies them before
// every F, G, f and g (cpfg/movements.c): one desired direction V, the sum over tropisms i of
// cos(A_i)·e_i·T_i and, where A_i is not 0, sin(A_i)·e_i·T_i × (H × T_i) / |H × T_i| (H × T_i
// replaced by L where H is along T_i); H turned toward V about H × V by |H × V| radians, at
// most 1; then the up vector as adjust_up_and_left makes it. No turn below 1e-6. The first
// tropism's vector is the turtle's (t.tropism: @Tp(x, y, z) sets it).
void cpfg_bend(TurtleState& t, const std::vector<lsys::ViewTropism>& tropisms) {
  dvec3 desired(0, 0, 0);
  dvec3 twist(0, 0, 0);  // the torques' sum of elasticity × T
  for (size_t i = 0; i < tropisms.size(); ++i) {
    const lsys::ViewTropism& tr = tropisms[i];
    if (tr.torque) {
      twist += t.elasticity[i] * dvec3(tr.vector[0], tr.vector[1], tr.vector[2]);
      continue;
    }
    const dvec3 T = i == 0 ? t.tropism : dvec3(tr.vector[0], tr.vector[1], tr.vector[2]);  // @Tp sets the first
    const double e = t.elasticity[i];
    const double a = tr.angle_deg;
    desired += lsys::cos_deg(a) * e * T;
    const double sin_a = lsys::sin_deg(a);
    if (sin_a != 0) {
      dvec3 across = glm::cross(t.heading, T);
      double len = glm::length(across);
      if (len < 1e-7) across = t.left, len = 1;
      desired += (sin_a * e / len) * glm::cross(T, across);
    }
  }
  const dvec3 rot = glm::cross(t.heading, desired);
  const double len = glm::length(rot);
  if (len >= 1e-6) {
    const dvec3 old_heading = t.heading;
    t.heading = glm::normalize(rotate_about(t.heading, rot / len, std::min(len, 1.0)));
    adjust_up_and_left(t, old_heading);
  }
  cpfg_twist(t, twist);
}

// @R(hx, hy[, hz]) and @R(hx, hy, hz, ux, uy, uz) (CPFG manual 6.2, as cpfg does it): the
// heading set to the given direction (normalised; z = 0 with two parameters; a zero vector
// is the initial heading, +y). With an up vector that is not zero and perpendicular to the
// heading, up is that vector normalised and left = up × heading; otherwise up and left as
// cpfg's adjust_up_and_left makes them: the last drawn segment's up turned by the least
// rotation from its heading to the new one.
void set_heading(TurtleState& t, uint32_t count, const double* p) {
  if (count < 2) throw TurtleFailure{"@R takes the heading: @R(hx, hy, hz), or with the up vector, @R(hx, hy, hz, ux, uy, uz)"};
  for (uint32_t k = 0; k < count && k < 6; ++k)
    if (!std::isfinite(p[k])) throw TurtleFailure{"@R's vectors must be finite"};
  const dvec3 h(p[0], p[1], count >= 3 ? p[2] : 0.0);
  const double hl = glm::length(h);
  if (!std::isfinite(hl)) throw TurtleFailure{"@R's vectors must be finite"};
  const dvec3 heading = hl > 0 ? h / hl : dvec3(0, 1, 0);
  if (count >= 6) {
    const dvec3 u(p[3], p[4], p[5]);
    const double ul = glm::length(u);
    if (ul > 0 && std::isfinite(ul) && std::abs(glm::dot(u / ul, heading)) <= 1e-12) {
      t.heading = heading;
      t.up = glm::normalize(u - glm::dot(u, heading) * heading);
      t.left = glm::cross(t.up, t.heading);
      return;
    }
  }
  const dvec3 old_heading = t.heading;
  t.heading = heading;
  adjust_up_and_left(t, old_heading);
}

// The places of the grammar that write a module with `symbol`: the axiom, then every
// production and interpretation production whose successor holds it, in file order.
// Modules carry no source place (derive.h), so this is where a turtle error can point.
std::vector<SourceLoc> places_writing(const lsys::Grammar& g, lsys::SymbolId symbol) {
  std::vector<SourceLoc> places;
  for (const lsys::Module& m : g.axiom.modules)
    if (m.symbol == symbol) {
      places.push_back(g.axiom_loc);
      break;
    }
  for (const auto* list : {&g.productions, &g.decomposition, &g.homomorphism})
    for (const lsys::Production& p : *list)
      for (const lsys::SuccessorModule& m : p.successor.modules)
        if (m.symbol == symbol) {
          places.push_back(p.loc);
          break;
        }
  std::sort(places.begin(), places.end(),
            [](SourceLoc a, SourceLoc b) { return a.line != b.line ? a.line < b.line : a.column < b.column; });
  return places;
}

// What the turtle makes of a cpfg file's own symbols (CPFG manual 6; docs/cpfg.md).
enum class CpfgKind : uint8_t {
  kNone, kDraw, kMove, kColorUp, kColorDown, kWidthUp, kWidthDown, kLevel, kSetPosition, kSetHeading, kCircle, kSphere,
  kScaleSet, kScaleUp, kScaleDown, kForceTwist, kElasticityUp, kElasticityDown, kElasticitySet,
  kCylinderStart, kCylinderPoint, kCylinderEnd, kCylinderTangents, kCylinderSides, kCylinderContour, kSurface, kRadiusTangents,
  kSubCall, kSubEnd, kPatchInit, kPatchPoint, kPatchDraw, kRing, kBackColorUp, kBackColorDown
};

struct CpfgSymbols {
  std::vector<CpfgKind> kind;  // by symbol id; empty for sylva's own format
};

CpfgSymbols cpfg_symbols(const lsys::Grammar& g) {
  CpfgSymbols out;
  if (!g.cpfg) return out;
  out.kind.assign(g.symbols.size(), CpfgKind::kNone);
  auto set = [&](const char* name, CpfgKind kind) {
    lsys::SymbolId id = 0;
    if (g.symbols.find(name, &id)) out.kind[id] = kind;
  };
  set("G", CpfgKind::kDraw);
  set("g", CpfgKind::kMove);
  set(";", CpfgKind::kColorUp);
  set(",", CpfgKind::kColorDown);
  set("#", CpfgKind::kWidthUp);
  set("!", CpfgKind::kWidthDown);
  set("@v", CpfgKind::kLevel);
  set("@M", CpfgKind::kSetPosition);
  set("@R", CpfgKind::kSetHeading);
  set("@c", CpfgKind::kCircle);
  set("@O", CpfgKind::kSphere);
  set("@o", CpfgKind::kSphere);  // a disc facing the camera: a sphere shows one from everywhere
  set("~", CpfgKind::kSurface);
  set("?", CpfgKind::kSubCall);  // ?(label, s): a sub-L-system, drawn s times larger
  set("$", CpfgKind::kSubEnd);   // its end (cpfg's $ is no roll: @v levels the turtle)
  set("@D", CpfgKind::kScaleSet);
  set("@Di", CpfgKind::kScaleUp);
  set("@Dd", CpfgKind::kScaleDown);
  set("@Tf", CpfgKind::kForceTwist);
  set("@T", CpfgKind::kElasticityUp);  // the manual's name; cpfg's source reads @Ti
  set("@Ti", CpfgKind::kElasticityUp);
  set("@Td", CpfgKind::kElasticityDown);
  set("@Ts", CpfgKind::kElasticitySet);
  set("@Gs", CpfgKind::kCylinderStart);
  set("@Gc", CpfgKind::kCylinderPoint);
  set("@Ge", CpfgKind::kCylinderEnd);
  set("@Gt", CpfgKind::kCylinderTangents);
  set("@Gr", CpfgKind::kRadiusTangents);
  set("@!", CpfgKind::kCylinderSides);
  set("@#", CpfgKind::kCylinderContour);
  set("@PS", CpfgKind::kPatchInit);
  set("@PC", CpfgKind::kPatchPoint);
  set("@PD", CpfgKind::kPatchDraw);
  set("@bc", CpfgKind::kRing);
  set("@bo", CpfgKind::kRing);  // a boundary facing the screen: drawn in the HL plane (docs/cpfg.md)
  set("@;", CpfgKind::kBackColorUp);
  set("@,", CpfgKind::kBackColorDown);
  return out;
}

// @c's polygon and @O's frusta (docs/cpfg.md): a 24-gon's area is 1.1 % short of the
// circle's; 16 frusta inscribed in the sphere's profile hold 99.0 % of its volume.
constexpr int kCircleSides = 24;
// Generalized cylinders: the strips a piece gets from f and F ({(type)'s default, cpfg's
// DEFAULT_RINGS), and the most one piece may ask for.
constexpr int kDefaultCylinderRings = 4;
constexpr int kMaxCylinderStrips = 10000;
constexpr int kSphereSegments = 16;

// An L-system defined surface patch (CPFG manual 6.7.2, cpfg's patches.c): @PS(id, basis)
// clears it, @PC(id, r, c) puts control point (r, c) where the turtle stands, @PD(id, s, t)
// draws it. Bases 1 Bézier, 2 B-spline, 3 Cardinal (patches.c's matrices).
struct TurtlePatch {
  int basis = 1;
  std::array<glm::dvec3, 16> points{};  // row-major: row r (along s), column c (along t)
  std::array<bool, 16> set{};
};
constexpr double kPatchBasis[3][4][4] = {
    {{-1, 3, -3, 1}, {3, -6, 3, 0}, {-3, 3, 0, 0}, {1, 0, 0, 0}},
    {{-1. / 6, 3. / 6, -3. / 6, 1. / 6}, {3. / 6, -6. / 6, 3. / 6, 0}, {-3. / 6, 0, 3. / 6, 0}, {1. / 6, 4. / 6, 1. / 6, 0}},
    {{-0.5, 1.5, -1.5, 0.5}, {1.0, -2.5, 2.0, -0.5}, {-0.5, 0.0, 0.5, 0.0}, {0.0, 1.0, 0.0, 0.0}}};
constexpr int kPatchMaxPrecision = 10;  // patches.c's S_COUNT and T_COUNT (half of each without @PD's s, t)

// The patch's point at (u, v) in [0, 1]²: [u³ u² u 1] M G Mᵀ [v³ v² v 1]ᵀ, G the control points.
glm::dvec3 patch_point(const TurtlePatch& patch, double u, double v) {
  const auto& m = kPatchBasis[patch.basis - 1];
  const double uu[4] = {u * u * u, u * u, u, 1}, vv[4] = {v * v * v, v * v, v, 1};
  double a[4] = {0, 0, 0, 0}, b[4] = {0, 0, 0, 0};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) a[i] += uu[k] * m[k][i], b[i] += vv[k] * m[k][i];
  glm::dvec3 out(0.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out += a[r] * b[c] * patch.points[static_cast<size_t>(4 * r + c)];
  return out;
}

}  // namespace

Expected<Skeleton> build_skeleton(const lsys::Word& word, const lsys::Grammar& g, TurtleStats* stats,
                                  const Progress& progress, std::vector<glm::dvec3>* queries,
                                  std::vector<glm::dvec3>* turtle_queries) {
  using namespace lsys;
  auto t0 = std::chrono::steady_clock::now();
  const TurtleDefaults& d = g.turtle;
  TurtleState t;
  t.tropism = dvec3(d.tropism[0], d.tropism[1], d.tropism[2]);
  t.radius = d.width;
  t.material = d.initial_color;
  t.back_material = d.initial_back_color;
  t.scale = d.initial_scale;
  t.tropism_e = d.has_tropism ? d.tropism_e : 0.0;
  // A cpfg file's tropisms: its view file's, else sylva's `tropism:` header as one
  // orthotropism (docs/cpfg.md); their elasticities start at E.
  std::vector<lsys::ViewTropism> cpfg_tropisms;
  if (g.cpfg) {
    cpfg_tropisms = d.view_tropisms;
    if (cpfg_tropisms.empty() && d.has_tropism) {
      lsys::ViewTropism one;
      for (int k = 0; k < 3; ++k) one.vector[k] = d.tropism[k];
      one.elasticity = d.tropism_e;
      cpfg_tropisms.push_back(one);
    }
    if (cpfg_tropisms.size() > lsys::kMaxViewTropisms) cpfg_tropisms.resize(lsys::kMaxViewTropisms);
    for (size_t i = 0; i < cpfg_tropisms.size(); ++i) t.elasticity[i] = cpfg_tropisms[i].elasticity;
    // The first tropism's vector rides on the turtle, so @Tp(x, y, z) sets it for the branch.
    if (!cpfg_tropisms.empty())
      t.tropism = dvec3(cpfg_tropisms[0].vector[0], cpfg_tropisms[0].vector[1], cpfg_tropisms[0].vector[2]);
    t.tropism_e = 0;  // a cpfg file bends by cpfg_bend only
  }
  std::vector<TurtleState> stack;
  std::vector<PendingJoint> joints;
  std::vector<uint32_t> chain_joint_count;
  std::vector<std::optional<ChainParent>> chain_parent;
  uint64_t zero_moves = 0;
  // `{ . } G` are looked up by name: making them built-in symbols would renumber every
  // grammar's own modules.
  auto id_of = [&](const char* name) {
    SymbolId id = 0;
    return g.symbols.find(name, &id) ? std::optional<SymbolId>(id) : std::nullopt;
  };
  const std::optional<SymbolId> sym_open = id_of("{"), sym_vertex = id_of("."), sym_close = id_of("}"),
                                sym_move = g.cpfg ? std::nullopt : id_of("G");
  // A cpfg file's own symbols (docs/cpfg.md), by symbol id; none for sylva's format.
  const CpfgSymbols cpfg = cpfg_symbols(g);
  std::vector<OpenPolygon> polygons;  // a stack: polygons nest
  std::vector<Leaf> leaves;
  // Generalized cylinders (cpfg files): the pool TurtleState::cylinder indexes. '[' gives
  // the branch a copy of the open one (cpfg's PushSpline) and ']' drops what the branch
  // added to the pool, so it never outgrows the open cylinders of the branches open.
  std::vector<GenCylinder> cylinders;
  std::vector<size_t> cylinder_marks;  // the pool's size at each '[' still open
  std::vector<double> sub_scales;      // cpfg: the scale of each sub-L-system entered and not left
  std::map<double, TurtlePatch> turtle_patches;  // cpfg: the L-system defined surfaces by id
  // The joint the turtle stands on, which what it draws in place (a leaf, a sphere) hangs from.
  auto standing_on = [](const TurtleState& at) -> std::optional<ChainParent> {
    if (at.chain < 0) return std::nullopt;
    return ChainParent{static_cast<uint32_t>(at.chain), static_cast<uint32_t>(at.joint)};
  };
  // A new chain of `count` joints hung from `parent`: its id (the joints are the caller's to add).
  auto new_chain = [&](uint32_t count, const std::optional<ChainParent>& parent) {
    if (chain_joint_count.size() >= 0xFFFFFFFFu) throw TurtleFailure{"too many chains"};
    const uint32_t c = static_cast<uint32_t>(chain_joint_count.size());
    chain_joint_count.push_back(count);
    chain_parent.push_back(parent);
    return c;
  };
  // Appends one piece of a cylinder's curve to its chain: `strips` joints at curve(k /
  // strips), radii from r0 to r1, in the colour of the piece's start. A new chain where
  // there is none yet or where the chain went on meanwhile (a branch drew from this point).
  auto cylinder_piece = [&](GenCylinder& c, const dvec3& start, const RadiusProfile& profile, uint32_t material,
                            int strips, const auto& curve) {
    const double r0 = profile.at(0).second;
    if (c.chain < 0 || c.joint + 1 != static_cast<int64_t>(chain_joint_count[static_cast<size_t>(c.chain)])) {
      const std::optional<ChainParent> parent =
          c.chain < 0 ? c.parent : ChainParent{static_cast<uint32_t>(c.chain), static_cast<uint32_t>(c.joint)};
      const uint32_t id = new_chain(1, parent);
      joints.push_back({id, Joint{{start.x, start.y, start.z}, r0, material}});
      c.chain = id;
      c.joint = 0;
    }
    for (int k = 1; k <= strips; ++k) {
      const auto [tau, radius] = profile.at(static_cast<double>(k) / strips);
      const dvec3 v = curve(tau);
      check_position(v);
      uint32_t& count = chain_joint_count[static_cast<size_t>(c.chain)];
      if (count == 0xFFFFFFFFu) throw TurtleFailure{"a chain has too many joints"};
      joints.push_back({static_cast<uint32_t>(c.chain), Joint{{v.x, v.y, v.z}, radius, material}});
      ++count;
      ++c.joint;
    }
  };
  // A piece whose ends have contours (docs/cpfg.md "Contours"): instead of frusta, the
  // contour swept along the curve as cpfg's make_contour places it — ring k at curve(k /
  // strips), the contour interpolated from a's to b's, times the radius, its x along cpfg's
  // up (sylva's −U) and y along −L, the frame carried along the curve from a's by the least
  // rotation between the tangents — and polygon leaves between neighbouring rings.
  // One cell of a surface or a swept contour (quad: its corners in order) as polygon leaves:
  // the quad where it is flat, else its two triangles, each kept only where it has area; a
  // triangle (three corners: a tsurface's) where it has area.
  // A leaf in `material` (the front's) hung from `at`. Where a cpfg view file makes surfaces
  // double-sided (TurtleDefaults::double_sided, docs/cpfg.md), its outline is turned round
  // (vertex 0 kept) so that its normal points to cpfg's front — the side cpfg's GL draws
  // clockwise, glFrontFace(GL_CW) — and the turtle's back colour is its back material.
  auto add_leaf = [&](const std::optional<ChainParent>& at, uint32_t material, std::vector<std::array<double, 3>> vertices) {
    if (leaves.size() >= 0xFFFFFFFFu) throw TurtleFailure{"too many leaves"};
    Leaf leaf{at, material, std::move(vertices), std::nullopt};
    if (d.double_sided) {
      std::reverse(leaf.vertices_m.begin() + 1, leaf.vertices_m.end());
      if (t.back_material != material) leaf.back_material = t.back_material;
    }
    leaves.push_back(std::move(leaf));
  };
  auto add_cell = [&](const std::optional<ChainParent>& at, uint32_t material, std::vector<std::array<double, 3>> quad) {
    if (!leaf_polygon_problem(quad)) return add_leaf(at, material, std::move(quad));
    if (quad.size() == 3) return;  // a degenerate triangle: nothing to draw
    for (std::vector<std::array<double, 3>> tri :
         {std::vector{quad[0], quad[1], quad[2]}, std::vector{quad[0], quad[2], quad[3]}})
      if (!leaf_polygon_problem(tri)) add_leaf(at, material, std::move(tri));
  };
  // A view-file contour's id, checked (0 is cpfg's default circle).
  auto check_contour = [&](int id) {
    if (id == 0 || std::any_of(g.contours.begin(), g.contours.end(), [&](const lsys::CpfgContour& c) { return c.id == id; }))
      return;
    throw TurtleFailure{"@#(" + std::to_string(id) + ") names no contour of the view file ('contour: " +
                        std::to_string(id) + " file.con')"};
  };
  // Contour `id` sampled to `sides` points, once per (id, sides) for the whole word.
  std::map<std::pair<int, int>, std::vector<std::array<double, 3>>> sampled_contours;
  auto contour_points = [&](int id, int sides) -> const std::vector<std::array<double, 3>>& {
    auto [it, added] = sampled_contours.try_emplace({id, sides});
    if (!added) return it->second;
    if (id == 0) {  // cpfg's default contour: the unit circle, closed
      for (int i = 0; i <= sides; ++i) {
        const double a = 2 * kPi * (i % sides) / sides;
        it->second.push_back({std::cos(a), std::sin(a), 0.0});
      }
      return it->second;
    }
    check_contour(id);
    for (const lsys::CpfgContour& c : g.contours)
      if (c.id == id) it->second = c.sample(sides);
    return it->second;
  };
  auto contour_piece = [&](const GenCylinder& c, const ControlPoint& a, const ControlPoint& b,
                           const RadiusProfile& profile, int strips, const auto& curve) {
    const int sides = a.sides;
    const auto& ca = contour_points(a.contour, sides);
    const auto& cb = contour_points(b.contour, sides);
    if (ca.size() != cb.size())
      throw TurtleFailure{"a generalized cylinder changes from an open contour to a closed one (cpfg cannot mix them)"};
    auto tangent = [&](double u) {
      const double e = 1e-4;
      const dvec3 d = curve(std::min(1.0, u + e)) - curve(std::max(0.0, u - e));
      const double l = glm::length(d);
      return l > 0 ? d / l : dvec3(0);
    };
    // The frames along the piece: the up vector carried by the least rotation between the
    // tangents, then turned about them by the share s of the twist that brings it to b's up
    // at the end (cpfg's twist_angle × t), so that pieces meet without a step.
    struct Frame {
      dvec3 position, heading, up;
      double radius, s;
    };
    std::vector<Frame> frames;
    frames.reserve(static_cast<size_t>(strips) + 1);
    dvec3 heading = a.heading, up = a.up;
    for (int k = 0; k <= strips; ++k) {
      const double s_k = static_cast<double>(k) / strips;
      const auto [u, r] = profile.at(s_k);
      const dvec3 p = curve(u);
      check_position(p);
      const dvec3 h = tangent(u);
      if (glm::length(h) > 0) {
        const dvec3 axis = glm::cross(heading, h);
        const double sin_a = glm::length(axis);
        if (sin_a > 1e-12) up = rotate_about(up, axis / sin_a, std::atan2(sin_a, glm::dot(heading, h)));
        heading = h;
        up = up - glm::dot(up, heading) * heading;
        const double ul = glm::length(up);
        if (ul > 1e-12) up /= ul;
      }
      frames.push_back({p, heading, up, r, s_k});
    }
    double twist = 0;
    {
      const Frame& end = frames.back();
      dvec3 target = b.up - glm::dot(b.up, end.heading) * end.heading;
      if (glm::length(target) > 1e-9) {
        target = glm::normalize(target);
        twist = std::atan2(glm::dot(glm::cross(end.up, target), end.heading), glm::dot(end.up, target));
      }
    }
    std::vector<std::array<double, 3>> previous;
    for (int k = 0; k <= strips; ++k) {
      const Frame& f = frames[static_cast<size_t>(k)];
      const double s_k = f.s, r = f.radius;
      const dvec3 p = f.position, heading = f.heading;
      const dvec3 up = twist != 0 ? rotate_about(f.up, heading, twist * s_k) : f.up;
      const dvec3 left = glm::cross(up, heading);
      std::vector<std::array<double, 3>> ring;
      ring.reserve(ca.size());
      for (size_t i = 0; i < ca.size(); ++i) {
        const double x = ca[i][0] + (cb[i][0] - ca[i][0]) * s_k, y = ca[i][1] + (cb[i][1] - ca[i][1]) * s_k;
        const dvec3 v = p + r * (-x * up - y * left);
        check_position(v);
        ring.push_back({v.x, v.y, v.z});
      }
      for (size_t i = 0; k > 0 && i + 1 < ring.size(); ++i)
        add_cell(c.parent, a.material, {previous[i], previous[i + 1], ring[i + 1], ring[i]});
      previous = std::move(ring);
    }
  };
  // A control point `cp` of cylinder `c`, and the piece it ends: Hermite (manual 6.7.3:
  // tangents along the two points' headings, the chord's length times @Gt's start and end
  // coefficients) or the uniform cubic B-spline piece of the last four points.
  auto cylinder_control = [&](GenCylinder& c, const ControlPoint& cp, int strips, double t_start, double t_end) {
    if (!c.bspline) {
      if (c.count == 0) {
        c.last[0] = cp;
        c.count = 1;
        return;
      }
      const ControlPoint a = c.last[0];
      c.last[0] = cp;
      const double len = glm::length(cp.position - a.position);
      if (!(len > 0)) return;  // coincident points: no piece (cpfg draws none)
      const dvec3 ta = a.heading * (len * t_start), tb = cp.heading * (len * t_end);
      const auto hermite = [&](double u) {
        const double u2 = u * u, u3 = u2 * u;
        return (2 * u3 - 3 * u2 + 1) * a.position + (u3 - 2 * u2 + u) * ta + (3 * u2 - 2 * u3) * cp.position +
               (u3 - u2) * tb;
      };
      const RadiusProfile profile(a, cp, len);
      if (a.contour != 0 || cp.contour != 0) contour_piece(c, a, cp, profile, strips, hermite);
      else cylinder_piece(c, a.position, profile, a.material, strips, hermite);
      return;
    }
    if (c.count < 3) {
      c.last[static_cast<size_t>(c.count++)] = cp;
      return;
    }
    const ControlPoint p0 = c.last[0], p1 = c.last[1], p2 = c.last[2];
    c.last = {p1, p2, cp};
    const auto b = [&](double u) {
      const double u2 = u * u, u3 = u2 * u, v = 1 - u;
      return (v * v * v * p0.position + (3 * u3 - 6 * u2 + 4) * p1.position +
              (-3 * u3 + 3 * u2 + 3 * u + 1) * p2.position + u3 * cp.position) / 6.0;
    };
    const dvec3 start = b(0);
    if (!(glm::length(b(1) - start) > 0)) return;
    const RadiusProfile profile(p1, p2, glm::length(b(1) - start));
    if (p1.contour != 0 || p2.contour != 0) contour_piece(c, p1, p2, profile, strips, b);
    else cylinder_piece(c, start, profile, p1.material, strips, b);
  };
  const size_t n = word.size();
  const Turn default_turn = turn_of(d.angle_deg);
  const Turn default_turn_back = turn_of(-d.angle_deg);
  auto turn = [&](const Module& m, const double* p, bool negate) {
    if (m.param_count == 0) return negate ? default_turn_back : default_turn;
    return turn_of(negate ? -p[0] : p[0]);
  };
  // Rotations keep the frame orthonormal up to rounding; re-orthonormalise every 16 of
  // them (and after tropism) so drift stays at the level of one rounding error.
  unsigned rotations = 0;
  auto rotated = [&](TurtleState& s) {
    if ((++rotations & 15u) == 0) orthonormalize(s);
    else s.up = glm::cross(s.heading, s.left);
  };
  // Strips of a piece: the parameter (at least 1, cpfg's clamp), else the cylinder's default.
  auto strips_of = [&](const Module& m, const double* p) {
    if (m.param_count == 0) return 0;
    if (!std::isfinite(p[0]) || p[0] > kMaxCylinderStrips)
      throw TurtleFailure{"a generalized cylinder's strips must be finite and at most " +
                          std::to_string(kMaxCylinderStrips)};
    return p[0] < 1 ? 1 : static_cast<int>(p[0]);  // below 1: 1, as cpfg clamps
  };
  // The turtle's open cylinder leaves the pool when it is the pool's last entry and this
  // branch's own (a finished or replaced one): sequences of cylinders do not pile up.
  auto cylinder_release = [&] {
    const size_t at = static_cast<size_t>(t.cylinder);
    if (t.cylinder >= 0 && at + 1 == cylinders.size() && (cylinder_marks.empty() || at >= cylinder_marks.back()))
      cylinders.pop_back();
  };
  auto cylinder_start = [&](bool bspline, bool closed, int default_strips, bool moves) {
    cylinder_release();  // a cylinder started while one is open replaces it (cpfg)
    GenCylinder c;
    c.bspline = bspline;
    c.closed = closed;
    c.default_strips = default_strips;
    c.parent = standing_on(t);
    cylinders.push_back(c);
    t.cylinder = static_cast<int32_t>(cylinders.size() - 1);
    t.cylinder_moves = moves;
  };
  // The turtle's place as the open cylinder's next control point (0 strips: the default).
  auto cylinder_point = [&](int strips) {
    GenCylinder& c = cylinders[static_cast<size_t>(t.cylinder)];
    const ControlPoint cp{t.position, t.heading, t.up, t.radius, t.material, t.contour,
                          t.contour_sides > 0 ? t.contour_sides : d.contour_sides, t.radius_tangent,
                          t.scale_radius_tangents};
    if (c.closed && c.first_count < (c.bspline ? 3 : 1)) c.first[static_cast<size_t>(c.first_count++)] = cp;
    cylinder_control(c, cp, strips > 0 ? strips : c.default_strips, t.tangent_start, t.tangent_end);
  };
  auto cylinder_end = [&] {
    GenCylinder& c = cylinders[static_cast<size_t>(t.cylinder)];
    // A closed curve ends where it began: its first points again (cpfg's FinishSpline).
    const std::array<ControlPoint, 3> first = c.first;
    for (int k = 0; c.closed && k < c.first_count; ++k)
      cylinder_control(c, first[static_cast<size_t>(k)], c.default_strips, t.tangent_start, t.tangent_end);
    cylinder_release();
    t.cylinder = -1;
    t.cylinder_moves = false;
  };
  {
    size_t moves = 0;
    for (const Module& m : word.modules) moves += m.symbol == kSymF;
    joints.reserve(moves + moves / 4);
  }
  size_t i = 0;
  try {
    for (; i < n; ++i) {
      if ((i & kProgressChunkMask) == 0 && i != 0) {  // between chunks of modules
        if (progress.cancelled()) return cancelled_diagnostic();
        progress.report(static_cast<double>(i) / static_cast<double>(n), "turtle");
      }
      const Module& m = word.modules[i];
      const double* p = word.params_of(m);
      const bool has = m.param_count > 0;
      if (m.symbol == sym_open && g.cpfg && has && p[0] != 0) {
        // {(type, strips): a generalized cylinder whose control points f and F set (manual 6.7.3).
        if (!(p[0] >= 1 && p[0] <= 4 && p[0] == std::floor(p[0])))
          throw TurtleFailure{"a generalized cylinder's type must be 1 to 4 (Hermite, closed Hermite, B-spline, closed B-spline)"};
        const int type = static_cast<int>(p[0]);
        const int strips = m.param_count >= 2 ? strips_of(Module{m.symbol, 1, 0}, p + 1) : 0;
        cylinder_start(type >= 3, type % 2 == 0, strips > 0 ? strips : kDefaultCylinderRings, true);
        continue;
      }
      if (m.symbol == sym_close && g.cpfg && has && p[0] != 0) {
        if (t.cylinder < 0) throw TurtleFailure{"'}(type)' without an open generalized cylinder"};
        cylinder_end();
        continue;
      }
      if (m.symbol == sym_open) {
        polygons.push_back({i, standing_on(t), t.position, {}});
        continue;
      }
      if (m.symbol == sym_vertex) {  // outside a polygon or cylinder a '.' records nothing (as in cpfg)
        if (!polygons.empty()) record_vertex(polygons.back(), t.position);
        else if (t.cylinder >= 0) cylinder_point(strips_of(m, p));  // .(strips) is @Gc(strips)
        continue;
      }
      if (m.symbol == sym_close) {
        if (polygons.empty()) throw TurtleFailure{"'}' without matching '{'"};
        OpenPolygon& polygon = polygons.back();
        std::vector<std::array<double, 3>> vertices = closed_polygon(polygon);
        if (auto problem = leaf_polygon_problem(vertices)) throw TurtleFailure{"bad leaf: " + *problem};
        add_leaf(polygon.joint, t.material, std::move(vertices));
        polygons.pop_back();
        continue;
      }
      if (m.symbol == sym_move) {  // G: move without drawing and without ending the chain
        t.position += t.heading * ((has ? p[0] : d.step) * t.scale);
        check_position(t.position);
        continue;
      }
      SymbolId symbol = m.symbol;
      if (symbol < cpfg.kind.size() && cpfg.kind[symbol] != CpfgKind::kNone) {
        switch (cpfg.kind[symbol]) {
          case CpfgKind::kDraw: symbol = kSymF; break;   // G: move and draw, no polygon vertex
          case CpfgKind::kMove: symbol = kSymf; break;   // g: move without drawing, no vertex
          case CpfgKind::kColorUp:
          case CpfgKind::kColorDown:
          case CpfgKind::kBackColorUp:
          case CpfgKind::kBackColorDown: {
            // A parameter is truncated toward zero, as cpfg's (int) cast; an index that steps
            // past either end of the 256-entry colour map comes round once (interpret.c). @;
            // and @, step the back's by the view file's second colour increment (blackbox.c).
            const CpfgKind kind = cpfg.kind[symbol];
            const bool back = kind == CpfgKind::kBackColorUp || kind == CpfgKind::kBackColorDown;
            const bool up = kind == CpfgKind::kColorUp || kind == CpfgKind::kBackColorUp;
            uint32_t& index = back ? t.back_material : t.material;
            double next = has ? std::trunc(p[0])
                              : static_cast<double>(index) +
                                    (up ? 1.0 : -1.0) * (back ? d.color_increment_back : d.color_increment);
            if (up && next > 255) next -= 256;
            else if (!up && next < 0) next += 256;
            if (!(next >= 0) || next != std::floor(next) || next > 4294967295.0)
              throw TurtleFailure{"a colour index must be an integer from 0 to 4294967295"};
            index = static_cast<uint32_t>(next);
            continue;
          }
          case CpfgKind::kWidthUp:
          case CpfgKind::kWidthDown: {
            const double sign = cpfg.kind[symbol] == CpfgKind::kWidthUp ? 1.0 : -1.0;
            // cpfg scales a width set or stepped by the turtle's scale (interpret.c).
            t.radius = has ? p[0] * d.width_scale * t.scale
                           : t.radius + sign * d.width_increment * d.width_scale * t.scale;
            if (!(t.radius >= 0) || !std::isfinite(t.radius)) throw TurtleFailure{"the line width must be finite and not negative"};
            if (t.radius > kMaxCoordinateM) throw TurtleFailure{"the radius exceeds the limit of 1e12 m (docs/limits.md)"};
            continue;
          }
          case CpfgKind::kLevel: symbol = kSymLevel; break;  // @v: U as close to up as H allows
          case CpfgKind::kSetPosition: {
            if (m.param_count < 3) throw TurtleFailure{"@M needs the position: @M(x, y, z)"};
            t.position = dvec3(p[0], p[1], p[2]);
            check_position(t.position);
            t.chain = -1;  // as after f: the next F starts a new chain
            t.joint = -1;
            t.branch_pending = false;
            continue;
          }
          case CpfgKind::kSetHeading:  // @R (CPFG manual 6.2)
            set_heading(t, m.param_count, p);
            continue;
          case CpfgKind::kElasticityUp:    // @T(id, v) / @Ti(id, v): tropism id's elasticity + v (or + its S:)
          case CpfgKind::kElasticityDown:  // @Td(id, v): − v (or − S:)
          case CpfgKind::kElasticitySet: {  // @Ts(id, v): v (or 0) — all for the rest of the branch
            if (!has) continue;  // as cpfg: without the id nothing changes
            const double id = p[0];
            if (!(id >= 1) || id != std::floor(id) || id > static_cast<double>(cpfg_tropisms.size()))
              throw TurtleFailure{g.symbols.name(m.symbol) + "'s first parameter is a tropism id from 1 to " +
                                  std::to_string(cpfg_tropisms.size()) + " (the view file's tropism: lines)"};
            const size_t i = static_cast<size_t>(id) - 1;
            const CpfgKind kind = cpfg.kind[symbol];
            const double value = m.param_count >= 2 ? p[1] : kind == CpfgKind::kElasticitySet ? 0.0 : cpfg_tropisms[i].step;
            if (!std::isfinite(value)) throw TurtleFailure{"an elasticity must be finite"};
            t.elasticity[i] = kind == CpfgKind::kElasticitySet ? value
                              : kind == CpfgKind::kElasticityUp ? t.elasticity[i] + value
                                                                : t.elasticity[i] - value;
            continue;
          }
          case CpfgKind::kForceTwist:  // @Tf (manual 6.8): the rolls so far stay (cpfg's prev frame := the frame)
            t.prev_heading = t.heading;
            t.prev_up = t.up;
            continue;
          case CpfgKind::kSubCall:  // ?(label, s) (CPFG manual 7.2; interpret.c's UpdateCurrentLsystem)
          case CpfgKind::kSubEnd: {  // $: back to the scale before the call; an unmatched $ is ignored
            const bool call = cpfg.kind[symbol] == CpfgKind::kSubCall;
            if (call && !has) continue;  // a bare ? is no call
            if (!call && sub_scales.empty()) continue;
            const double before = sub_scales.empty() ? d.initial_scale : sub_scales.back();
            if (call) {
              const double next = m.param_count >= 2 ? before * p[1] : before;
              if (!std::isfinite(next) || std::abs(next) > kMaxCoordinateM)
                throw TurtleFailure{"the turtle's scale must be finite and at most 1e12"};
              sub_scales.push_back(next);
            } else {
              sub_scales.pop_back();
            }
            // cpfg's turtle takes the stack's scale, and its line width in proportion.
            const double now = sub_scales.empty() ? d.initial_scale : sub_scales.back();
            if (before != 0) t.radius = t.radius * now / before;
            t.scale = now;
            continue;
          }
          case CpfgKind::kScaleSet:    // @D(s): the scale is s (CPFG manual 6.3)
          case CpfgKind::kScaleUp:     // @Di(s): times s, else times the view file's scale multiplier
          case CpfgKind::kScaleDown: {  // @Dd(s): over s, else over the multiplier
            // As cpfg's source does it (blackbox.c): @Di(s) and @Dd(s) multiply and divide by s.
            const CpfgKind kind = cpfg.kind[symbol];
            if (kind == CpfgKind::kScaleSet && !has) throw TurtleFailure{"@D needs the scale: @D(s)"};
            const double factor = has ? p[0] : d.scale_multiplier;
            if (kind != CpfgKind::kScaleSet && factor == 0)
              throw TurtleFailure{"the factor of " + g.symbols.name(m.symbol) + " must not be 0"};
            const double next = kind == CpfgKind::kScaleSet ? factor
                                : kind == CpfgKind::kScaleUp ? t.scale * factor
                                                             : t.scale / factor;
            if (!std::isfinite(next) || std::abs(next) > kMaxCoordinateM)
              throw TurtleFailure{"the turtle's scale must be finite and at most 1e12"};
            t.scale = next;
            continue;
          }
          case CpfgKind::kCircle:  // @c(d): a disc of diameter d in the HL plane (CPFG manual 6.6)
          case CpfgKind::kSphere: {  // @O(d): a sphere of diameter d
            // Diameter: the parameter, else the current line width (the drawn diameter).
            const double radius = has ? 0.5 * p[0] * t.scale : t.radius;
            if (!std::isfinite(radius) || radius > kMaxCoordinateM)
              throw TurtleFailure{"a diameter must be finite and at most 2e12 m"};
            if (!(radius > 0)) continue;  // 0 or negative: nothing drawn (cpfg draws no sphere)
            const std::optional<ChainParent> at = standing_on(t);
            if (cpfg.kind[symbol] == CpfgKind::kCircle) {
              // A leaf: kCircleSides vertices around the turtle in the plane of H and L.
              std::vector<std::array<double, 3>> vertices;
              for (int k = 0; k < kCircleSides; ++k) {
                const double a = 2 * kPi * k / kCircleSides;
                const dvec3 v = t.position + radius * (std::cos(a) * t.heading + std::sin(a) * t.left);
                check_position(v);
                vertices.push_back({v.x, v.y, v.z});
              }
              add_leaf(at, t.material, std::move(vertices));
              continue;
            }
            // A chain of its own, hung from the joint the turtle stands on: kSphereSegments
            // frusta along H through the turtle's position, the profile inscribed in the
            // circle of the radius (tips at both poles). The turtle does not move.
            const uint32_t c = new_chain(kSphereSegments + 1, at);
            for (int k = 0; k <= kSphereSegments; ++k) {
              const double a = kPi * k / kSphereSegments;
              const dvec3 v = t.position - radius * std::cos(a) * t.heading;
              check_position(v);
              const double r = k == 0 || k == kSphereSegments ? 0.0 : radius * std::sin(a);
              joints.push_back({c, Joint{{v.x, v.y, v.z}, r, t.material}});
            }
            continue;
          }
          case CpfgKind::kCylinderStart:  // @Gs: a Hermite cylinder from here ({(1) with this point)
            cylinder_start(false, false, 1, false);
            cylinder_point(0);
            continue;
          case CpfgKind::kCylinderPoint:  // @Gc(strips): a control point (starting a cylinder if none is open)
          case CpfgKind::kCylinderEnd: {  // @Ge(strips): the last one
            if (t.cylinder < 0) cylinder_start(false, false, 1, false);
            cylinder_point(strips_of(m, p));
            if (cpfg.kind[symbol] == CpfgKind::kCylinderEnd) cylinder_end();
            continue;
          }
          case CpfgKind::kRadiusTangents: {  // @Gr(flag) or @Gr(angle, length[, angle2, length2]) (manual 6.7.3)
            if (m.param_count == 1) {
              t.scale_radius_tangents = p[0] != 0;
            } else if (m.param_count >= 2) {
              for (uint32_t k = 0; k < std::min<uint32_t>(m.param_count, 4); ++k)
                if (!std::isfinite(p[k]) || std::abs(p[k]) > 1e12) throw TurtleFailure{"@Gr's angles and lengths must be finite"};
              auto tangent = [](double angle, double length) {
                return glm::dvec2(lsys::cos_deg(angle) * length, lsys::sin_deg(angle) * length);
              };
              t.radius_tangent[0] = t.radius_tangent[1] = tangent(p[0], p[1]);
              if (m.param_count >= 4) t.radius_tangent[1] = tangent(p[2], p[3]);
            }
            continue;
          }
          case CpfgKind::kCylinderTangents:  // @Gt(start, end): Hermite tangent coefficients (one: both)
            if (has) {
              const double a = p[0], b = m.param_count > 1 ? p[1] : p[0];
              if (!std::isfinite(a) || !std::isfinite(b) || std::abs(a) > 1e6 || std::abs(b) > 1e6)
                throw TurtleFailure{"@Gt's tangent coefficients must be finite and at most 1e6"};
              t.tangent_start = a;
              t.tangent_end = b;
            }
            continue;
          case CpfgKind::kCylinderSides:  // @!(n): the points around a contour (frusta are round)
            if (has) {
              if (!(p[0] >= 3) || !(p[0] <= lsys::kMaxContourSides))
                throw TurtleFailure{"@!(n) takes 3 to " + std::to_string(lsys::kMaxContourSides) + " sides"};
              t.contour_sides = static_cast<int>(p[0]);
            }
            continue;
          case CpfgKind::kCylinderContour:  // @#(id): the view file's contour id; 0 (or none) the circle
            if (!has || p[0] == 0) {
              t.contour = 0;
            } else {
              if (p[0] != std::floor(p[0]) || std::abs(p[0]) > 1e6) throw TurtleFailure{"@#(id) takes a contour's id, a whole number"};
              check_contour(static_cast<int>(p[0]));  // one of the view file's, or an error here
              t.contour = static_cast<int>(p[0]);
            }
            continue;
          case CpfgKind::kSurface: {
            // ~X(s) or ~X(sx, sy, sz) (CPFG manual 6.7.1): the view file's surface X at the
            // turtle, its x along L, y along H, z along cpfg's up, scaled by s and
            // the turtle's scale; one polygon leaf per grid cell (two triangles where the
            // cell is not flat), or per triangle of a tsurface. The module after `~` names the surface and carries the
            // scale; a surface the view file does not define draws nothing, as in cpfg.
            if (i + 1 >= n) continue;
            const Module& id_module = word.modules[++i];
            const double* q = word.params_of(id_module);
            const std::string& id_name = g.symbols.name(id_module.symbol);
            const lsys::CpfgSurface* surface = nullptr;
            for (const lsys::CpfgSurface& candidate : g.surfaces)
              if (id_name.size() == 1 && id_name[0] == candidate.id) surface = &candidate;
            if (!surface) continue;
            dvec3 size(1, 1, 1);
            if (id_module.param_count >= 3) size = dvec3(q[0], q[1], q[2]);
            else if (id_module.param_count >= 1) size = dvec3(q[0]);
            size *= t.scale;
            if (!std::isfinite(size.x) || !std::isfinite(size.y) || !std::isfinite(size.z) ||
                std::max({std::abs(size.x), std::abs(size.y), std::abs(size.z)}) > kMaxCoordinateM)
              throw TurtleFailure{"a surface's scale must be finite and at most 2e12"};
            if (size.x == 0 || size.y == 0 || size.z == 0) continue;  // cpfg draws nothing
            // cpfg's frame is sylva's with the up vector reversed (cpfg starts with U = −z,
            // sylva with +z; their left and heading agree): x along L, z along cpfg's U = −U.
            auto place = [&](const std::array<double, 3>& v) {
              const dvec3 w = t.position + size.x * v[0] * t.left + size.y * v[1] * t.heading - size.z * v[2] * t.up;
              check_position(w);
              return std::array<double, 3>{w.x, w.y, w.z};
            };
            const std::optional<ChainParent> at = standing_on(t);
            for (const auto& tri : surface->triangles)  // a tsurface: one leaf a triangle
              add_cell(at, t.material, {place(tri[0]), place(tri[1]), place(tri[2])});
            const int columns = surface->t_cells + 1;
            for (const auto& grid : surface->patches)
              for (int a = 0; a < surface->s_cells; ++a)
                for (int b = 0; b < surface->t_cells; ++b) {
                  const auto corner = [&](int da, int db) { return place(grid[static_cast<size_t>((a + da) * columns + b + db)]); };
                  add_cell(at, t.material, {corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)});
                }
            continue;
          }
          case CpfgKind::kPatchInit:
          case CpfgKind::kPatchPoint:
          case CpfgKind::kPatchDraw: {
            const CpfgKind kind = cpfg.kind[symbol];
            const std::string name = g.symbols.name(m.symbol);
            if (!has) throw TurtleFailure{name + " needs the surface's id"};
            TurtlePatch& patch = turtle_patches[p[0]];
            if (kind == CpfgKind::kPatchInit) {
              patch = TurtlePatch{};
              // Its basis: 1 Bézier, 2 B-spline, 3 Cardinal; another (or none) Bézier, as patches.c.
              if (m.param_count >= 2 && p[1] >= 1 && p[1] <= 3) patch.basis = static_cast<int>(p[1]);
              continue;
            }
            if (kind == CpfgKind::kPatchPoint) {
              if (m.param_count < 3) throw TurtleFailure{"@PC needs the surface's id, row and column: @PC(id, r, c)"};
              if (!(p[1] >= 0 && p[1] < 4 && p[2] >= 0 && p[2] < 4))
                throw TurtleFailure{"@PC's row and column are 0 to 3 (a 4 x 4 patch)"};
              const size_t k = static_cast<size_t>(4 * static_cast<int>(p[1]) + static_cast<int>(p[2]));
              patch.points[k] = t.position;
              patch.set[k] = true;
              continue;
            }
            // @PD(id, s, t): every control point set, else nothing drawn (patches.c warns);
            // the s x t cells (at most 10 each, 5 without them) are polygon leaves.
            if (std::find(patch.set.begin(), patch.set.end(), false) != patch.set.end()) continue;
            int cells[2] = {kPatchMaxPrecision / 2, kPatchMaxPrecision / 2};
            if (m.param_count >= 3)
              for (int k = 0; k < 2; ++k) {
                if (!(p[1 + k] >= 1)) throw TurtleFailure{"@PD's s and t are counts of lines, 1 or more"};
                cells[k] = static_cast<int>(std::min<double>(p[1 + k], kPatchMaxPrecision));
              }
            const std::optional<ChainParent> at = standing_on(t);
            auto corner = [&](int a, int b) {
              const dvec3 v = patch_point(patch, static_cast<double>(a) / cells[0], static_cast<double>(b) / cells[1]);
              check_position(v);
              return std::array<double, 3>{v.x, v.y, v.z};
            };
            for (int a = 0; a < cells[0]; ++a)
              for (int b = 0; b < cells[1]; ++b)
                add_cell(at, t.material, {corner(a, b), corner(a + 1, b), corner(a + 1, b + 1), corner(a, b + 1)});
            continue;
          }
          case CpfgKind::kRing: {
            // @bc(d) (and @bo(d)): a circle's boundary of diameter d (else the line width) in
            // the plane of H and L, the line as wide as the current line width: a closed chain
            // of kCircleSides frusta hung from the joint the turtle stands on. It does not move.
            const double radius = has ? 0.5 * p[0] * t.scale : t.radius;
            if (!std::isfinite(radius) || radius > kMaxCoordinateM)
              throw TurtleFailure{"a diameter must be finite and at most 2e12 m"};
            if (!(radius > 0) || !(t.radius > 0)) continue;  // no circle, or no line width: nothing drawn
            const std::optional<ChainParent> at = standing_on(t);
            const uint32_t c = new_chain(kCircleSides + 1, at);
            for (int k = 0; k <= kCircleSides; ++k) {
              const double a = 2 * kPi * (k % kCircleSides) / kCircleSides;
              const dvec3 v = t.position + radius * (std::cos(a) * t.heading + std::sin(a) * t.left);
              check_position(v);
              joints.push_back({c, Joint{{v.x, v.y, v.z}, t.radius, t.material}});
            }
            continue;
          }
          case CpfgKind::kNone: break;
        }
      }
      // A cpfg file's view-file tropism turns the turtle before every F, G, f and g (cpfg's
      // movement_adjust); sylva's own format bends after every F (ABOP 2.2, below).
      if (!cpfg_tropisms.empty() && (symbol == kSymF || symbol == kSymf)) cpfg_bend(t, cpfg_tropisms);
      if ((symbol == kSymF || symbol == kSymf) && !polygons.empty() && symbol == m.symbol) {
        // Inside a polygon F and f move without drawing, keep the chain, and record the
        // turtle's new position as the polygon's next vertex (cpfg; docs/spec/grammar.md).
        const double len = (has ? p[0] : d.step) * t.scale;
        if (len == 0) ++zero_moves;
        t.position += t.heading * len;
        check_position(t.position);
        record_vertex(polygons.back(), t.position);
        if (g.cpfg && symbol == kSymF) t.prev_heading = t.heading, t.prev_up = t.up;
        continue;
      }
      switch (symbol) {
        case kSymF: {
          const double len = (has ? p[0] : d.step) * t.scale;
          if (g.cpfg) t.prev_heading = t.heading, t.prev_up = t.up;  // cpfg: the frame of the last F or G
          if (len == 0) {
            ++zero_moves;
            break;
          }
          const bool start_chain = t.chain < 0 || t.branch_pending ||
                                   t.joint + 1 != static_cast<int64_t>(chain_joint_count[t.chain]);
          if (start_chain) {
            const uint32_t c = new_chain(1, standing_on(t));
            joints.push_back({c, Joint{{t.position.x, t.position.y, t.position.z}, t.radius, t.material}});
            t.chain = c;
            t.joint = 0;
            t.branch_pending = false;
          }
          t.position += t.heading * len;
          check_position(t.position);
          if (chain_joint_count[t.chain] == 0xFFFFFFFFu) throw TurtleFailure{"a chain has too many joints"};
          joints.push_back({static_cast<uint32_t>(t.chain),
                            Joint{{t.position.x, t.position.y, t.position.z}, t.radius, t.material}});
          ++chain_joint_count[t.chain];
          ++t.joint;
          if (t.tropism_e != 0.0) {  // 0 in a cpfg file: cpfg_bend does its bending
            // ABOP 2.2: rotate the frame about H × T by e·|H × T|.
            const dvec3 axis = glm::cross(t.heading, t.tropism);
            const double len_axis = glm::length(axis);
            if (len_axis > 1e-12) {
              const dvec3 k = axis / len_axis;
              const double alpha = t.tropism_e * len_axis;
              t.heading = rotate_about(t.heading, k, alpha);
              t.left = rotate_about(t.left, k, alpha);
              orthonormalize(t);
            }
          }
          break;
        }
        case kSymf: {
          const double len = (has ? p[0] : d.step) * t.scale;
          if (len == 0) ++zero_moves;
          t.position += t.heading * len;
          check_position(t.position);
          t.chain = -1;
          t.joint = -1;
          t.branch_pending = false;
          break;
        }
        case kSymTurnLeft: rotate_pair(t.heading, t.left, turn(m, p, false)); rotated(t); break;
        case kSymTurnRight: rotate_pair(t.heading, t.left, turn(m, p, true)); rotated(t); break;
        case kSymPitchDown: rotate_pair(t.heading, t.up, turn(m, p, true)); rotated(t); break;  // H toward −U
        case kSymPitchUp: rotate_pair(t.heading, t.up, turn(m, p, false)); rotated(t); break;
        case kSymRollLeft: {  // U toward L; H is unchanged, so recompute L from U and H
          rotate_pair(t.up, t.left, turn(m, p, false));
          if ((++rotations & 15u) == 0) orthonormalize(t);
          break;
        }
        case kSymRollRight: {
          rotate_pair(t.up, t.left, turn(m, p, true));
          if ((++rotations & 15u) == 0) orthonormalize(t);
          break;
        }
        case kSymTurnAround:
          t.heading = -t.heading;
          t.left = -t.left;
          break;
        case kSymLevel: {
          // ABOP 2.2: L = (V × H) / |V × H|, U = H × L, with V = +Y.
          const dvec3 v(0, 1, 0);
          const dvec3 c = glm::cross(v, t.heading);
          const double len = glm::length(c);
          if (len > 1e-9) {
            t.left = c / len;
            t.up = glm::cross(t.heading, t.left);
          }
          break;
        }
        case kSymCut:
          // A % left in a cpfg file's word (cpfg cuts one step later, docs/cpfg.md): passed
          // over, or with the view file's `interpretation past %: off` the rest of its branch.
          if (g.cpfg && !d.interpret_past_cut) {
            int depth = 0;
            for (; i + 1 < n; ++i) {
              const SymbolId s = word.modules[i + 1].symbol;
              if (s == kSymPush) ++depth;
              else if (s == kSymPop && depth-- == 0) break;
            }
          }
          break;
        case kSymPush:
          stack.push_back(t);
          t.branch_pending = true;
          if (g.cpfg) {
            cylinder_marks.push_back(cylinders.size());
            if (t.cylinder >= 0) {  // the branch draws on a copy of the open cylinder
              cylinders.push_back(cylinders[static_cast<size_t>(t.cylinder)]);
              t.cylinder = static_cast<int32_t>(cylinders.size() - 1);
            }
          }
          break;
        case kSymPop:
          if (stack.empty()) throw TurtleFailure{"']' without matching '['"};
          t = stack.back();
          stack.pop_back();
          if (g.cpfg && !cylinder_marks.empty()) {
            cylinders.resize(cylinder_marks.back());
            cylinder_marks.pop_back();
          }
          break;
        case kSymWidth:
          if (has) t.radius = p[0];
          else t.radius *= d.width_decrement;
          if (!(t.radius >= 0) || !std::isfinite(t.radius)) throw TurtleFailure{"the radius must be finite and not negative"};
          if (t.radius > kMaxCoordinateM) throw TurtleFailure{"the radius exceeds the limit of 1e12 m (docs/limits.md)"};
          break;
        case kSymMaterial:
          if (has) {
            if (!(p[0] >= 0) || p[0] != std::floor(p[0]) || p[0] > 4294967295.0)
              throw TurtleFailure{"a material index must be a non-negative integer"};
            t.material = static_cast<uint32_t>(p[0]);
          } else {
            if (t.material == 0xFFFFFFFFu) throw TurtleFailure{"material index overflow"};
            ++t.material;
          }
          break;
        case kSymTropism:
          if (!has) throw TurtleFailure{"@T needs the susceptibility: @T(e)"};
          t.tropism_e = p[0];
          break;
        case kSymTropismVector:  // the parser holds its arity at 3 (or 0 in a cpfg file)
          if (m.param_count == 0) {  // cpfg's bare @Tp (manual 6.8): the up from the last segment's frame
            adjust_up_and_left(t, t.heading);
            break;
          }
          t.tropism = dvec3(p[0], p[1], p[2]);
          if (!std::isfinite(t.tropism.x) || !std::isfinite(t.tropism.y) || !std::isfinite(t.tropism.z))
            throw TurtleFailure{"the tropism vector must be finite"};
          break;
        case kSymLightQuery:
          if (queries) queries->push_back(t.position);
          break;
        case kSymQueryPosition:
        case kSymQueryHeading:
        case kSymQueryLeft:
        case kSymQueryUp:
          if (turtle_queries) {
            const dvec3* answer[] = {&t.position, &t.heading, &t.left, &t.up};  // in BuiltinSymbol order
            turtle_queries->push_back(*answer[symbol - kSymQueryPosition]);
          }
          break;
        default:
          break;  // carried through, ignored by the turtle
      }
      // Inside {(type) ... }(type) every f and F (not g, G) is also a control point.
      if (t.cylinder >= 0 && t.cylinder_moves && (symbol == kSymF || symbol == kSymf) && symbol == m.symbol)
        cylinder_point(0);
    }
    if (!polygons.empty()) {
      i = polygons.back().module;
      throw TurtleFailure{"'{' without matching '}'"};
    }
  } catch (const TurtleFailure& f) {
    Word one;
    const Module& m = word.modules[i];
    one.modules.push_back(Module{m.symbol, m.param_count, 0});
    one.params.assign(word.params_of(m), word.params_of(m) + m.param_count);
    const std::string module = print_word(one, g.symbols);
    const std::string message =
        "turtle: " + f.message + " at module " + std::to_string(i) + " (" + module + ") of the interpreted word";
    // The error at the one place that writes the module; where several could have, at the
    // file, with a note at each of them.
    const std::vector<SourceLoc> places = places_writing(g, m.symbol);
    if (places.size() == 1) return g.error_at(places[0], message + ", written here");
    Diagnostic d = g.error_at({}, message);
    constexpr size_t kMaxNotes = 4;
    for (size_t k = 0; k < places.size() && k < kMaxNotes; ++k)
      d = std::move(d).with_note(g.error_at(places[k], "a module '" + g.symbols.name(m.symbol) + "' is written here"));
    if (places.size() > kMaxNotes)
      d = std::move(d).with_note(g.error_at({}, "and by " + std::to_string(places.size() - kMaxNotes) +
                                                    " more productions"));
    return d;
  }

  // Flatten: chains' joints were interleaved in creation order; a counting sort by chain
  // keeps each chain's joints in order and makes every chain one contiguous range.
  Skeleton sk;
  sk.chains.resize(chain_joint_count.size());
  uint32_t offset = 0;
  for (size_t c = 0; c < chain_joint_count.size(); ++c) {
    sk.chains[c] = Chain{offset, 0, chain_parent[c]};
    offset += chain_joint_count[c];
  }
  sk.leaves = std::move(leaves);
  sk.joints.resize(joints.size());
  for (const PendingJoint& pj : joints) {
    Chain& c = sk.chains[pj.chain];
    sk.joints[c.first_joint + c.joint_count++] = pj.joint;
  }
  if (stats) {
    stats->zero_length_moves = zero_moves;
    stats->modules_read = n;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  progress.report(1, "turtle");
  return sk;
}

}  // namespace sylva
