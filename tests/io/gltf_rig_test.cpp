// gltf_rig_test.cpp — core/io/gltf_rig.h and the rigged glTF export: the joint tree's
// limits, the weights, a rig on every joint reproducing sway_skeleton exactly, the wind
// clip read back with tinygltf and posed in sylva's own code against the renderer's sway
// (sway_skeleton) on the rigged joints, its loop, and the errors that write nothing.
#include "core/io/gltf_rig.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "core/io/gltf.h"
#include "core/scene/animate.h"
#include "tests/io/tinygltf_read.h"
#include "core/geometry/crotch_mesh.h"
#include "tests/support/limb_crotch.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

namespace fs = std::filesystem;
using test::floats_of;
using test::load_with_tinygltf;
using test::u16s_of;

// A branching plant with leaves on its joints.
constexpr const char* kSmallPlant =
    "angle: 30\nwidth: 0.1\nderivation length: 3\n"
    "axiom: F(1)A\n"
    "A -> !(0.7)F(0.8)[+F(0.5)A{.+f(0.2)-f(0.2)-f(0.2)}][-/F(0.5)A]F(0.6)A\n";

glm::dvec3 joint_position(const Skeleton& sk, uint32_t j) {
  return {sk.joints[j].position_m[0], sk.joints[j].position_m[1], sk.joints[j].position_m[2]};
}

double plant_height(const Skeleton& sk) {
  double lo = 1e300, hi = -1e300;
  for (const Joint& j : sk.joints) lo = std::min(lo, j.position_m[1]), hi = std::max(hi, j.position_m[1]);
  return hi - lo;
}

