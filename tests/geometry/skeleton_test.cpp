// Tests for core/geometry/skeleton.h: the sylva-skeleton file format (docs/spec/skeleton.md)
// and the skeleton's invariants.
//
// Rejection tests compare the whole formatted message, "file:line:column: error: ...",
// so both the place and the chain/joint named are checked. Column arithmetic for the
// chain lines used below (one chain per line, starting at line 3):
//   {"parent": P, ...          P starts at column 12
//   {"parent": [1,0], "joints": [[0,2,0,0.1,1],J]}
//     joints array at 29, joint 0 at 30, J at 44; inside J = [x,y,z,r,m] with
//     one-character x, y, z: x 45, y 47, z 49, radius 51.
#include "core/geometry/skeleton.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/util/file_io.h"

namespace sylva {
namespace {

constexpr const char* kFile = "plant.skel.json";

Joint joint(double x, double y, double z, double radius, uint32_t material = 0) {
  return Joint{{x, y, z}, radius, material};
}

// The two-chain skeleton of the format's documentation.
Skeleton documented_skeleton() {
  Skeleton skeleton;
  skeleton.source.grammar = "presets/saguaro.lsys";
  skeleton.source.seed = 1;
  skeleton.source.steps = 6;
  skeleton.source.defines = {{"N", 5.0}};
  skeleton.joints = {joint(0, 0, 0, 0.3), joint(0, 1, 0, 0.28), joint(0, 1, 0, 0.1),
                     joint(0.7, 1.7, 0, 0.08)};
  skeleton.chains = {Chain{0, 2, std::nullopt}, Chain{2, 2, ChainParent{0, 1}}};
  return skeleton;
}

// A file whose chains are `chains`, one per line from line 3.
std::string file_with_chains(const std::vector<std::string>& chains) {
  std::string text = "{\"format\": \"sylva-skeleton\", \"version\": 1,\n \"chains\": [\n";
  for (size_t i = 0; i < chains.size(); ++i) text += chains[i] + (i + 1 < chains.size() ? ",\n" : "\n");
  return text + "]}\n";
}

// Three chains; the third (chain 2, line 5) has parent `parent` and a second joint `j1`.
std::string file_with_third_chain(const std::string& parent, const std::string& j1) {
  return file_with_chains({
      R"({"parent": null, "joints": [[0,0,0,0.3,0],[0,1,0,0.28,0]]})",
      R"({"parent": [0,1], "joints": [[0,1,0,0.1,0],[0.7,1.7,0,0.08,0]]})",
      "{\"parent\": " + parent + ", \"joints\": [[0,2,0,0.1,1]," + j1 + "]}",
  });
}

// A file with a "source" member `source`, which starts at line 2, column 12.
std::string file_with_source(const std::string& source) {
  return "{\"format\": \"sylva-skeleton\", \"version\": 1, \"chains\": [],\n \"source\": " + source +
         "}\n";
}

// A diagnostic's one line (these errors have no source line or notes).
std::string one_line(const Diagnostic& d) {
  std::string text = d.format();
  EXPECT_EQ(text.find('\n'), text.size() - 1) << text;
  text.pop_back();
  return text;
}

// The formatted error reading `text`, or "no error".
std::string read_error(const std::string& text) {
  const Expected<Skeleton> result = read_skeleton_json(text, kFile);
  if (result) return "no error";
  return one_line(result.error());
}

Skeleton read_ok(const std::string& text) {
  Expected<Skeleton> result = read_skeleton_json(text, kFile);
  EXPECT_TRUE(result.ok()) << result.error().format();
  return result ? std::move(*result) : Skeleton{};
}

std::string validate_error(const Skeleton& skeleton) {
  const Status valid = validate_skeleton(skeleton);
  return valid ? "no error" : one_line(valid.error());
}

void expect_same_bits(double a, double b) {
  EXPECT_EQ(std::bit_cast<uint64_t>(a), std::bit_cast<uint64_t>(b)) << a << " vs " << b;
}

// ---- writing ----------------------------------------------------------------------

TEST(SkeletonWrite, WritesTheDocumentedLayoutByteForByte) {
  EXPECT_EQ(write_skeleton_json(documented_skeleton()),
            "{\n"
            "  \"format\": \"sylva-skeleton\",\n"
            "  \"version\": 1,\n"
            "  \"source\": {\"grammar\": \"presets/saguaro.lsys\", \"seed\": 1, \"steps\": 6, "
            "\"defines\": {\"N\": 5}},\n"
            "  \"chains\": [\n"
            "    {\"parent\": null, \"joints\": [[0,0,0,0.3,0],[0,1,0,0.28,0]]},\n"
            "    {\"parent\": [0,1], \"joints\": [[0,1,0,0.1,0],[0.7,1.7,0,0.08,0]]}\n"
            "  ]\n"
            "}\n");
}

TEST(SkeletonWrite, TheCompactFormForEmbeddingIsTheSameDocumentWithTheSeedAsAString) {
  Skeleton skeleton = documented_skeleton();
  skeleton.source.seed = 18446744073709551615u;
  JsonWriter w;
  w.begin_object();
  write_skeleton_members(w, skeleton, {.compact = true, .seed_as_string = true});
  w.end_object();
  EXPECT_EQ(w.text(),
            "{\"format\":\"sylva-skeleton\",\"version\":1,\"source\":{\"grammar\":\"presets/saguaro.lsys\","
            "\"seed\":\"18446744073709551615\",\"steps\":6,\"defines\":{\"N\":5}},\"chains\":["
            "{\"parent\":null,\"joints\":[[0,0,0,0.3,0],[0,1,0,0.28,0]]},"
            "{\"parent\":[0,1],\"joints\":[[0,1,0,0.1,0],[0.7,1.7,0,0.08,0]]}]}");
}

TEST(SkeletonWrite, AnEmptySkeletonWritesEmptyDefinesAndChains) {
  EXPECT_EQ(write_skeleton_json(Skeleton{}),
            "{\n"
            "  \"format\": \"sylva-skeleton\",\n"
            "  \"version\": 1,\n"
            "  \"source\": {\"grammar\": \"\", \"seed\": 1, \"steps\": 0, \"defines\": {}},\n"
            "  \"chains\": []\n"
            "}\n");
}

TEST(SkeletonWrite, DefinesAreSortedByNameAndNumbersAreShortest) {
  Skeleton skeleton;
  skeleton.source.defines = {{"b", 0.1}, {"a", 1e300}, {"C", -2.5e-8}};
  skeleton.joints = {joint(123456789012345678.0, 1e-300, -0.0, 0.0, 4294967295u)};
  skeleton.chains = {Chain{0, 1, std::nullopt}};
  const std::string text = write_skeleton_json(skeleton);
  EXPECT_NE(text.find("\"defines\": {\"C\": -2.5e-08, \"a\": 1e+300, \"b\": 0.1}}"), std::string::npos)
      << text;
  EXPECT_NE(text.find("[[123456789012345680,1e-300,0,0,4294967295]]"), std::string::npos) << text;
}

TEST(SkeletonWrite, TheSeedIsWrittenAsAnExactInteger) {
  Skeleton skeleton;
  skeleton.source.seed = 18446744073709551615u;  // not representable as a double
  EXPECT_NE(write_skeleton_json(skeleton).find("\"seed\": 18446744073709551615,"), std::string::npos);
}

TEST(SkeletonWrite, TheGrammarPathIsEscaped) {
  Skeleton skeleton;
  skeleton.source.grammar = "dir \"q\"\\tab\t\xC3\xA9.lsys";
  EXPECT_NE(write_skeleton_json(skeleton).find(R"("grammar": "dir \"q\"\\tab\té.lsys")"),
            std::string::npos);
}

// ---- round trips ------------------------------------------------------------------

Skeleton varied_skeleton() {
  Skeleton skeleton;
  skeleton.source.grammar = "presets/\xC3\xA9rable \"v2\".lsys";
  skeleton.source.seed = 18446744073709551615u;
  skeleton.source.steps = 9223372036854775807;
  skeleton.source.defines = {{"N", 5}, {"angle", 22.5}, {"tiny", 1e-300}, {"big", 1e300},
                             {"third", 1.0 / 3.0}, {"neg", -0.1}};
  skeleton.joints = {joint(0, 0, 0, 0.3), joint(0.1, 1.0 / 3.0, -2.5e-8, 0.29, 1),
                     joint(123456789012345678.0, 1e-300, 5e-324, 0, 4294967295u),
                     joint(0.1, 1.0 / 3.0, -2.5e-8, 0.05, 2), joint(-1e300, 7, 8, 1e-9, 3),
                     joint(0.25, 0.5, 0.75, 0.01, 3)};
  skeleton.chains = {Chain{0, 3, std::nullopt}, Chain{3, 2, ChainParent{0, 1}},
                     Chain{5, 1, ChainParent{1, 1}}};
  return skeleton;
}

TEST(SkeletonRoundTrip, WriteReadWriteIsByteIdentical) {
  const std::string first = write_skeleton_json(varied_skeleton());
  const Skeleton read = read_ok(first);
  EXPECT_EQ(write_skeleton_json(read), first);
}

TEST(SkeletonRoundTrip, EveryValueReadsBackExactly) {
  const Skeleton original = varied_skeleton();
  const Skeleton read = read_ok(write_skeleton_json(original));
  EXPECT_EQ(read.source.grammar, original.source.grammar);
  EXPECT_EQ(read.source.seed, 18446744073709551615u);
  EXPECT_EQ(read.source.steps, 9223372036854775807);
  EXPECT_EQ(read.source.defines, original.source.defines);
  ASSERT_EQ(read.joints.size(), original.joints.size());
  for (size_t i = 0; i < read.joints.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      expect_same_bits(read.joints[i].position_m[axis], original.joints[i].position_m[axis]);
    }
    expect_same_bits(read.joints[i].radius_m, original.joints[i].radius_m);
    EXPECT_EQ(read.joints[i].material, original.joints[i].material);
  }
  ASSERT_EQ(read.chains.size(), 3u);
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_EQ(read.chains[c].first_joint, original.chains[c].first_joint);
    EXPECT_EQ(read.chains[c].joint_count, original.chains[c].joint_count);
    EXPECT_EQ(read.chains[c].parent, original.chains[c].parent);
  }
}

