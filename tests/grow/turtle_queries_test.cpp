// Tests for the turtle's queries ?P, ?H, ?L and ?U (CPFG manual 6.9; docs/cpfg.md): filled
// after the axiom and after every step from the turtle's state where each stands, read by
// the next step's conditions and context, in sylva files and cpfg files alike; arity and
// homomorphism errors; light never traced for them.
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/grow/grow.h"
#include "lsystem/vlab_object.h"

namespace sylva {
namespace {

lsys::Grammar parsed(const std::string& text, const std::string& file = "queries.lsys") {
  auto g = lsys::parse_grammar(text, file);
  if (!g) ADD_FAILURE() << g.error().format();
  return g ? std::move(*g) : lsys::Grammar{};
}

Expected<lsys::Word> derived_word(const lsys::Grammar& g, int64_t steps) {
  lsys::DeriveOptions o;
  o.steps = steps;
  return derive_word(g, o);
}

std::string derived(const lsys::Grammar& g, int64_t steps) {
  auto w = derived_word(g, steps);
  if (!w) return "error: " + w.error().message;
  return lsys::print_word(*w, g.symbols);
}

// The parameters of the n-th module with `symbol` in `word`.
std::vector<double> params_of(const lsys::Word& word, lsys::SymbolId symbol, size_t n = 0) {
  for (const lsys::Module& m : word.modules)
    if (m.symbol == symbol && n-- == 0) return {word.params_of(m), word.params_of(m) + m.param_count};
  return {};
}

// A vlab object in a fresh folder whose environmental program is vlab's honda81 (its
// ENVIRO/honda81): `axiom` as the model, `environment` as field.e, `spec` as density.spec.
std::string grown_in_honda81(const std::string& axiom, const std::string& environment, const std::string& spec) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("sylva_honda81_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "specifications") << "generate:\n\tcpfg -m plant.map -e field.e plant.l plant.v\n";
  std::ofstream(dir / "plant.l") << "Lsystem: 1\nderivation length: 1\nAxiom: " << axiom << "\nendlsystem\n";
  std::ofstream(dir / "plant.v") << "angle increment: 90\n";
  std::ofstream(dir / "field.e") << environment;
  std::ofstream(dir / "density.spec") << spec;
  auto g = lsys::load_grammar(dir.string());
  std::string out;
  if (!g) {
    out = "error: " + g.error().format();
  } else {
    auto w = derived_word(*g, 1);
    out = w ? lsys::print_word(*w, g->symbols) : "error: " + w.error().message;
  }
  fs::remove_all(dir);
  return out;
}

// honda81 answers ?E(vigor[, index]) with 0 where another query of the same index and at
// least its vigor lies within the radius, else 1 (in x, y and z with `3d case: on`, else in x
// and z); cpfg writes positions with the .e file's conversions when it talks through files.
TEST(TurtleQueries, Honda81AnswersEByTheQueriesWithinItsRadius) {
  const std::string memory = "executable: honda81 density.spec\ncommunication type: memory\nturtle position:P:%g %g %g\n";
  // At y = 0 and 0.3 (vigor 1): each sees the other, 0. At y = 1.3 (vigor 2): none as
  // vigorous, 1. Index 1 at x = -0.1 beside it: alone in its index, 1.
  EXPECT_EQ(grown_in_honda81("?E(1)f(0.3)?E(1)f(1)?E(2)[+f(0.1)?E(1,1)]", memory, "radius: 0.5\n3d case: on\n"),
            "?E(0)f(0.3)?E(0)f(1)?E(1)[+f(0.1)?E(1,1)]");
  // Written through files as "%.0f": 0.4 and 0.6 are sent as 0 and 1, farther than 0.5.
  const std::string files = "executable: honda81 density.spec\ncommunication type: files\nturtle position:P:%.0f %.0f %.0f\n";
  EXPECT_EQ(grown_in_honda81("f(0.4)?E(1)f(0.2)?E(1)", memory, "radius: 0.5\n3d case: on\n"), "f(0.4)?E(0)f(0.2)?E(0)");
  EXPECT_EQ(grown_in_honda81("f(0.4)?E(1)f(0.2)?E(1)", files, "radius: 0.5\n3d case: on\n"), "f(0.4)?E(1)f(0.2)?E(1)");
  // Without `3d case: on` only x and z count: 5 apart along y is no distance.
  EXPECT_EQ(grown_in_honda81("?E(1)f(5)?E(1)", memory, "radius: 0.5\n3d case: on\n"), "?E(1)f(5)?E(1)");
  EXPECT_EQ(grown_in_honda81("?E(1)f(5)?E(1)", memory, "radius: 0.5\n"), "?E(0)f(5)?E(0)");
  // A radius far below the positions' scale (the neighbour grid's cells stay in range).
  EXPECT_EQ(grown_in_honda81("?E(1)f(1e9)?E(1)", memory, "radius: 1e-300\n3d case: on\n"), "?E(1)f(1e+09)?E(1)");
  // Another program is an error at the -e, the program named; honda81's own mistakes at theirs.
  const std::string clover = grown_in_honda81("?E(1)", "executable: clover -e x.e light.spec\n", "");
  EXPECT_NE(clover.find("specifications:2:20"), std::string::npos) << clover;
  EXPECT_NE(clover.find("'clover'"), std::string::npos) << clover;
  const std::string radius = grown_in_honda81("?E(1)", memory, "radius: -1\n");
  EXPECT_NE(radius.find("density.spec:1:9"), std::string::npos) << radius;
  EXPECT_NE(grown_in_honda81("?E(1)", "executable: honda81 density.spec\n", "radius: 1\n").find("turtle's position"),
            std::string::npos);
}

// chiba answers ?E(r) with the light reaching a ball of radius r where the turtle meets it,
// and ?E(r, x, y, z) with the brightest direction too; other counts are left as they are.
// Straight up through three balls of radius 0.9 one apart, transmittance 0.25 and no beam:
// each ball above dims by 0.25^(1.8 / 1.8).
TEST(TurtleQueries, ChibaAnswersEWithTheLightReachingItsBall) {
  const std::string memory = "executable: chiba -e field.e density.spec\ncommunication type: memory\n"
                             "turtle position:P:%g %g %g\n";
  const std::string spec = "grid size: 32x32x32\ntransmittance: 0.25\nsource direction: 0 100 0 4\n";
  EXPECT_EQ(grown_in_honda81("?E(0.9)f(1)?E(0.9,0,0,0)f(1)?E(0.9)?E(1,1)", memory, spec),
            "?E(0.0625)f(1)?E(0.25,0,1,0)f(1)?E(1)?E(1,1)");
  // A radius of 0 is the spec's (`radius:`): 0.1, too small for the ray straight up to meet
  // a ball 0.3 beside it; by default 25, each dims the other's light by the part of the ray
  // inside it, 0.25^(25.998 / 50) and 0.25^(23.998 / 50). (The answer stays in the query as
  // the next step's radius: the production asks with 0 again.)
  const std::string again = "?E(0)f(1)+f(0.3)?E(0)\n?E(r) --> ?E(0)";
  EXPECT_EQ(grown_in_honda81(again, memory, spec + "radius: 0.1\n"), "?E(1)f(1)+f(0.3)?E(1)");
  const std::string wide = grown_in_honda81(again, memory, spec);
  EXPECT_EQ(wide.substr(0, 8), "?E(0.486") << wide;
  EXPECT_NE(wide.find("?E(0.514"), std::string::npos) << wide;
  const std::string bad = grown_in_honda81("?E(1)", memory, "transmittance: 2\n");
  EXPECT_NE(bad.find("density.spec:1:16"), std::string::npos) << bad;
  EXPECT_NE(grown_in_honda81("?E(1)", memory, "source direction: 0 0 0 1\n").find("must not be zero"),
            std::string::npos);
}

// The word a vlab object of `model` and `view` derives in `steps` steps.
std::string grown_object(const std::string& model, const std::string& view, int64_t steps = 1) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("sylva_object_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "specifications") << "generate:\n\tcpfg plant.l plant.v\n";
  std::ofstream(dir / "plant.l") << model;
  std::ofstream(dir / "plant.v") << view;
  auto g = lsys::load_grammar(dir.string());
  fs::remove_all(dir);
  if (!g) return "error: " + g.error().format();
  auto w = derived_word(*g, steps);
  return w ? lsys::print_word(*w, g->symbols) : "error: " + w.error().message;
}

// A view file's torque (CPFG manual 8.1.8, cpfg's movement_adjust) twists the turtle about its
// heading before every move: the up vector turns by |U × D'| (at most 1 radian) toward D', the
// torque's e·T across H, and comes to rest along it; the heading never changes. From U = +z
// with T = +x and E 1: after one F, U = (sin 1, 0, cos 1); after three, along +x.
TEST(TurtleQueries, CpfgTorqueTwistsTheUpVectorTowardItsVectorAcrossTheHeading) {
  const std::string model = "Lsystem: 1\nderivation length: 1\nAxiom: F ?U(0,0,0) F F ?U(0,0,0) ?H(0,0,0)\nendlsystem\n";
  std::string turned = "?U(";
  lsys::append_shortest_double(turned, std::sin(1.0));
  turned += ",0,";
  lsys::append_shortest_double(turned, std::cos(1.0));
  turned += ")";
  const std::string word = grown_object(model, "torque: T: 1 0 0 E: 1\n");
  EXPECT_EQ(word.substr(0, 1 + turned.size()), "F" + turned) << word;
  // After three moves: within 1e-4 of +x (the angle to it falls 90° → 32.7° → 1.7° → 0.0005°).
  const size_t second = word.find("?U(", word.find("?U(") + 1);
  ASSERT_NE(second, std::string::npos) << word;
  EXPECT_NEAR(std::stod(word.substr(second + 3)), 1, 1e-4) << word;
  EXPECT_NE(word.find("?H(0,1,0)"), std::string::npos) << word;  // the heading never turns
  // No elasticity, no twist; @Ts sets a torque's elasticity by its id, shared with tropisms.
  EXPECT_EQ(grown_object(model, "torque: T: 1 0 0\n").substr(0, 12), "F?U(0,0,1)FF");
  const std::string by_id = grown_object("Lsystem: 1\nderivation length: 1\nAxiom: @Ts(2, 1) F ?U(0,0,0)\nendlsystem\n",
                                         "tropism: T: 0 1 0\ntorque: T: 1 0 0\n");
  EXPECT_EQ(by_id, "@Ts(2,1)F" + turned) << "the torque is id 2";
}

TEST(TurtleQueries, PositionIsFilledAfterEveryStepAndReadByTheNextStep) {
  // The QueryPosition pattern: an apex climbs one metre a step while the position after it
  // is below 2.5 m, then stops. On the axiom ?P reads y = 0; after steps 1, 2, 3: 1, 2, 3.
  const lsys::Grammar g = parsed(
      "module: A\n"
      "axiom: A ?P(-1, -1)\n"
      "A > ?P(x, y) : y < 2.5 -> F(1) A\n");
  EXPECT_EQ(derived(g, 6), "F(1)F(1)F(1)A?P(0,3)");
  EXPECT_EQ(derived(g, 0), "A?P(0,0)") << "the axiom's queries are filled too";
}

TEST(TurtleQueries, EachQueryAnswersItsVectorOfTheTurtleWhereItStands) {
  // Turned 30 degrees (+, toward L) and pitched down 20 (&), then one metre forward: the
  // answers are the turtle's state there, which the skeleton's last segment also records.
  const lsys::Grammar g = parsed(
      "module: A\n"
      "axiom: +(30) &(20) F(1) ?P(0, 0, 0) ?H(0, 0, 0) ?L(0, 0, 0) ?U(0, 0, 0) [ /(90) ?U(0, 0, 0) ]\n");
  auto w = derived_word(g, 1);
  ASSERT_TRUE(w) << w.error().format();
  const auto p = params_of(*w, lsys::kSymQueryPosition), h = params_of(*w, lsys::kSymQueryHeading),
             l = params_of(*w, lsys::kSymQueryLeft), u = params_of(*w, lsys::kSymQueryUp),
             rolled = params_of(*w, lsys::kSymQueryUp, 1);
  ASSERT_EQ(p.size(), 3u);
  ASSERT_EQ(rolled.size(), 3u);
  auto sk = build_skeleton(*w, g);
  ASSERT_TRUE(sk);
  ASSERT_EQ(sk->joints.size(), 2u);
  const glm::dvec3 end(sk->joints[1].position_m[0], sk->joints[1].position_m[1], sk->joints[1].position_m[2]);
  const glm::dvec3 start(sk->joints[0].position_m[0], sk->joints[0].position_m[1], sk->joints[0].position_m[2]);
  const glm::dvec3 P(p[0], p[1], p[2]), H(h[0], h[1], h[2]), L(l[0], l[1], l[2]), U(u[0], u[1], u[2]);
  EXPECT_NEAR(glm::length(P - end), 0, 1e-12);
  EXPECT_NEAR(glm::length(H - glm::normalize(end - start)), 0, 1e-12);
  // An orthonormal right-handed frame (H × L = U), L turned 30° off -x and pitched with H.
  EXPECT_NEAR(glm::length(L), 1, 1e-12);
  EXPECT_NEAR(glm::dot(H, L), 0, 1e-12);
  EXPECT_NEAR(glm::length(glm::cross(H, L) - U), 0, 1e-12);
  EXPECT_GT(glm::length(L - glm::dvec3(-1, 0, 0)), 0.1);
  // /(90) rolls U toward L... so the branch's up is the trunk's ±left (the sign is the roll's).
  EXPECT_NEAR(std::abs(glm::dot(glm::dvec3(rolled[0], rolled[1], rolled[2]), L)), 1, 1e-12);
  // + turned H about U = +z, & pitched it 20° toward -U.
  EXPECT_NEAR(H.z, -std::sin(glm::radians(20.0)), 1e-12);
}

TEST(TurtleQueries, TwoParametersTakeXAndY) {
  const lsys::Grammar g = parsed("module: A\naxiom: +(90) F(2) ?H(7, 7) ?P(7, 7)\n");
  EXPECT_EQ(derived(g, 0), "+(90)F(2)?H(-1,0)?P(-2,0)");
}

TEST(TurtleQueries, ACpfgFileFillsThemTheSameWay) {
  const lsys::Grammar g = parsed(
      "Lsystem: 1\nderivation length: 3\nAxiom: A?P(0,0)\nA --> F(1)A\nendlsystem\n", "q.l");
  auto w = derived_word(g, 3);
  ASSERT_TRUE(w) << w.error().format();
  const auto p = params_of(*w, lsys::kSymQueryPosition);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NEAR(p[0], 0, 1e-12);
  EXPECT_NEAR(p[1], 3, 1e-12);
}

TEST(TurtleQueries, TheHomomorphismIsWhatTheTurtleReads) {
  // A is drawn as two metres: the query after two A's stands four metres up. A homomorphism
  // that drops a query is an error naming the counts.
  const lsys::Grammar g = parsed("module: A\naxiom: A A ?P(0, 0)\nhomomorphism:\nA -> F(2)\n");
  EXPECT_EQ(derived(g, 0), "AA?P(0,4)");
  const lsys::Grammar dropped = parsed("module: A\naxiom: A ?P(0, 0)\nhomomorphism:\n?P(x, y) -> F(1)\n");
  const std::string error = derived(dropped, 0);
  EXPECT_NE(error.find("changes the number of turtle (?P ?H ?L ?U) queries (1 in the derived word, 0 drawn)"),
            std::string::npos)
      << error;
}

TEST(TurtleQueries, AreNotLightQueriesAndNeedNoLight) {
  const lsys::Grammar g = parsed("module: A\naxiom: A ?P(0, 0)\nA -> F(1) A\n");
  EXPECT_TRUE(grammar_queries_turtle(g));
  EXPECT_FALSE(grammar_queries_light(g));
  LightGrowthStats stats;
  lsys::DeriveOptions o;
  o.steps = 2;
  auto w = derive_word(g, o, {}, &stats);
  ASSERT_TRUE(w) << w.error().format();
  EXPECT_EQ(stats.answers, 0u);
  EXPECT_FALSE(grammar_queries_turtle(parsed("module: A\naxiom: A ?E(1)\nA -> F(1) A\n")));
}

// The three vectors a cpfg axiom's ?P? modules receive: `axiom` followed by ?H, ?L and ?U.
std::array<glm::dvec3, 3> frame_after(const std::string& axiom) {
  const lsys::Grammar g =
      parsed("Lsystem: 1\nderivation length: 0\nAxiom: " + axiom + "?H(0,0,0)?L(0,0,0)?U(0,0,0)\nendlsystem\n", "r.l");
  auto w = derived_word(g, 0);
  if (!w) {
    ADD_FAILURE() << w.error().format();
    return {};
  }
  std::array<glm::dvec3, 3> out;
  const lsys::SymbolId ids[3] = {lsys::kSymQueryHeading, lsys::kSymQueryLeft, lsys::kSymQueryUp};
  for (int k = 0; k < 3; ++k) {
    const auto v = params_of(*w, ids[k]);
    if (v.size() == 3) out[static_cast<size_t>(k)] = {v[0], v[1], v[2]};
  }
  return out;
}

bool near(const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b) < 1e-12; }

// Position, heading, left and up after `axiom` in a cpfg file, its grammar changed by `set`
// first (the turtle settings a view file would give); an error goes to *error, else fails.
std::array<glm::dvec3, 4> cpfg_frame_after(const std::string& axiom, const std::function<void(lsys::Grammar&)>& set,
                                           std::string* error = nullptr) {
  lsys::Grammar g = parsed("Lsystem: 1\nderivation length: 0\nAxiom: " + axiom +
                               "?P(0,0,0)?H(0,0,0)?L(0,0,0)?U(0,0,0)\nendlsystem\n",
                           "t.l");
  set(g);
  auto w = derived_word(g, 0);
  if (!w) {
    if (error) *error = w.error().format();
    else ADD_FAILURE() << w.error().format();
    return {};
  }
  std::array<glm::dvec3, 4> out;
  const lsys::SymbolId ids[4] = {lsys::kSymQueryPosition, lsys::kSymQueryHeading, lsys::kSymQueryLeft,
                                 lsys::kSymQueryUp};
  for (int k = 0; k < 4; ++k) {
    const auto v = params_of(*w, ids[k]);
    if (v.size() == 3) out[static_cast<size_t>(k)] = {v[0], v[1], v[2]};
  }
  return out;
}

// ... with one tropism T of elasticity e (sylva's `tropism:` header, which stands for one in a
// cpfg file without view-file tropisms).
std::array<glm::dvec3, 4> tropism_frame_after(const std::string& axiom, glm::dvec3 tropism, double e) {
  return cpfg_frame_after(axiom, [&](lsys::Grammar& g) {
    g.turtle.has_tropism = e != 0;
    g.turtle.tropism[0] = tropism.x, g.turtle.tropism[1] = tropism.y, g.turtle.tropism[2] = tropism.z;
    g.turtle.tropism_e = e;
  });
}

// A cpfg file's view-file tropism, as cpfg's movement_adjust (cpfg/movements.c): before every
// F, G, f and g — not after every F, as ABOP's rule in sylva's own format — H turns toward T
// by e·|H × T| radians, at most 1; the up vector is the last drawn segment's turned by the
// least rotation to the new heading, so a roll since that segment is undone unless @Tf.
TEST(TurtleQueries, CpfgViewFileTropismTurnsBeforeEveryMoveAsCpfgDoes) {
  const glm::dvec3 x(1, 0, 0);
  // Before the first F: 0.5 rad from +y toward +x, so the first segment already leans.
  auto f = tropism_frame_after("F(1)", x, 0.5);
  EXPECT_TRUE(near(f[0], {std::sin(0.5), std::cos(0.5), 0}));
  // Before the second: e·|H × T| = 0.5·cos(0.5) more.
  const double second = 0.5 + 0.5 * std::cos(0.5);
  f = tropism_frame_after("F(1)F(1)", x, 0.5);
  EXPECT_TRUE(near(f[1], {std::sin(second), std::cos(second), 0}));
  // f and g turn it too, G as F.
  f = tropism_frame_after("f(1)g(1)G(1)", x, 0.5);
  const double third = second + 0.5 * std::cos(second);
  EXPECT_TRUE(near(f[1], {std::sin(third), std::cos(third), 0}));
  // At most 1 radian a move.
  f = tropism_frame_after("F(1)", x, 5);
  EXPECT_TRUE(near(f[0], {std::sin(1.0), std::cos(1.0), 0}));
  // A roll before the next move is undone (the up of the last segment, carried along)...
  const auto unrolled = tropism_frame_after("F(1)/(90)F(1)", x, 0.5);
  const auto plain = tropism_frame_after("F(1)F(1)", x, 0.5);
  EXPECT_TRUE(near(unrolled[3], plain[3]));
  EXPECT_TRUE(near(unrolled[2], plain[2]));
  // ... unless @Tf keeps it: then up is the rolled up, turned with the heading.
  const auto kept = tropism_frame_after("F(1)/(90)@TfF(1)", x, 0.5);
  EXPECT_FALSE(near(kept[3], plain[3]));
  EXPECT_NEAR(glm::dot(kept[3], plain[3]), 0, 1e-12) << "a quarter roll: the ups are perpendicular";
  EXPECT_TRUE(near(kept[1], plain[1])) << "the heading is the same";
  // Every frame stays orthonormal and right-handed (H × L = U).
  for (const auto& frame : {unrolled, kept}) {
    EXPECT_NEAR(glm::length(frame[1]), 1, 1e-12);
    EXPECT_TRUE(near(glm::cross(frame[1], frame[2]), frame[3]));
  }
  // A bare @Tp (manual 6.8) undoes the twist since the last segment the same way, at once:
  // after a pitch and a roll, up is the last segment's turned by the least rotation.
  const auto twisted = tropism_frame_after("F(1)&(30)/(90)", x, 0);
  const auto untwisted = tropism_frame_after("F(1)&(30)/(90)@Tp", x, 0);
  const auto pitched = tropism_frame_after("F(1)&(30)", x, 0);
  EXPECT_TRUE(near(untwisted[1], twisted[1])) << "the heading stays";
  EXPECT_TRUE(near(untwisted[3], pitched[3])) << "the roll is undone, the pitch kept";
  EXPECT_FALSE(near(twisted[3], pitched[3]));
  // Without a tropism the roll stays.
  const auto untouched = tropism_frame_after("F(1)/(90)F(1)", x, 0);
  EXPECT_TRUE(near(untouched[3], {1, 0, 0}) || near(untouched[3], {-1, 0, 0})) << untouched[3].x;
}

// ... with the view file's tropism lines (ids 1, 2, ...; vlab_object.cpp fills them).
std::array<glm::dvec3, 4> tropisms_frame_after(const std::string& axiom, std::vector<lsys::ViewTropism> tropisms,
                                               std::string* error = nullptr) {
  return cpfg_frame_after(axiom, [&](lsys::Grammar& g) { g.turtle.view_tropisms = tropisms; }, error);
}

lsys::ViewTropism view_tropism(glm::dvec3 t, double e, double angle_deg = 0, double step = 0) {
  lsys::ViewTropism v;
  v.vector[0] = t.x, v.vector[1] = t.y, v.vector[2] = t.z;
  v.elasticity = e;
  v.angle_deg = angle_deg;
  v.step = step;
  return v;
}

// Several tropisms (cpfg/movements.c movement_adjust): one desired direction, the sum of
// cos(A)·e·T and, for A ≠ 0, sin(A)·e·T × (H × T) / |H × T|; @T(id, v) / @Ti, @Td and @Ts
// change one tropism's elasticity for the rest of the branch.
TEST(TurtleQueries, CpfgTropismIdsSumIntoOneTurnAndTheirElasticitiesFollowTheBranch) {
  const glm::dvec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  // Two orthotropisms: V = 0.3 x + 0.2 z (perpendicular to H = +y): H turns toward V by |V|.
  auto f = tropisms_frame_after("F(1)", {view_tropism(x, 0.3), view_tropism(z, 0.2)});
  const glm::dvec3 v(0.3, 0, 0.2);
  const double turn = glm::length(v);
  EXPECT_TRUE(near(f[0], std::cos(turn) * y + std::sin(turn) * v / turn)) << f[0].x << " " << f[0].z;
  // Diatropism (A = 90 degrees): a shoot at 45 degrees from T = x turns away from it, toward
  // the plane across T, by e·sin 45°.
  f = tropisms_frame_after("-(45)F(1)", {view_tropism(x, 0.5, 90)});
  const double from_y = std::acos(-1.0) / 4 - 0.5 * std::sin(std::acos(-1.0) / 4);
  EXPECT_TRUE(near(f[0], {std::sin(from_y), std::cos(from_y), 0})) << f[0].x << " " << f[0].y;
  // A shoot across T already is where diatropism wants it: no turn.
  f = tropisms_frame_after("F(1)", {view_tropism(x, 0.5, 90)});
  EXPECT_TRUE(near(f[0], {0, 1, 0}));
  // Elasticities: @Ts(1, 0) stops tropism 1 in its branch only; @Ti(1) adds its step, @T(1, v)
  // (the manual's name) adds v, @Td(1, v) takes v.
  const std::vector<lsys::ViewTropism> one = {view_tropism(x, 0.5, 0, 0.25)};
  f = tropisms_frame_after("[@Ts(1,0)F(1)]F(1)", one);
  EXPECT_TRUE(near(f[0], {std::sin(0.5), std::cos(0.5), 0})) << "the main axis bends";
  f = tropisms_frame_after("@Ts(1,0)F(1)", one);
  EXPECT_TRUE(near(f[0], {0, 1, 0})) << "the branch that set 0 does not";
  f = tropisms_frame_after("@Ts(1,0)@Ti(1)F(1)", one);
  EXPECT_TRUE(near(f[0], {std::sin(0.25), std::cos(0.25), 0}));
  f = tropisms_frame_after("@Ts(1,0)@T(1,0.4)@Td(1,0.1)F(1)", one);
  EXPECT_TRUE(near(f[0], {std::sin(0.3), std::cos(0.3), 0}));
  // An id that is not a tropism's is an error naming the ids there are.
  std::string error;
  tropisms_frame_after("@Ti(2,1)F", one, &error);
  EXPECT_NE(error.find("a tropism id from 1 to 1"), std::string::npos) << error;
}

TEST(TurtleQueries, CpfgAtRSetsTheHeadingByTheLeastRotationOrWithItsUpVector) {
  // CPFG manual 6.2. The turtle starts with H = +y, L = -x, U = +z. Turning H to +x rotates
  // about -z: U stays, L becomes +y. A reversal turns about U, as |.
  auto f = frame_after("@R(2,0,0)");
  EXPECT_TRUE(near(f[0], {1, 0, 0}));
  EXPECT_TRUE(near(f[1], {0, 1, 0}));
  EXPECT_TRUE(near(f[2], {0, 0, 1}));
  f = frame_after("@R(0,-3,0)");
  EXPECT_TRUE(near(f[0], {0, -1, 0}));
  EXPECT_TRUE(near(f[1], {1, 0, 0}));
  EXPECT_TRUE(near(f[2], {0, 0, 1}));
  // With an up vector perpendicular to H: that up, normalised, and L = U x H.
  f = frame_after("@R(1,0,0,0,2,2)");
  const double r = 1 / std::sqrt(2.0);
  EXPECT_TRUE(near(f[0], {1, 0, 0}));
  EXPECT_TRUE(near(f[2], {0, r, r}));
  EXPECT_TRUE(near(f[1], {0, r, -r}));
  // An up vector that is not perpendicular (or zero) is ignored as cpfg ignores it: the
  // least rotation again. Two parameters are x and y; a zero heading is +y.
  f = frame_after("@R(1,0,0,1,1,1)");
  EXPECT_TRUE(near(f[1], {0, 1, 0}));
  EXPECT_TRUE(near(f[2], {0, 0, 1}));
  f = frame_after("@R(0,-3)");
  EXPECT_TRUE(near(f[0], {0, -1, 0}));
  f = frame_after("+(90)@R(0,0,0)");
  EXPECT_TRUE(near(f[0], {0, 1, 0}));
  // The up vector comes from the last drawn segment's (cpfg's adjust_up_and_left): a roll
  // since then is undone, as cpfg does; after an F the roll is that segment's and stays.
  f = frame_after("/(90)@R(1,0,0)");
  EXPECT_TRUE(near(f[0], {1, 0, 0}));
  EXPECT_TRUE(near(f[1], {0, 1, 0}));
  EXPECT_TRUE(near(f[2], {0, 0, 1}));
  f = frame_after("/(90)F@R(1,0,0)");
  EXPECT_TRUE(near(f[0], {1, 0, 0}));
  EXPECT_FALSE(near(f[2], {0, 0, 1}));
  // After a roll and a pitch, @R still sets the heading absolutely, and F follows it.
  const lsys::Grammar g = parsed("Lsystem: 1\nderivation length: 0\nAxiom: /(33)&(20)@R(0,0,1)F(2)?P(0,0,0)\nendlsystem\n", "r.l");
  auto w = derived_word(g, 0);
  ASSERT_TRUE(w);
  const auto p = params_of(*w, lsys::kSymQueryPosition);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_TRUE(near({p[0], p[1], p[2]}, {0, 0, 2}));
  // No heading is an error naming @R.
  for (const char* bad : {"@R F", "@R(1)F"}) {
    const lsys::Grammar b = parsed(std::string("Lsystem: 1\nAxiom: ") + bad + "\nendlsystem\n", "r.l");
    auto sk = build_skeleton(b.axiom, b);
    ASSERT_FALSE(sk) << bad;
    EXPECT_NE(sk.error().message.find("@R"), std::string::npos) << sk.error().message;
  }
}

}  // namespace
}  // namespace sylva