std::string temp_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("sylva-rig-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

TEST(GltfRig, TheJointTreeKeepsItsLimitsAndParentsComeFirst) {
  const Skeleton elm = test::grow_preset("elm");
  for (uint32_t max_joints : {2u, 8u, 128u, 1024u}) {
    Expected<Rig> rig = build_rig(elm, {.max_joints = max_joints});
    ASSERT_TRUE(rig) << rig.error().format();
    EXPECT_LE(rig->joints.size(), max_joints);
    EXPECT_LE(rig->max_depth(), kMaxRigDepth);
    EXPECT_EQ(rig->joints[0].skeleton_joint, kNoRigJoint);
    EXPECT_EQ(rig->joints[0].position_m, glm::dvec3(0));
    for (size_t j = 1; j < rig->joints.size(); ++j) {
      const RigJoint& joint = rig->joints[j];
      ASSERT_LT(joint.parent, j);
      EXPECT_EQ(joint.depth, rig->joints[joint.parent].depth + 1);
      EXPECT_EQ(joint.position_m, joint_position(elm, joint.skeleton_joint));
    }
    // Every chain of order <= full_order with a segment is rigged.
    std::vector<uint32_t> order(elm.chains.size(), 0);
    for (size_t c = 0; c < elm.chains.size(); ++c) {
      if (elm.chains[c].parent) order[c] = order[elm.chains[c].parent->chain] + 1;
      if (order[c] <= rig->full_order && elm.chains[c].joint_count >= 2) {
        EXPECT_FALSE(rig->chain_joints[c].empty()) << "chain " << c << " with " << max_joints << " joints";
      }
    }
  }
  // One joint, the root alone, cannot carry the trunk.
  EXPECT_FALSE(build_rig(elm, {.max_joints = 1}));
  // The default rig of the elm: its trunk and limbs, well used.
  Expected<Rig> rig = build_rig(elm);
  ASSERT_TRUE(rig);
  EXPECT_GT(rig->joints.size(), 64u);
  EXPECT_GT(rig->rigged_chains, 10u);
}

TEST(GltfRig, ALongChainStaysWithinTheDepthBlenderImports) {
  Skeleton sk;
  constexpr uint32_t kSegments = 3000;
  for (uint32_t k = 0; k <= kSegments; ++k) sk.joints.push_back({{0, 0.01 * k, 0}, 0.05, 0});
  sk.chains = {{0, kSegments + 1, std::nullopt}};
  Expected<Rig> rig = build_rig(sk, {.max_joints = 1024});
  ASSERT_TRUE(rig);
  EXPECT_LE(rig->max_depth(), kMaxRigDepth);
  // As fine as the depth allows: the smallest step whose joints fit 512 levels.
  EXPECT_EQ(rig->step, (kSegments + kMaxRigDepth - 1) / kMaxRigDepth);
  EXPECT_EQ(rig->max_depth(), (kSegments + rig->step - 1) / rig->step);
}

TEST(GltfRig, TooManyRootChainsForTheJointsIsAnError) {
  Skeleton sk;
  for (uint32_t c = 0; c < 5; ++c) {
    sk.joints.push_back({{double(c), 0, 0}, 0.1, 0});
    sk.joints.push_back({{double(c), 1, 0}, 0.1, 0});
    sk.chains.push_back({2 * c, 2, std::nullopt});
  }
  EXPECT_TRUE(build_rig(sk, {.max_joints = 6}));
  Expected<Rig> rig = build_rig(sk, {.max_joints = 5});
  ASSERT_FALSE(rig);
  EXPECT_NE(rig.error().message.find("5 root chains"), std::string::npos) << rig.error().message;
}

TEST(GltfRig, WeightsAreAtMostTwoNonNegativeSummingToOneAndExactAtJoints) {
  const Skeleton elm = test::grow_preset("elm");
  Expected<Rig> rig = build_rig(elm);
  ASSERT_TRUE(rig);
  for (uint32_t c = 0; c < elm.chains.size(); ++c) {
    const Chain& chain = elm.chains[c];
    const double length = rig->arc_m[chain.first_joint + chain.joint_count - 1];
    for (double s : {-0.1, 0.0, 0.25 * length, 0.5 * length, length, length + 1}) {
      const RigWeights w = rig_weights(*rig, elm, c, s);
      ASSERT_GE(w.count, 1);
      ASSERT_LE(w.count, 2);
      float sum = 0;
      for (int i = 0; i < w.count; ++i) {
        EXPECT_GT(w.weights[static_cast<size_t>(i)], 0);
        EXPECT_LT(w.joints[static_cast<size_t>(i)], rig->joints.size());
        sum += w.weights[static_cast<size_t>(i)];
      }
      EXPECT_NEAR(sum, 1, 2e-7);
      if (w.count == 2) {
        EXPECT_NE(w.joints[0], w.joints[1]);
      }
    }
  }
  // A point on a rig joint rides on that joint alone.
  for (size_t j = 1; j < rig->joints.size(); ++j) {
    const RigJoint& joint = rig->joints[j];
    const RigWeights w = rig_weights(*rig, elm, joint.chain, rig->arc_m[joint.skeleton_joint]);
    ASSERT_EQ(w.count, 1);
    EXPECT_EQ(w.joints[0], j);
  }
}

TEST(GltfRig, ARigOnEveryJointPosesExactlyAsTheRenderersSway) {
  const Skeleton sk = test::grown(kSmallPlant);
  ASSERT_GT(sk.chains.size(), 4u);
  Expected<Rig> rig = build_rig(sk, {.max_joints = kMaxRigJoints, .max_order = 100});
  ASSERT_TRUE(rig);
  ASSERT_EQ(rig->step, 1u);
  SwayParameters sway;
  sway.amplitude_deg = 9;
  sway.branch_amplitude_deg = 14;
  sway.wind_direction = {0.6, 0.3, -0.8};
  const glm::dvec3 axis = *sway_axis(sway);
  for (double t : {0.3, 1.1, 2.9}) {
    const Skeleton swayed = sway_skeleton(sk, t, sway);
    const std::vector<RigJointPose> pose = pose_rig(*rig, axis, sway_joint_angles(sk, t, sway));
    double moved = 0;
    for (size_t j = 1; j < rig->joints.size(); ++j) {
      const glm::dvec3 expected = joint_position(swayed, rig->joints[j].skeleton_joint);
      EXPECT_LT(glm::length(pose[j].position_m - expected), 1e-12) << "joint " << j << " at t " << t;
      moved = std::max(moved, glm::length(expected - rig->joints[j].position_m));
    }
    EXPECT_GT(moved, 0.01) << "the sway must move something at t " << t;
    // Every tip joint, skinned on its chain's last rig joint, lands where the sway puts it
    // (the segment below a tip turns with the joint it leaves).
    for (uint32_t c = 0; c < sk.chains.size(); ++c) {
      const Chain& chain = sk.chains[c];
      if (chain.joint_count < 2) continue;
      const uint32_t tip = chain.first_joint + chain.joint_count - 1;
      const glm::dvec3 skinned =
          skin_point(*rig, pose, axis, rig_weights(*rig, sk, c, rig->arc_m[tip]), joint_position(sk, tip));
      EXPECT_LT(glm::length(skinned - joint_position(swayed, tip)), 1e-6) << "tip of chain " << c;
    }
  }
}

// The local rotations of every node the file's wind clip animates, at key `key`.
std::map<int, glm::dquat> clip_rotations(const tinygltf::Model& model, size_t key) {
  std::map<int, glm::dquat> out;
  const tinygltf::Animation& clip = model.animations.at(0);
  for (const tinygltf::AnimationChannel& channel : clip.channels) {
    EXPECT_EQ(channel.target_path, "rotation");
    const tinygltf::AnimationSampler& sampler = clip.samplers.at(static_cast<size_t>(channel.sampler));
    EXPECT_EQ(sampler.interpolation, "LINEAR");
    const std::vector<float> q = floats_of(model, sampler.output);
    out[channel.target_node] = glm::dquat(q.at(4 * key + 3), q.at(4 * key), q.at(4 * key + 1), q.at(4 * key + 2));
  }
  return out;
}

TEST(GltfRig, TheWindClipPosesTheRiggedJointsAsTheRendererSwaysThem) {
  const Skeleton elm = test::grow_preset("elm");
  GltfPlant plant;
  plant.name = "elm";
  plant.skeleton = elm;
  GltfWindClip clip;  // the default sway over 4 s at 24 fps
  GltfExportOptions options{.mesh = true, .segments_around = 5, .rig = true, .animation = clip};
  const std::string path = temp_path("elm_wind.glb");
  ASSERT_TRUE(export_gltf({plant}, path, options));
  tinygltf::Model model;
  ASSERT_TRUE(load_with_tinygltf(path, &model));
  ASSERT_EQ(model.skins.size(), 1u);
  ASSERT_EQ(model.animations.size(), 1u);
  const tinygltf::Skin& skin = model.skins[0];
  Expected<Rig> rig = build_rig(elm);
  ASSERT_TRUE(rig);
  ASSERT_EQ(skin.joints.size(), rig->joints.size());
  EXPECT_EQ(skin.skeleton, skin.joints[0]);
  // The skinned mesh node is a scene root, the rig under the plant's node.
  const std::vector<int>& roots = model.scenes.at(0).nodes;
  ASSERT_EQ(roots.size(), 2u);
  EXPECT_EQ(model.nodes.at(static_cast<size_t>(roots[1])).skin, 0);
  EXPECT_EQ(model.nodes.at(static_cast<size_t>(roots[0])).children, std::vector<int>{skin.joints[0]});

  const std::vector<float> times = floats_of(model, model.animations[0].samplers.at(0).input);
  const uint64_t intervals = wind_clip_intervals(clip);
  ASSERT_EQ(intervals, 96u);
  ASSERT_EQ(times.size(), intervals + 1);
  EXPECT_EQ(times.front(), 0.0f);
  EXPECT_EQ(times.back(), 4.0f);

  // Frame 0 is the rest pose and the last key is the first: the clip loops.
  for (const auto& [node, q] : clip_rotations(model, 0)) EXPECT_EQ(q, glm::dquat(1, 0, 0, 0)) << "node " << node;
  EXPECT_EQ(clip_rotations(model, 0), clip_rotations(model, intervals));

  // The joints posed by the file's keys (forward kinematics from the rig root, the
  // node translations as written) against the renderer's sway, frequencies rounded to
  // loop over 4 s, at three frames.
  SwayParameters sway = plant_sway_parameters(clip.sway, 0);
  sway.loop_period_s = clip.duration_s;
  const double height = plant_height(elm);
  std::map<int, size_t> rig_index;
  for (size_t j = 0; j < skin.joints.size(); ++j) rig_index[skin.joints[j]] = j;
  double worst = 0, moved = 0;
  for (size_t key : {17u, 40u, 71u}) {
    const double t = clip.duration_s * static_cast<double>(key) / static_cast<double>(intervals);
    const Skeleton swayed = sway_skeleton(elm, t, sway);
    const std::map<int, glm::dquat> local = clip_rotations(model, key);
    std::vector<glm::dquat> world_q(rig->joints.size(), glm::dquat(1, 0, 0, 0));
    std::vector<glm::dvec3> world_p(rig->joints.size(), glm::dvec3(0));
    for (size_t j = 1; j < rig->joints.size(); ++j) {
      const int node = skin.joints[j];
      const tinygltf::Node& n = model.nodes.at(static_cast<size_t>(node));
      const size_t parent = rig->joints[j].parent;
      const glm::dvec3 translation = n.translation.empty() ? glm::dvec3(0)
                                                           : glm::dvec3(n.translation[0], n.translation[1], n.translation[2]);
      const auto it = local.find(node);
      world_p[j] = world_p[parent] + world_q[parent] * translation;
      world_q[j] = world_q[parent] * (it == local.end() ? glm::dquat(1, 0, 0, 0) : it->second);
      const glm::dvec3 expected = joint_position(swayed, rig->joints[j].skeleton_joint);
      worst = std::max(worst, glm::length(world_p[j] - expected));
      moved = std::max(moved, glm::length(expected - rig->joints[j].position_m));
    }
  }
  EXPECT_GT(moved, 0.05 * height * 0.2);  // the sway moves the crown visibly
  // The stated tolerance (docs/gltf.md "Rig and wind clip"): 1 % of the plant's height
  // with the default sway on the default rig.
  EXPECT_LT(worst, 0.01 * height) << "worst " << worst << " m of " << height << " m";
  RecordProperty("rig_joint_error_over_height", std::to_string(worst / height));

  // Every vertex's weights: at most two used, normalised exactly (unsigned shorts summing
  // to 65535), no joint twice; joints as bytes (101 joints).
  const tinygltf::Primitive& prim = model.meshes.at(static_cast<size_t>(model.nodes.at(static_cast<size_t>(roots[1])).mesh))
                                        .primitives.at(0);
  const tinygltf::Accessor& weight_accessor = model.accessors.at(static_cast<size_t>(prim.attributes.at("WEIGHTS_0")));
  EXPECT_TRUE(weight_accessor.normalized);
  const std::vector<uint8_t> joints =
      test::components_of<uint8_t>(model, prim.attributes.at("JOINTS_0"), TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE);
  const std::vector<uint16_t> weights = u16s_of(model, prim.attributes.at("WEIGHTS_0"));
  ASSERT_EQ(joints.size(), weights.size());
  for (size_t v = 0; v < joints.size(); v += 4) {
    uint32_t sum = 0;
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_LT(joints[v + k], rig->joints.size());
      sum += weights[v + k];
      if (k >= 2) {
        EXPECT_EQ(weights[v + k], 0);
      }
    }
    EXPECT_EQ(sum, 65535u);
    if (weights[v + 1] > 0) {
      EXPECT_NE(joints[v], joints[v + 1]);
    }
  }
  fs::remove(path);
}