TEST(SkeletonRoundTrip, NegativeZeroReadsBackAsPositiveZero) {
  Skeleton skeleton;
  skeleton.joints = {joint(-0.0, 0, 0, -0.0)};
  skeleton.chains = {Chain{0, 1, std::nullopt}};
  const std::string text = write_skeleton_json(skeleton);
  EXPECT_NE(text.find("[[0,0,0,0,0]]"), std::string::npos);
  const Skeleton read = read_ok(text);
  expect_same_bits(read.joints[0].position_m[0], 0.0);
  EXPECT_EQ(write_skeleton_json(read), text);
}

TEST(SkeletonRead, ReadsTheSpecExampleWithItsSpacing) {
  const Skeleton skeleton = read_ok(R"({
  "format": "sylva-skeleton",
  "version": 1,
  "source": {"grammar": "presets/saguaro.lsys", "seed": 1, "steps": 6, "defines": {"N": 5}},
  "chains": [
    {"parent": null,   "joints": [[0,0,0, 0.3, 0], [0,1,0, 0.28, 0]]},
    {"parent": [0, 1], "joints": [[0,1,0, 0.1, 0], [0.7,1.7,0, 0.08, 0]]}
  ]
})");
  EXPECT_EQ(write_skeleton_json(skeleton), write_skeleton_json(documented_skeleton()));
  EXPECT_EQ(skeleton.segment_count(), 2u);
  ASSERT_EQ(skeleton.chains.size(), 2u);
  EXPECT_EQ(skeleton.chains[1].parent, (ChainParent{0, 1}));
  EXPECT_EQ(skeleton.joints[3].position_m[1], 1.7);
}

