// layering_test.cpp — the rooms of sylva and what each may include, held by a test
// (docs/design.md "Layout" shows the same graph): every `#include "…"` of every source
// and test file is read, and an include across an edge the graph does not allow fails,
// naming the file, the line and the rooms. A test of the test builds throwaway trees with
// one forbidden include each and expects exactly that violation.
//
// Also held here: every room's file lives in a room (nothing loose in core/), and no code
// comment points outside the repository (the contracts are docs/spec/, the papers are
// cited by authors and year, docs/papers.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace sylva {
namespace {

namespace fs = std::filesystem;

// The rooms and what each depends on directly (the graph is closed transitively below).
// Data flows one way: grammar → grow → scene → cpu/gl → app.
const std::map<std::string, std::vector<std::string>> kDependsOn = {
    {"core/util", {}},
    {"lsystem", {"core/util"}},
    {"core/geometry", {"core/util"}},
    {"core/light", {"core/geometry"}},
    {"core/scene", {"core/light"}},
    {"core/grow", {"core/scene", "lsystem"}},  // the only room that reads grammars
    {"core/io", {"core/scene"}},
    {"core/cpu", {"core/scene"}},
    {"core/gl", {"core/scene"}},  // a sibling of core/cpu: takes cones and height maps
    {"app/front", {"core/grow", "core/io", "core/cpu", "core/gl"}},
    {"app/cli", {"app/front"}},
    {"app/bench", {"app/front"}},
    {"app/studio", {"app/front"}},
    {"app/python", {"app/front"}},
    {"app/main", {"app/cli", "app/bench", "app/studio"}},
};

// Rooms whose headers only their own room and core/grow may include directly: everything
// above core/grow reaches the grammar through core/grow/grow.h.
const std::set<std::string> kOnlyThroughGrow = {"lsystem"};

// Every room `room` may include: itself and the transitive closure of kDependsOn, less
// what may only be reached through core/grow.
std::set<std::string> allowed_rooms(const std::string& room) {
  std::set<std::string> seen{room};
  std::vector<std::string> todo{room};
  while (!todo.empty()) {
    const std::string r = todo.back();
    todo.pop_back();
    auto it = kDependsOn.find(r);
    if (it == kDependsOn.end()) continue;
    for (const std::string& d : it->second)
      if (seen.insert(d).second) todo.push_back(d);
  }
  if (room != "core/grow" && room != "lsystem")
    for (const std::string& r : kOnlyThroughGrow) seen.erase(r);
  return seen;
}

// The room of a repository path ("core/gl/render_gl.cpp" → "core/gl"), "tests/<room>" for
// tests, "" for a path in no room.
std::string room_of(const std::string& path) {
  if (path == "app/main.cpp") return "app/main";
  std::string best;
  for (const auto& [room, deps] : kDependsOn)
    if (path.rfind(room + "/", 0) == 0 && room.size() > best.size()) best = room;
  if (!best.empty()) return best;
  static const std::regex test_room(R"(^(tests/[a-z_]+)/)");
  std::smatch m;
  if (std::regex_search(path, m, test_room)) return m[1];
  return "";
}

// What a test folder may include: its room's allowed set and tests/support/ (fixtures),
// and its own folder. tests/app runs the `sylva` binary (and reads app/bench, app/front);
// tests/support, tests/fuzz and tests/layering are fixtures and tools: any room but the
// layering rule's own.
std::set<std::string> allowed_for(const std::string& room) {
  if (room.rfind("tests/", 0) != 0) return allowed_rooms(room);
  const std::string tested = room.substr(6);
  std::set<std::string> allowed;
  if (tested == "support" || tested == "fuzz" || tested == "layering") {
    for (const auto& [r, deps] : kDependsOn) allowed.insert(r);
  } else if (tested == "app") {
    allowed = allowed_rooms("app/main");
  } else {
    const std::string source_room = tested == "util" || tested == "geometry" || tested == "light" ||
                                            tested == "scene" || tested == "grow" || tested == "io" ||
                                            tested == "cpu" || tested == "gl"
                                        ? "core/" + tested
                                    : tested == "lsystem" ? "lsystem"
                                                          : "app/" + tested;
    allowed = allowed_rooms(source_room);
  }
  allowed.insert(room);
  allowed.insert("tests/support");
  return allowed;
}

struct Violation {
  std::string file;  // repository path
  int line = 0;
  std::string message;
};

std::string describe(const std::vector<Violation>& violations) {
  std::ostringstream out;
  for (const Violation& v : violations) out << v.file << ":" << v.line << ": " << v.message << "\n";
  return out.str();
}

// The source files under `root` that belong to the layering: C++ in lsystem/, core/, app/
// and tests/.
std::vector<std::string> source_files(const fs::path& root) {
  std::vector<std::string> files;
  for (const char* top : {"lsystem", "core", "app", "tests"}) {
    if (!fs::exists(root / top)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(root / top)) {
      if (!entry.is_regular_file()) continue;
      const std::string ext = entry.path().extension().string();
      if (ext != ".h" && ext != ".cpp") continue;
      files.push_back(fs::relative(entry.path(), root).generic_string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Every include across a forbidden edge under `root`, and every file of lsystem/, core/
// or app/ that is in no room.
std::vector<Violation> layering_violations(const fs::path& root) {
  static const std::regex include(R"re(^\s*#\s*include\s*"([^"]+)")re");
  std::vector<Violation> out;
  for (const std::string& file : source_files(root)) {
    const std::string room = room_of(file);
    if (room.empty()) {
      if (file.rfind("tests/", 0) != 0)
        out.push_back({file, 0, "is in no room (core/ holds rooms only: docs/design.md \"Layout\")"});
      continue;
    }
    const std::set<std::string> allowed = allowed_for(room);
    std::ifstream in(root / file);
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
      std::smatch m;
      if (!std::regex_search(text, m, include)) continue;
      const std::string target = m[1];
      if (target.find('/') == std::string::npos) continue;  // a file beside it
      const std::string target_room = room_of(target);
      if (target_room.empty() || allowed.count(target_room)) continue;
      std::string why = room + " may not include " + target;
      if (kOnlyThroughGrow.count(target_room)) why += " (" + target_room + "/ is reached through core/grow/grow.h)";
      out.push_back({file, line, why});
    }
  }
  return out;
}

TEST(Layering, EveryIncludeInTheRepositoryFollowsTheGraph) {
  const std::vector<Violation> v = layering_violations(SYLVA_SOURCE_DIR);
  EXPECT_TRUE(v.empty()) << describe(v);
  // The scan saw the tree: every room has files.
  std::set<std::string> rooms;
  for (const std::string& f : source_files(SYLVA_SOURCE_DIR)) rooms.insert(room_of(f));
  for (const auto& [room, deps] : kDependsOn) EXPECT_TRUE(rooms.count(room)) << room << " has no source file";
}

TEST(Layering, TheGraphIsOneWay) {
  // No room reaches itself through its dependencies.
  for (const auto& [room, deps] : kDependsOn)
    for (const std::string& d : deps) EXPECT_FALSE(allowed_rooms(d).count(room)) << room << " <-> " << d;
  EXPECT_FALSE(allowed_rooms("core/gl").count("core/cpu"));
  EXPECT_FALSE(allowed_rooms("core/cpu").count("core/gl"));
  EXPECT_FALSE(allowed_rooms("core/scene").count("lsystem"));
  EXPECT_TRUE(allowed_rooms("core/grow").count("lsystem"));
  EXPECT_FALSE(allowed_rooms("app/front").count("lsystem"));
}

// A throwaway tree under the test's temporary folder.
class Tree {
 public:
  Tree() : root_(fs::path(testing::TempDir()) / ("layering_" + std::to_string(counter_++))) {
    fs::remove_all(root_);
  }
  ~Tree() { fs::remove_all(root_); }
  void write(const std::string& path, const std::string& text) {
    fs::create_directories((root_ / path).parent_path());
    std::ofstream(root_ / path) << text;
  }
  const fs::path& root() const { return root_; }

 private:
  static inline int counter_ = 0;
  fs::path root_;
};

TEST(LayeringOfTheTest, AThrowawayIncludeOfCpuFromGlFails) {
  Tree t;
  t.write("core/cpu/photons.h", "#pragma once\n");
  t.write("core/scene/scene.h", "#pragma once\n");
  t.write("core/gl/render_gl.cpp", "#include \"core/scene/scene.h\"\n// #include nothing\n#include \"core/cpu/photons.h\"\n");
  const std::vector<Violation> v = layering_violations(t.root());
  ASSERT_EQ(v.size(), 1u) << describe(v);
  EXPECT_EQ(v[0].file, "core/gl/render_gl.cpp");
  EXPECT_EQ(v[0].line, 3);
  EXPECT_EQ(v[0].message, "core/gl may not include core/cpu/photons.h");
}

TEST(LayeringOfTheTest, LsystemOutsideCoreGrowFails) {
  Tree t;
  t.write("lsystem/grammar.h", "#pragma once\n");
  t.write("core/grow/grow.h", "#include \"lsystem/grammar.h\"\n");
  t.write("core/scene/scene.cpp", "#include \"lsystem/grammar.h\"\n");
  t.write("app/cli/cli_grow.cpp", "#include \"core/grow/grow.h\"\n  #  include \"lsystem/grammar.h\"\n");
  const std::vector<Violation> v = layering_violations(t.root());
  ASSERT_EQ(v.size(), 2u) << describe(v);
  EXPECT_EQ(v[0].file, "app/cli/cli_grow.cpp");
  EXPECT_EQ(v[0].line, 2);
  EXPECT_EQ(v[0].message, "app/cli may not include lsystem/grammar.h (lsystem/ is reached through core/grow/grow.h)");
  EXPECT_EQ(v[1].file, "core/scene/scene.cpp");
}

TEST(LayeringOfTheTest, UpwardIncludesAndLooseFilesFail) {
  Tree t;
  t.write("core/geometry/skin.cpp", "#include \"core/scene/scene.h\"\n");  // geometry below scene
  t.write("core/util/json.cpp", "#include \"core/geometry/skeleton.h\"\n");
  t.write("core/loose.h", "#pragma once\n");
  t.write("tests/cpu/x_test.cpp", "#include \"core/gl/render_gl.h\"\n#include \"tests/support/plants.h\"\n");
  const std::vector<Violation> v = layering_violations(t.root());
  ASSERT_EQ(v.size(), 4u) << describe(v);
  EXPECT_EQ(v[0].file, "core/geometry/skin.cpp");
  EXPECT_EQ(v[1].file, "core/loose.h");
  EXPECT_EQ(v[1].line, 0);
  EXPECT_EQ(v[2].file, "core/util/json.cpp");
  EXPECT_EQ(v[3].file, "tests/cpu/x_test.cpp");
  EXPECT_EQ(v[3].message, "tests/cpu may not include core/gl/render_gl.h");
}

TEST(LayeringOfTheTest, AllowedIncludesPass) {
  Tree t;
  t.write("core/gl/render_gl.cpp", "#include \"core/scene/scene.h\"\n#include \"core/light/fog.h\"\n#include <vector>\n");
  t.write("app/front/render.cpp", "#include \"core/cpu/photons.h\"\n#include \"core/gl/render_gl.h\"\n");
  t.write("app/main.cpp", "#include \"app/cli/cli.h\"\n#include \"app/studio/studio.h\"\n");
  t.write("tests/gl/x_test.cpp", "#include \"core/gl/render_gl.h\"\n#include \"tests/support/gl_checks.h\"\n");
  const std::vector<Violation> v = layering_violations(t.root());
  EXPECT_TRUE(v.empty()) << describe(v);
}

// ---- Comments point inside the repository -------------------------------------------------

// Places in code (C++, GLSL, CMake, scripts) that point outside the repository: the shared
// folders beside it ("../shared/…"), a contract cited as "spec/NAME.md" without docs/, the
// research notes beside it (notes/, studio-gui.md, fog-speed.md, light-growth.md), or a
// paper by its number ("paper 000"): the contracts are docs/spec/, the papers are cited
// by authors and year (docs/papers.md).
std::vector<Violation> outside_pointers(const fs::path& root) {
  static const std::regex outside(
      R"re((\.\./shared/|(^|[^/a-z_])spec/[a-z]+\.md|(^|[^/a-z_-])(notes/|studio-gui\.md|fog-speed\.md|light-growth\.md)|\bpapers?/0\d\d|\bpaper 00\d))re");
  std::vector<Violation> out;
  for (const char* top : {"lsystem", "core", "app", "tests", "shaders", "scripts"}) {
    if (!fs::exists(root / top)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(root / top)) {
      if (!entry.is_regular_file()) continue;
      const std::string ext = entry.path().extension().string();
      const std::string name = entry.path().filename().string();
      if (ext != ".h" && ext != ".cpp" && ext != ".glsl" && ext != ".py" && ext != ".sh" && ext != ".cmake" &&
          ext != ".mjs" && name != "CMakeLists.txt")
        continue;
      const std::string file = fs::relative(entry.path(), root).generic_string();
      if (file == "tests/layering/layering_test.cpp") continue;  // this test names the patterns
      std::ifstream in(entry.path());
      std::string text;
      for (int line = 1; std::getline(in, text); ++line)
        if (std::regex_search(text, outside)) out.push_back({file, line, "points outside the repository: " + text});
    }
  }
  return out;
}

TEST(Comments, NoCodePointsOutsideTheRepository) {
  const std::vector<Violation> v = outside_pointers(SYLVA_SOURCE_DIR);
  EXPECT_TRUE(v.empty()) << v.size() << " places:\n" << describe(v);
}

TEST(CommentsOfTheTest, TheSharedFolderABareSpecAndAPaperNumberAreFound) {
  Tree t;
  t.write("core/a.h", "// see ../shared/spec/fog.md\n// spec/fog.md sec. 2\n// docs/spec/fog.md is fine\n");
  t.write("shaders/b.glsl", "// paper 000, eq. 7\n// Bhagvat et al. 2009, eq. 7\n// as studio-gui.md sec. 1 says\n");
  const std::vector<Violation> v = outside_pointers(t.root());
  ASSERT_EQ(v.size(), 4u) << describe(v);
  EXPECT_EQ(v[0].line, 1);
  EXPECT_EQ(v[1].line, 2);
  EXPECT_EQ(v[2].file, "shaders/b.glsl");
  EXPECT_EQ(v[3].line, 3);
}

}  // namespace
}  // namespace sylva
