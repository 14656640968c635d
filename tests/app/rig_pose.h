// rig_pose.h — sylva's own pose of an exported rig, for the tests that play the wind clip
// in another program (three.js: export_rig_cli_test.cpp; Blender: blender_check_test.cpp):
// the plant read back from the file, its rig rebuilt (build_rig is deterministic), the
// scene's sway with its frequencies rounded to loop, and the placement of the plant node.
#pragma once

#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "core/io/gltf.h"
#include "core/io/gltf_rig.h"
#include "core/scene/animate.h"
#include "core/scene/scene_json.h"
#include "core/util/json.h"
#include "tests/support/process.h"

namespace sylva::test {

// A scene of one plant of `grammar`, placed (moved, turned, scaled), with the `animation`
// key `animation` (JSON), written into `dir`.
inline std::string placed_scene(const TempDir& dir, const std::string& grammar, const std::string& animation) {
  return dir.write("placed.scene.json", R"({"format":"sylva-scene","version":1,"plants":[
    {"grammar":")" + grammar + R"(","position":[2,0,-1],"rotate_y_deg":30,"scale":1.5}],
    "animation":)" + animation + "}");
}

// The JSON after `marker` on a line of `out` (a script's report line).
inline Expected<JsonValue> report_after(const std::string& out, const std::string& marker) {
  const size_t at = out.find(marker);
  if (at == std::string::npos) return file_diagnostic("", "no " + marker + "line");
  return parse_json(out.substr(at + marker.size(), out.find('\n', at) - at - marker.size()));
}

inline std::vector<double> numbers_of(const JsonValue& array) {
  std::vector<double> out;
  for (const JsonValue& v : array.elements) out.push_back(v.number);
  return out;
}

// The influences of vertex v of three_check.mjs's "skin" array (8 numbers a vertex).
inline RigWeights weights_of(const std::vector<double>& skin, size_t v) {
  RigWeights w;
  w.count = 0;
  for (size_t k = 0; k < 4; ++k)
    if (skin[8 * v + 4 + k] > 0 && w.count < 2) {
      w.joints[static_cast<size_t>(w.count)] = static_cast<uint32_t>(skin[8 * v + k]);
      w.weights[static_cast<size_t>(w.count)] = static_cast<float>(skin[8 * v + 4 + k]);
      ++w.count;
    }
  return w;
}

// The rig of the one plant of `glb` (exported from the scene `scene_path` with --rig
// --animation) posed as sylva poses it.
class SylvaRigPose {
 public:
  SylvaRigPose(const std::string& glb, const std::string& scene_path) {
    Expected<std::vector<GltfPlant>> plants = import_gltf_skeletons(glb);
    if (!plants || plants->size() != 1) throw std::runtime_error("cannot read the one plant of " + glb);
    plant_ = plants->front();
    Expected<Scene> scene = read_scene_file(scene_path);
    if (!scene || !scene->animation) throw std::runtime_error("cannot read the animated scene " + scene_path);
    Expected<Rig> rig = build_rig(plant_.skeleton);
    if (!rig) throw std::runtime_error(rig.error().message);
    rig_ = std::move(*rig);
    sway_ = plant_sway_parameters(sway_parameters_of(*scene->animation), 0);
    sway_.loop_period_s = scene->animation->duration_s;
    axis_ = *sway_axis(sway_);
    turn_ = glm::angleAxis(glm::radians(plant_.rotate_y_deg), glm::dvec3(0, 1, 0));
  }

  const Rig& rig() const { return rig_; }

  // The plant's height (its joints' span in Y) as placed, metres.
  double placed_height_m() const {
    double lo = 1e300, hi = -1e300;
    for (const Joint& j : plant_.skeleton.joints) lo = std::min(lo, j.position_m[1]), hi = std::max(hi, j.position_m[1]);
    return plant_.scale * (hi - lo);
  }

  // The rig's joints at t_s.
  std::vector<RigJointPose> pose(double t_s) const {
    return pose_rig(rig_, axis_, sway_joint_angles(plant_.skeleton, t_s, sway_));
  }

  // `rest_m` (the file's POSITION) skinned with `weights` in `pose`, placed in the world.
  glm::dvec3 posed(const std::vector<RigJointPose>& pose, const RigWeights& weights, const glm::dvec3& rest_m) const {
    return placed(skin_point(rig_, pose, axis_, weights, rest_m));
  }

  glm::dvec3 placed(const glm::dvec3& p) const {
    return glm::dvec3(plant_.position_m[0], plant_.position_m[1], plant_.position_m[2]) + turn_ * (plant_.scale * p);
  }

 private:
  GltfPlant plant_;
  Rig rig_;
  SwayParameters sway_;
  glm::dvec3 axis_{0};
  glm::dquat turn_{1, 0, 0, 0};
};

}  // namespace sylva::test