TEST(SkeletonRead, SourceIsOptionalAndDefaultsWhenAbsent) {
  const Skeleton skeleton = read_ok(R"({"format": "sylva-skeleton", "version": 1, "chains": []})");
  EXPECT_EQ(skeleton.source.grammar, "");
  EXPECT_EQ(skeleton.source.seed, 1u);
  EXPECT_EQ(skeleton.source.steps, 0);
  EXPECT_TRUE(skeleton.source.defines.empty());
  EXPECT_TRUE(skeleton.chains.empty());
}

TEST(SkeletonRead, AcceptsTheLargestMaterialIndex) {
  const Skeleton skeleton = read_ok(file_with_third_chain("[1,0]", "[0,3,0,0.1,4294967295]"));
  EXPECT_EQ(skeleton.joints.back().material, 4294967295u);
  EXPECT_EQ(skeleton.chains[2].first_joint, 4u);
  EXPECT_EQ(skeleton.chains[2].joint_count, 2u);
}

// ---- rejections: the header -------------------------------------------------------

TEST(SkeletonRead, RejectsAnUnknownFormat) {
  EXPECT_EQ(read_error(R"({"format": "sylva-skel", "version": 1, "chains": []})"),
            "plant.skel.json:1:12: error: unknown format \"sylva-skel\"; this reader reads "
            "\"sylva-skeleton\"");
  EXPECT_EQ(read_error(R"({"format": 1, "version": 1, "chains": []})"),
            "plant.skel.json:1:12: error: format must be the string \"sylva-skeleton\", got 1");
}

TEST(SkeletonRead, RejectsAnUnknownVersion) {
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": 3, "chains": []})"),
            "plant.skel.json:1:41: error: unsupported version 3 of \"sylva-skeleton\"; this "
            "reader reads versions 1 and 2");
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": 1.0, "chains": []})"),
            "plant.skel.json:1:41: error: version must be an integer, got 1.0");
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": "1", "chains": []})"),
            "plant.skel.json:1:41: error: version must be an integer, got the string \"1\"");
}

TEST(SkeletonRead, RejectsMissingRequiredKeys) {
  EXPECT_EQ(read_error(R"({"version": 1, "chains": []})"),
            "plant.skel.json:1:1: error: missing required key \"format\" (a skeleton file starts "
            "with \"format\": \"sylva-skeleton\")");
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "chains": []})"),
            "plant.skel.json:1:1: error: missing required key \"version\"");
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": 1})"),
            "plant.skel.json:1:1: error: missing required key \"chains\"");
}

TEST(SkeletonRead, RejectsAnUnknownTopLevelKeyByName) {
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": 1, "chain": []})"),
            "plant.skel.json:1:44: error: unknown key \"chain\" at the top level; expected "
            "\"format\", \"version\", \"source\" or \"chains\"");
}

TEST(SkeletonRead, RejectsARootThatIsNotAnObject) {
  EXPECT_EQ(read_error("\n  []"),
            "plant.skel.json:2:3: error: a skeleton file holds a JSON object, found an array of "
            "0 elements");
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": 1, "chains": {}})"),
            "plant.skel.json:1:54: error: chains must be an array, got an object");
}