TEST(GltfRig, RiggingErrorsNameTheirCauseAndWriteNothing) {
  GltfPlant plant;
  plant.name = "small";
  plant.skeleton = test::grown(kSmallPlant);
  const std::string path = temp_path("refused.glb");
  fs::remove(path);
  auto refused = [&](const GltfExportOptions& options, const std::string& words) {
    Status s = export_gltf({plant, plant}, path, options);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find(words), std::string::npos) << s.error().message;
    EXPECT_FALSE(fs::exists(path));
  };
  refused({.rig = true}, "export the mesh too");
  refused({.mesh = true, .instancing = true, .rig = true}, "cannot be instanced");
  refused({.mesh = true, .rig = true, .max_joints = 0}, "from 1 to 1024");
  refused({.mesh = true, .rig = true, .max_joints = 1025}, "from 1 to 1024");
  refused({.mesh = true, .animation = GltfWindClip{}}, "export the rig too");
  GltfWindClip still;
  still.sway.wind_direction = {0, 1, 0};
  refused({.mesh = true, .rig = true, .animation = still}, "moves no joint");
  GltfWindClip calm;
  calm.sway.amplitude_deg = 0;
  calm.sway.branch_amplitude_deg = 0;
  refused({.mesh = true, .rig = true, .animation = calm}, "moves no joint");
  GltfWindClip long_clip;
  long_clip.duration_s = 3600;  // 3.6 million keys
  long_clip.fps = 1000;
  refused({.mesh = true, .rig = true, .animation = long_clip}, "keys");
  GltfWindClip no_time;
  no_time.duration_s = 0;
  refused({.mesh = true, .rig = true, .animation = no_time}, "duration");
}