TEST(SkeletonRead, ReportsMalformedJsonAtItsPlace) {
  EXPECT_EQ(read_error(R"({"format": "sylva-skeleton", "version": 1, "chains": [],})"),
            "plant.skel.json:1:56: error: trailing comma before '}' is not allowed in JSON");
  EXPECT_EQ(read_error("{\"format\": \"sylva-skeleton\",\n \"format\": \"sylva-skeleton\"}"),
            "plant.skel.json:2:2: error: duplicate key \"format\" (first at line 1, column 2)");
  EXPECT_EQ(read_error("{\"format\": \"sylva-skeleton\", \"version\": 1, \"chains\": [\n \"\xC3\x28\"]}"),
            "plant.skel.json:2:3: error: invalid UTF-8 (byte 0xC3) inside a string");
}

TEST(SkeletonRead, AMillionDeepNestingIsAnErrorNotACrash) {
  // The root object is level 1, so the 256th '[' (column 54 + 255) is one level too many.
  const std::string text =
      R"({"format": "sylva-skeleton", "version": 1, "chains": )" + std::string(1'000'000, '[');
  EXPECT_EQ(read_error(text),
            "plant.skel.json:1:309: error: arrays and objects are nested more than 256 levels deep");
}

// ---- rejections: chains and joints ------------------------------------------------

TEST(SkeletonRead, RejectsNaNAndInfinityNamingChainAndJoint) {
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,NaN,0,0.1,1]")),
            "plant.skel.json:5:47: error: chain 2, joint 1: y must be a finite number, got NaN");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[Infinity,3,0,0.1,1]")),
            "plant.skel.json:5:45: error: chain 2, joint 1: x must be a finite number, got "
            "Infinity");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,-Infinity,0.1,1]")),
            "plant.skel.json:5:49: error: chain 2, joint 1: z must be a finite number, got "
            "-Infinity");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,NaN,1]")),
            "plant.skel.json:5:51: error: chain 2, joint 1: radius must be a finite number, got "
            "NaN");
}

TEST(SkeletonRead, RejectsOutOfRangeNumbersNamingChainAndJoint) {
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,1e400,1]")),
            "plant.skel.json:5:51: error: chain 2, joint 1: radius must be a finite number, got "
            "1e400 (out of range of a double)");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[-1e309,3,0,0.1,1]")),
            "plant.skel.json:5:45: error: chain 2, joint 1: x must be a finite number, got "
            "-1e309 (out of range of a double)");
}

TEST(SkeletonRead, RejectsANegativeRadiusNamingChainAndJoint) {
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,-0.25,1]")),
            "plant.skel.json:5:51: error: chain 2, joint 1: radius -0.25 is negative; radii must "
            "be >= 0");
  // -0 is not negative: it reads as a tip.
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,-0,1]")), "no error");
}

TEST(SkeletonRead, RejectsAMaterialThatIsNotAnIntegerBelowTwoToThe32) {
  // The material of J = [0,3,0,0.1,M] starts at column 55.
  for (const char* material : {"1.5", "-1", "4294967296", "1e2", "1.0"}) {
    EXPECT_EQ(read_error(file_with_third_chain("[1,0]", std::string("[0,3,0,0.1,") + material + "]")),
              std::string("plant.skel.json:5:55: error: chain 2, joint 1: material must be an "
                          "integer from 0 to 4294967295, got ") + material);
  }
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,0.1,\"bark\"]")),
            "plant.skel.json:5:55: error: chain 2, joint 1: material must be an integer from 0 "
            "to 4294967295, got the string \"bark\"");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,0.1,null]")),
            "plant.skel.json:5:55: error: chain 2, joint 1: material must be an integer from 0 "
            "to 4294967295, got null");
}

TEST(SkeletonRead, RejectsAJointThatIsNotFiveNumbers) {
  const std::string expected_prefix =
      "plant.skel.json:5:44: error: chain 2, joint 1: a joint must be an array of 5 numbers "
      "[x, y, z, radius, material], got ";
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,0.1]")),
            expected_prefix + "an array of 4 elements");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,0,0.1,1,1]")),
            expected_prefix + "an array of 6 elements");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "7")), expected_prefix + "7");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "{}")), expected_prefix + "an object");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,\"3\",0,0.1,1]")),
            "plant.skel.json:5:47: error: chain 2, joint 1: y must be a number, got the string "
            "\"3\"");
  EXPECT_EQ(read_error(file_with_third_chain("[1,0]", "[0,3,true,0.1,1]")),
            "plant.skel.json:5:49: error: chain 2, joint 1: z must be a number, got true");
}

TEST(SkeletonRead, RejectsAChainWithNoJoints) {
  EXPECT_EQ(read_error(file_with_chains({R"({"parent": null, "joints": []})"})),
            "plant.skel.json:3:28: error: chain 0 has no joints; a chain needs at least one");
  EXPECT_EQ(read_error(file_with_chains({R"({"parent": null, "joints": 5})"})),
            "plant.skel.json:3:28: error: chain 0: joints must be an array of [x, y, z, radius, "
            "material], got 5");
}

TEST(SkeletonRead, RejectsAChainThatIsNotAnObjectWithParentAndJoints) {
  EXPECT_EQ(read_error(file_with_chains({R"({"parent": null, "joints": [[0,0,0,1,0]]})", "[0,0,0,1,0]"})),
            "plant.skel.json:4:1: error: chain 1 must be an object {\"parent\": ..., \"joints\": "
            "[...]}, got an array of 5 elements");
  EXPECT_EQ(read_error(file_with_chains({R"({"parent": null, "joint": []})"})),
            "plant.skel.json:3:18: error: chain 0: unknown key \"joint\"; expected \"parent\" or "
            "\"joints\"");
  EXPECT_EQ(read_error(file_with_chains({R"({"joints": [[0,0,0,1,0]]})"})),
            "plant.skel.json:3:1: error: chain 0: missing required key \"parent\"");
  EXPECT_EQ(read_error(file_with_chains({R"({"parent": null})"})),
            "plant.skel.json:3:1: error: chain 0: missing required key \"joints\"");
}

TEST(SkeletonRead, RejectsAParentThatIsNotNullOrAPairOfIndices) {
  EXPECT_EQ(read_error(file_with_third_chain("\"root\"", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:12: error: chain 2: parent must be null or [chain index, joint "
            "index], got the string \"root\"");
  EXPECT_EQ(read_error(file_with_third_chain("[0]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:12: error: chain 2: parent must be null or [chain index, joint "
            "index], got an array of 1 element");
  EXPECT_EQ(read_error(file_with_third_chain("[0,1,2]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:12: error: chain 2: parent must be null or [chain index, joint "
            "index], got an array of 3 elements");
  EXPECT_EQ(read_error(file_with_third_chain("[-1,0]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:13: error: chain 2: parent chain index must be an integer from 0 "
            "to 4294967295, got -1");
  EXPECT_EQ(read_error(file_with_third_chain("[0,0.5]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:15: error: chain 2: parent joint index must be an integer from 0 "
            "to 4294967295, got 0.5");
  EXPECT_EQ(read_error(file_with_third_chain("[0,4294967296]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:15: error: chain 2: parent joint index must be an integer from 0 "
            "to 4294967295, got 4294967296");
}

TEST(SkeletonRead, RejectsAParentThatIsNotAnEarlierChain) {
  EXPECT_EQ(read_error(file_with_third_chain("[2,0]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:13: error: chain 2: parent [2, 0] refers to chain 2, which does "
            "not come before chain 2 (parents come before their children)");
  EXPECT_EQ(read_error(file_with_third_chain("[7,0]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:13: error: chain 2: parent [7, 0] refers to chain 7, which does "
            "not come before chain 2 (parents come before their children)");
  EXPECT_EQ(read_error(file_with_chains({R"({"parent": [0,0], "joints": [[0,0,0,1,0]]})"})),
            "plant.skel.json:3:13: error: chain 0: parent [0, 0] refers to chain 0, which does "
            "not come before chain 0 (parents come before their children)");
}

TEST(SkeletonRead, RejectsAParentJointPastTheEndOfItsChain) {
  EXPECT_EQ(read_error(file_with_third_chain("[1,2]", "[0,3,0,0.1,1]")),
            "plant.skel.json:5:15: error: chain 2: parent [1, 2] refers to joint 2 of chain 1, "
            "which has 2 joints");
  EXPECT_EQ(read_error(file_with_third_chain("[1,1]", "[0,3,0,0.1,1]")), "no error");
}

// ---- rejections: source -----------------------------------------------------------
// In {"grammar": "g.lsys", "seed": S, "steps": T, "defines": D} starting at column 12:
// grammar value at 24, S at 42; with S = 1, T at 54; with T = 6, D at 68.

TEST(SkeletonRead, RejectsASourceWithWrongFieldTypes) {
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": 7, "seed": 1, "steps": 6, "defines": {}})")),
            "plant.skel.json:2:24: error: source: grammar must be a string, got 7");
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": "g.lsys", "seed": 1, "steps": 6, "defines": []})")),
            "plant.skel.json:2:68: error: source: defines must be an object of name: number, got "
            "an array of 0 elements");
  EXPECT_EQ(read_error(file_with_source("null")),
            "plant.skel.json:2:12: error: source must be an object {\"grammar\", \"seed\", "
            "\"steps\", \"defines\"}, got null");
}

TEST(SkeletonRead, RejectsASeedThatIsNotAnExactUint64) {
  for (const char* seed : {"-1", "1.5", "1e3", "18446744073709551616", "\"1\""}) {
    const std::string got = seed[0] == '"' ? std::string("the string ") + seed : seed;
    EXPECT_EQ(read_error(file_with_source(std::string(R"({"grammar": "g.lsys", "seed": )") + seed +
                                          R"(, "steps": 6, "defines": {}})")),
              "plant.skel.json:2:42: error: source: seed must be an integer from 0 to "
              "18446744073709551615, got " + got);
  }
}

TEST(SkeletonRead, RejectsNegativeOrFractionalSteps) {
  for (const char* steps : {"-1", "2.5", "9223372036854775808"}) {
    EXPECT_EQ(read_error(file_with_source(std::string(R"({"grammar": "g.lsys", "seed": 1, "steps": )") +
                                          steps + R"(, "defines": {}})")),
              std::string("plant.skel.json:2:54: error: source: steps must be an integer from 0 "
                          "to 9223372036854775807, got ") + steps);
  }
}

TEST(SkeletonRead, RejectsDefinesThatAreNotFiniteNumbers) {
  // D = {"N": V}: V at column 74.
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": "g.lsys", "seed": 1, "steps": 6, "defines": {"N": "five"}})")),
            "plant.skel.json:2:74: error: source: define \"N\" must be a finite number, got the "
            "string \"five\"");
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": "g.lsys", "seed": 1, "steps": 6, "defines": {"N": NaN}})")),
            "plant.skel.json:2:74: error: source: define \"N\" must be a finite number, got NaN");
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": "g.lsys", "seed": 1, "steps": 6, "defines": {"": 1}})")),
            "plant.skel.json:2:69: error: source: a define name must not be empty");
}

TEST(SkeletonRead, RejectsUnknownOrMissingSourceKeys) {
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": "g.lsys", "sed": 1, "steps": 6, "defines": {}})")),
            "plant.skel.json:2:34: error: source: unknown key \"sed\"; expected \"grammar\", "
            "\"seed\", \"steps\" or \"defines\"");
  EXPECT_EQ(read_error(file_with_source(R"({"grammar": "g.lsys"})")),
            "plant.skel.json:2:12: error: source: missing required key \"seed\"");
}