TEST(GltfWindData, PivotLevelAndPhaseOfEveryVertexAreItsChainsAndLeaves) {
  GltfPlant plant;
  plant.name = "small";
  plant.skeleton = test::grown(kSmallPlant);
  const Skeleton& sk = plant.skeleton;
  ASSERT_FALSE(sk.leaves.empty());
  const std::string path = temp_path("wind_data.glb");
  ASSERT_TRUE(export_gltf({plant}, path, {.mesh = true, .wind_data = true, .wind_seed = 11}));
  tinygltf::Model model;
  ASSERT_TRUE(load_with_tinygltf(path, &model));
  const uint64_t seed = plant_sway_parameters(SwayParameters{.seed = 11}, 0).seed;
  const std::vector<uint32_t> order = chain_orders(sk);
  size_t wood = 0, leaf = 0;
  for (const tinygltf::Primitive& prim : model.meshes.at(0).primitives) {
    if (prim.mode != TINYGLTF_MODE_TRIANGLES) continue;
    ASSERT_EQ(prim.attributes.count("TEXCOORD_1"), 1u);  // no gap before TEXCOORD_2
    const std::vector<float> xy = floats_of(model, prim.attributes.at("TEXCOORD_2"));
    const std::vector<float> zl = floats_of(model, prim.attributes.at("TEXCOORD_3"));
    const std::vector<float> positions = floats_of(model, prim.attributes.at("POSITION"));
    ASSERT_EQ(xy.size(), zl.size());
    const bool leaves = model.materials.at(static_cast<size_t>(prim.material)).name.starts_with("sylva_leaf");
    for (size_t v = 0; v < xy.size() / 2; ++v) {
      const glm::dvec3 pivot(xy[2 * v], xy[2 * v + 1], zl[2 * v]);
      const float level = std::floor(zl[2 * v + 1]);
      const float phase = zl[2 * v + 1] - level;
      ASSERT_GE(phase, 0);
      ASSERT_LT(phase, 1);
      // Some chain (or, for a leaf, some joint) has exactly this pivot, level and phase.
      bool found = false;
      for (uint32_t c = 0; c < sk.chains.size() && !found; ++c) {
        const float want_phase = static_cast<float>(chain_flutter_draw(seed, c));
        if (std::abs(phase - want_phase) > 1e-5f) continue;
        if (leaves) {
          if (level != static_cast<float>(order[c] + 1)) continue;
          for (uint32_t j = 0; j < sk.chains[c].joint_count && !found; ++j)
            found = glm::length(pivot - joint_position(sk, sk.chains[c].first_joint + j)) < 1e-5;
        } else {
          found = level == static_cast<float>(order[c]) &&
                  glm::length(pivot - joint_position(sk, sk.chains[c].first_joint)) < 1e-5;
        }
      }
      EXPECT_TRUE(found) << (leaves ? "leaf" : "wood") << " vertex " << v << " at " << positions[3 * v] << ", "
                         << positions[3 * v + 1] << ", " << positions[3 * v + 2];
      ++(leaves ? leaf : wood);
    }
  }
  EXPECT_GT(wood, 100u);
  EXPECT_GT(leaf, 10u);
  // Wind data without a mesh is refused.
  fs::remove(path);
  EXPECT_FALSE(export_gltf({plant}, path, {.wind_data = true}));
  EXPECT_FALSE(fs::exists(path));
}