TEST(SkeletonRead, ReadsASourceExactly) {
  const Skeleton skeleton = read_ok(file_with_source(
      R"({"grammar": "a\u00e9.lsys", "seed": 18446744073709551615, "steps": 12, "defines": {"b": 2.5, "a": -1}})"));
  EXPECT_EQ(skeleton.source.grammar, "a\xC3\xA9.lsys");
  EXPECT_EQ(skeleton.source.seed, 18446744073709551615u);
  EXPECT_EQ(skeleton.source.steps, 12);
  EXPECT_EQ(skeleton.source.defines, (std::map<std::string, double>{{"a", -1.0}, {"b", 2.5}}));
}

// ---- validate_skeleton ------------------------------------------------------------

TEST(SkeletonValidate, AcceptsWellFormedSkeletons) {
  EXPECT_EQ(validate_error(documented_skeleton()), "no error");
  EXPECT_EQ(validate_error(varied_skeleton()), "no error");
  EXPECT_EQ(validate_error(Skeleton{}), "no error");
}

TEST(SkeletonValidate, RejectsNonFinitePositionsAndBadRadiiNamingChainAndJoint) {
  Skeleton skeleton = documented_skeleton();
  skeleton.joints[3].position_m[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validate_error(skeleton), "error: chain 1, joint 1: z is NaN; positions must be finite");
  skeleton = documented_skeleton();
  skeleton.joints[2].radius_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(validate_error(skeleton), "error: chain 1, joint 0: radius is Infinity; radii must be finite");
  skeleton = documented_skeleton();
  skeleton.joints[1].radius_m = -0.5;
  EXPECT_EQ(validate_error(skeleton), "error: chain 0, joint 1: radius -0.5 is negative; radii must be >= 0");
}

TEST(SkeletonValidate, RejectsChainRangesThatAreEmptyOverlappingOrOutOfBounds) {
  Skeleton skeleton = documented_skeleton();
  skeleton.chains[1].joint_count = 0;
  EXPECT_EQ(validate_error(skeleton), "error: chain 1 has no joints; a chain needs at least one");
  skeleton = documented_skeleton();
  skeleton.chains[1].joint_count = 3;
  EXPECT_EQ(validate_error(skeleton),
            "error: chain 1: joints 2 to 4 run past the end of the joint array (4 joints)");
  skeleton = documented_skeleton();
  skeleton.chains[1].first_joint = 4294967295u;  // no uint32 wrap-around
  EXPECT_EQ(validate_error(skeleton),
            "error: chain 1: joints 4294967295 to 4294967296 run past the end of the joint array "
            "(4 joints)");
  skeleton = documented_skeleton();
  skeleton.chains[1].first_joint = 1;
  skeleton.chains[1].parent = std::nullopt;
  EXPECT_EQ(validate_error(skeleton),
            "error: chain 1: joints start at 1, inside an earlier chain's range; ranges must be "
            "disjoint and in chain order");
}

TEST(SkeletonValidate, RejectsDanglingAndForwardParents) {
  Skeleton skeleton = documented_skeleton();
  skeleton.chains[1].parent = ChainParent{1, 0};
  EXPECT_EQ(validate_error(skeleton),
            "error: chain 1: parent chain 1 does not come before it (parents come before their "
            "children)");
  skeleton.chains[1].parent = ChainParent{0, 2};
  EXPECT_EQ(validate_error(skeleton), "error: chain 1: parent joint 2 is past the end of chain 0 (2 joints)");
}