// With SkinOptions::blend_crotches the mesh carries each crotch's fillet (crotch_mesh.h):
// its triangles besides the frusta's, every fillet vertex written, riding on the trunk's or
// the limb's chain in the wind data; the coarser levels of detail leave them out.
TEST(GltfCrotches, TheMeshCarriesTheFilletsWithTheirChainsWindData) {
  GltfPlant plant;
  plant.name = "limb";
  plant.skeleton = test::limb_on_trunk();
  const Skeleton& sk = plant.skeleton;
  SkinOptions blended;
  blended.blend_crotches = true;
  const TriangleMesh fillets = asset_fillets(sk, skin_skeleton(sk).frusta);
  ASSERT_GT(fillets.triangle_count(), 100u);
  auto triangles_and_positions = [&](const GltfExportOptions& options, const std::string& name) {
    const std::string path = temp_path(name);
    EXPECT_TRUE(export_gltf({plant}, path, options));
    tinygltf::Model model;
    EXPECT_TRUE(load_with_tinygltf(path, &model));
    size_t triangles = 0;
    std::vector<glm::dvec3> positions;
    std::vector<glm::dvec3> pivots;
    for (const tinygltf::Primitive& prim : model.meshes.at(0).primitives) {
      if (prim.mode != TINYGLTF_MODE_TRIANGLES) continue;
      triangles += model.accessors.at(static_cast<size_t>(prim.indices)).count / 3;
      const std::vector<float> p = floats_of(model, prim.attributes.at("POSITION"));
      const std::vector<float> xy = floats_of(model, prim.attributes.at("TEXCOORD_2"));
      const std::vector<float> zl = floats_of(model, prim.attributes.at("TEXCOORD_3"));
      for (size_t v = 0; v < p.size() / 3; ++v) {
        positions.emplace_back(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
        pivots.emplace_back(xy[2 * v], xy[2 * v + 1], zl[2 * v]);
      }
    }
    fs::remove(path);
    return std::make_tuple(triangles, positions, pivots);
  };
  GltfExportOptions plain_options{.mesh = true, .wind_data = true};
  plain_options.skin.blend_crotches = false;
  GltfExportOptions blended_options = plain_options;
  blended_options.skin = blended;
  const auto [plain, plain_positions, plain_pivots] = triangles_and_positions(plain_options, "plain.glb");
  const auto [with, positions, pivots] = triangles_and_positions(blended_options, "blended.glb");
  EXPECT_EQ(with, plain + fillets.triangle_count());
  // Every fillet vertex is written, pivoting about the first joint of the trunk or the limb.
  size_t on_trunk = 0, on_limb = 0;
  for (const glm::dvec3& want : fillets.positions) {
    size_t found = positions.size();
    for (size_t v = 0; v < positions.size() && found == positions.size(); ++v)
      if (glm::length(positions[v] - want) < 1e-5) found = v;
    ASSERT_LT(found, positions.size()) << want.x << ", " << want.y << ", " << want.z;
    if (glm::length(pivots[found] - joint_position(sk, sk.chains[0].first_joint)) < 1e-5) ++on_trunk;
    if (glm::length(pivots[found] - joint_position(sk, sk.chains[1].first_joint)) < 1e-5) ++on_limb;
  }
  EXPECT_GT(on_trunk, 10u);
  EXPECT_GT(on_limb, 10u);
  EXPECT_EQ(on_trunk + on_limb, fillets.positions.size());
  // The paper's skin has no fillets, whatever the options ask.
  plant.skin = SkinStyle::paper;
  const auto [paper, paper_positions, paper_pivots] = triangles_and_positions(blended_options, "paper.glb");
  const auto [paper_plain, pp, pq] = triangles_and_positions(plain_options, "paper_plain.glb");
  EXPECT_EQ(paper, paper_plain);
}

TEST(SwayLoop, ALoopPeriodRoundsEveryFrequencySoTheSwayRepeats) {
  EXPECT_EQ(looping_frequency_hz(0.4, 4), 0.5);
  EXPECT_EQ(looping_frequency_hz(0.1, 4), 0.25);  // at least one cycle
  EXPECT_EQ(looping_frequency_hz(0, 4), 0);
  EXPECT_EQ(looping_frequency_hz(1.13, 0), 1.13);  // no loop: unchanged
  const Skeleton sk = test::grown(kSmallPlant);
  SwayParameters sway;
  sway.loop_period_s = 3;
  for (double t : {0.2, 1.7}) {
    const Skeleton a = sway_skeleton(sk, t, sway), b = sway_skeleton(sk, t + 3, sway);
    for (size_t j = 0; j < sk.joints.size(); ++j)
      EXPECT_LT(glm::length(joint_position(a, j) - joint_position(b, j)), 1e-9);
  }
  // Without the loop the same motion does not repeat after 3 s.
  sway.loop_period_s = 0;
  const Skeleton a = sway_skeleton(sk, 0.2, sway), b = sway_skeleton(sk, 3.2, sway);
  double apart = 0;
  for (size_t j = 0; j < sk.joints.size(); ++j)
    apart = std::max(apart, glm::length(joint_position(a, j) - joint_position(b, j)));
  EXPECT_GT(apart, 1e-3);
}

}  // namespace
}  // namespace sylva