TEST(SkeletonValidate, JointsInNoChainMustStillBeFinite) {
  Skeleton skeleton = documented_skeleton();
  skeleton.joints.push_back(joint(0, 0, 0, -1));
  EXPECT_EQ(validate_error(skeleton), "error: joint 4 (in no chain): radius -1 is negative; radii must be >= 0");
  skeleton.joints.back().radius_m = 1;
  EXPECT_EQ(validate_error(skeleton), "no error");
}

TEST(SkeletonValidate, RejectsASourceTheFormatCannotHold) {
  Skeleton skeleton = documented_skeleton();
  skeleton.source.steps = -1;
  EXPECT_EQ(validate_error(skeleton), "error: source: steps is -1; must be >= 0");
  skeleton = documented_skeleton();
  skeleton.source.defines["angle"] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validate_error(skeleton), "error: source: define \"angle\" is NaN; defines must be finite");
}

TEST(SkeletonValidate, SegmentCountIsJointsMinusOnePerChain) {
  EXPECT_EQ(documented_skeleton().segment_count(), 2u);
  EXPECT_EQ(varied_skeleton().segment_count(), 3u);  // 3 + 2 + 1 joints
  EXPECT_EQ(Skeleton{}.segment_count(), 0u);
}

// ---- errors and files -------------------------------------------------------------

TEST(SkeletonErrors, AreDiagnosticsAtTheOffendingValueWithoutSourceLine) {
  const Expected<Skeleton> result = read_skeleton_json("{\"format\": \"sylva-skeleton\",\n \"version\": 3}", kFile);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().file, kFile);
  EXPECT_EQ(result.error().loc, (SourceLoc{2, 13}));
  EXPECT_FALSE(result.error().source_line.has_value());
  EXPECT_TRUE(result.error().notes.empty());
  EXPECT_FALSE(result.cancelled());
}

class SkeletonFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = ::testing::TempDir() + "sylva-skeleton-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    directory_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }
  std::string directory_;
};

TEST_F(SkeletonFileTest, ReadsAWrittenFileBackExactly) {
  const std::string path = directory_ + "/plant.skel.json";
  const std::string text = write_skeleton_json(varied_skeleton());
  ASSERT_TRUE(write_file_atomically(path, text).ok());
  const Expected<Skeleton> result = read_skeleton_file(path);
  ASSERT_TRUE(result.ok()) << result.error().format();
  EXPECT_EQ(*result, varied_skeleton());
  EXPECT_EQ(write_skeleton_json(*result), text);
}

TEST_F(SkeletonFileTest, AMissingFileIsAnErrorNamingThePath) {
  const std::string path = directory_ + "/missing.skel.json";
  const Expected<Skeleton> result = read_skeleton_file(path);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().format(), path + ": error: cannot open for reading: No such file or directory\n");
}

TEST_F(SkeletonFileTest, ErrorsInAFileNameTheFileAndPlace) {
  const std::string path = directory_ + "/bad.skel.json";
  ASSERT_TRUE(write_file_atomically(path, "{\"format\": \"sylva-skeleton\", \"version\": 3, \"chains\": []}").ok());
  const Expected<Skeleton> result = read_skeleton_file(path);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().format(), path + ":1:41: error: unsupported version 3 of \"sylva-skeleton\"; "
                                            "this reader reads versions 1 and 2\n");
}

// ---- leaves (docs/spec/skeleton.md "Leaves", version 2) ---------------------------------------

// documented_skeleton with two leaves: a triangle on joint [1, 1] and a square on none.
Skeleton skeleton_with_leaves() {
  Skeleton sk = documented_skeleton();
  sk.leaves = {Leaf{ChainParent{1, 1}, 1, {{0.7, 1.7, 0}, {0.9, 1.8, 0.1}, {0.75, 2.0, -0.05}}, std::nullopt},
               Leaf{std::nullopt, 3, {{0, 0, 0}, {0.1, 0, 0}, {0.1, 0.1, 0}, {0, 0.1, 0}}, std::nullopt}};
  return sk;
}

TEST(SkeletonLeaves, WithLeavesTheFileIsVersion2WithOneLeafPerLineAndReadsBackEqual) {
  const Skeleton sk = skeleton_with_leaves();
  const std::string text = write_skeleton_json(sk);
  EXPECT_NE(text.find("\"version\": 2,"), std::string::npos) << text;
  EXPECT_NE(text.find("\n  ],\n  \"leaves\": [\n    {\"joint\": [1,1], \"material\": 1, \"vertices\": "
                      "[[0.7,1.7,0],[0.9,1.8,0.1],[0.75,2,-0.05]]},\n    {\"joint\": null, \"material\": 3, "),
            std::string::npos)
      << text;
  EXPECT_EQ(read_ok(text), sk);
  EXPECT_EQ(write_skeleton_json(read_ok(text)), text);
}

// A double-sided leaf's back material (docs/leaves.md "Two colours") is written after its
// material, only where it has one, and reads back equal.
TEST(SkeletonLeaves, ABackMaterialIsWrittenWhereALeafHasOneAndReadsBackEqual) {
  Skeleton sk = skeleton_with_leaves();
  sk.leaves[1].back_material = 7;
  const std::string text = write_skeleton_json(sk);
  EXPECT_NE(text.find("{\"joint\": null, \"material\": 3, \"back_material\": 7, \"vertices\": "), std::string::npos)
      << text;
  EXPECT_EQ(text.find("back_material"), text.rfind("back_material")) << "the first leaf has none";
  EXPECT_EQ(read_ok(text), sk);
  EXPECT_NE(read_ok(text), skeleton_with_leaves());
}

TEST(SkeletonLeaves, WithoutLeavesTheFileIsStillVersion1) {
  const std::string text = write_skeleton_json(documented_skeleton());
  EXPECT_NE(text.find("\"version\": 1,"), std::string::npos) << text;
  EXPECT_EQ(text.find("leaves"), std::string::npos) << text;
}

TEST(SkeletonLeaves, Version1FilesHaveNoLeavesKey) {
  const std::string e = read_error(R"({"format": "sylva-skeleton", "version": 1, "chains": [], "leaves": []})");
  EXPECT_NE(e.find("plant.skel.json:1:58: error: unknown key \"leaves\" at the top level"), std::string::npos) << e;
}

TEST(SkeletonLeaves, BadLeavesAreLocatedAndNamed) {
  auto file = [](const std::string& leaf) {
    return "{\"format\": \"sylva-skeleton\", \"version\": 2,\n \"chains\": [{\"parent\": null, \"joints\": "
           "[[0,0,0,0.1,0],[0,1,0,0.1,0]]}],\n \"leaves\": [" + leaf + "]}";
  };
  struct Bad {
    std::string leaf, says;
  };
  const Bad bad[] = {
      {R"({"joint": [0, 2], "material": 1, "vertices": [[0,0,0],[1,0,0],[0,1,0]]})",
       "3:23: error: leaf 0: joint [0, 2] is past the end of chain 0 (2 joints)"},
      {R"({"joint": [1, 0], "material": 1, "vertices": [[0,0,0],[1,0,0],[0,1,0]]})",
       "3:23: error: leaf 0: joint [1, 0] refers to chain 1 of 1 chain"},
      {R"({"joint": null, "material": 1, "vertices": [[0,0,0],[1,0,0]]})",
       "3:56: error: leaf 0: a leaf needs at least 3 distinct vertices, this polygon has 2"},
      {R"({"joint": null, "material": 1, "vertices": [[0,0,0],[1,0,0],[1,0,0]]})",
       "this polygon has 2 (3 vertices)"},
      {R"({"joint": null, "material": 1, "vertices": [[0,0,0],[1,0,0],[1,1,0],[0,1,1]]})",
       "leaf 0: the polygon is not planar: vertex "},
      {R"({"joint": null, "material": 1, "vertices": [[0,0,0],[1,0,0],[2,0,0]]})", "no area"},
      {R"({"joint": null, "material": 1, "vertices": [[0,0,0],[1,0],[2,0,0]]})",
       "leaf 0: vertex 1 must be an array of 3 numbers"},
      {R"({"joint": null, "material": -1, "vertices": []})", "leaf 0: material must be an integer"},
      {R"({"joint": null, "vertices": []})", "leaf 0: missing required key \"material\""},
      {R"({"joint": null, "material": 0, "vertices": [], "colour": 1})", "unknown key \"colour\""},
      {R"({"joint": null, "material": 0, "back_material": 1.5, "vertices": []})",
       "leaf 0: back_material must be an integer from 0 to 4294967295, got 1.5"},
  };
  for (const Bad& b : bad) EXPECT_NE(read_error(file(b.leaf)).find(b.says), std::string::npos) << read_error(file(b.leaf));
}

TEST(SkeletonLeaves, ValidateChecksLeavesToo) {
  Skeleton sk = skeleton_with_leaves();
  EXPECT_EQ(validate_error(sk), "no error");
  sk.leaves[0].joint = ChainParent{2, 0};
  EXPECT_NE(validate_error(sk).find("leaf 0: joint [2, 0] refers to chain 2 of 2 chains"), std::string::npos)
      << validate_error(sk);
  sk = skeleton_with_leaves();
  sk.leaves[1].vertices_m[2][1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validate_error(sk).find("leaf 1: vertex 2 is not finite"), std::string::npos) << validate_error(sk);
}

TEST(SkeletonLeaves, APlanarPolygonPassesAndAFoldedOneDoesNot) {
  using V = std::array<double, 3>;
  const std::vector<V> square{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  EXPECT_FALSE(leaf_polygon_problem(square).has_value());
  std::vector<V> twisted = square;
  twisted[3][2] = 0.01;  // 0.25 % of the diagonal off the plane (as a fitted plane sees it)
  EXPECT_FALSE(leaf_polygon_problem(twisted).has_value());
  twisted[3][2] = 0.5;
  ASSERT_TRUE(leaf_polygon_problem(twisted).has_value());
  EXPECT_NE(leaf_polygon_problem(twisted)->find("not planar"), std::string::npos);
}

}  // namespace
}  // namespace sylva
