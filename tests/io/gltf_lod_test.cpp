// gltf_lod_test.cpp — core/io/gltf_lod.h and the LOD export: every level a valid skeleton
// indexed as the plant, about a quarter of the triangles of the level before, the kept
// chains closed under parents, the leaves merged with their area kept; the last level two
// crossed cards carrying the card renderer's images; the errors that write nothing.
#include "core/io/gltf_lod.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/geometry/leaf_mesh.h"
#include "core/geometry/skin.h"
#include "core/geometry/tessellate.h"
#include "core/io/gltf.h"
#include "tests/io/tinygltf_read.h"
#include "tests/support/plants.h"

namespace sylva {
namespace {

namespace fs = std::filesystem;
using test::load_with_tinygltf;

// Triangles of a level: its frusta tessellated with `columns` around, and its leaves.
size_t triangles(const Skeleton& sk, int columns) {
  TessellateOptions options;
  options.segments_around = columns;
  LeafMesh leaves;
  append_leaves(leaves, sk, 0);
  return tessellate(skin_skeleton(sk), options).triangle_count() + leaves.triangle_count();
}

double total_leaf_area(const Skeleton& sk) {
  double area = 0;
  for (const Leaf& leaf : sk.leaves) {
    glm::dvec3 n(0);
    for (size_t i = 0; i < leaf.vertices_m.size(); ++i) {
      const auto& a = leaf.vertices_m[i];
      const auto& b = leaf.vertices_m[(i + 1) % leaf.vertices_m.size()];
      n += glm::cross(glm::dvec3(a[0], a[1], a[2]), glm::dvec3(b[0], b[1], b[2]));
    }
    area += 0.5 * glm::length(n);
  }
  return area;
}

TEST(GltfLod, EachLevelIsAValidSkeletonWithAboutAQuarterOfTheTrianglesBefore) {
  for (const char* preset : {"elm", "elm_in_leaf", "pine", "abop_2_6_honda_leaves"}) {
    const Skeleton sk = test::grow_preset(preset);
    size_t before = triangles(sk, 8);
    for (uint32_t level = 1; level <= 3; ++level) {
      const Skeleton lod = lod_skeleton(sk, level, 8);
      ASSERT_TRUE(validate_skeleton(lod)) << preset << " level " << level << ": "
                                          << validate_skeleton(lod).error().message;
      ASSERT_EQ(lod.chains.size(), sk.chains.size());
      // A kept chain is the plant's, joint for joint; its parent is kept too.
      for (size_t c = 0; c < sk.chains.size(); ++c) {
        const Chain& a = sk.chains[c];
        const Chain& b = lod.chains[c];
        if (b.joint_count == 1) continue;
        EXPECT_EQ(b.joint_count, a.joint_count);
        for (uint32_t j = 0; j < a.joint_count; ++j)
          EXPECT_EQ(lod.joints[b.first_joint + j], sk.joints[a.first_joint + j]);
        if (b.parent) {
          EXPECT_EQ(b.parent, a.parent);
          EXPECT_GT(lod.chains[b.parent->chain].joint_count, 1u) << preset << " chain " << c;
        }
      }
      // Leaves: groups of 4^level, their area kept.
      const size_t group = size_t{1} << (2 * level);
      EXPECT_EQ(lod.leaves.size(), (sk.leaves.size() + group - 1) / group);
      if (!sk.leaves.empty()) {
        EXPECT_NEAR(total_leaf_area(lod), total_leaf_area(sk), 1e-9 * total_leaf_area(sk));
      }
      const size_t now = triangles(lod, lod_columns(8, level));
      const double ratio = static_cast<double>(now) / static_cast<double>(before);
      EXPECT_GT(ratio, 0.1) << preset << " level " << level;
      EXPECT_LT(ratio, 0.4) << preset << " level " << level;
      before = now;
    }
  }
}

TEST(GltfLod, AllLevelsAtOnceAreTheLevelsOneByOneAndThePlantsSkinCounts) {
  // lod_skeletons (the export's: one skin, one tessellation a level) gives each level
  // exactly as lod_skeleton does; level 0 is the plant itself.
  const Skeleton sk = test::grow_preset("elm");
  const std::vector<Skeleton> all = lod_skeletons(sk, 3, 8);
  ASSERT_EQ(all.size(), 3u);
  for (uint32_t level = 1; level <= 3; ++level) EXPECT_EQ(all[level - 1], lod_skeleton(sk, level, 8)) << level;
  EXPECT_EQ(lod_skeleton(sk, 0, 8).chains, sk.chains);
  EXPECT_TRUE(lod_skeletons(sk, 0, 8).empty());
  // The chains' costs are the plant's own skin's: the paper skin (no collars, domes or
  // rounded bends: fewer frusta) keeps at least as many chains within the same budget.
  const SkinOptions paper = SkinOptions::paper();
  auto kept = [](const Skeleton& s) {
    size_t n = 0;
    for (const Chain& c : s.chains) n += c.joint_count > 1;
    return n;
  };
  const std::vector<Skeleton> as_paper = lod_skeletons(sk, 3, 8, paper);
  for (uint32_t level = 1; level <= 3; ++level) {
    EXPECT_EQ(as_paper[level - 1], lod_skeleton(sk, level, 8, paper)) << level;
    EXPECT_TRUE(validate_skeleton(as_paper[level - 1]).ok()) << level;
  }
  EXPECT_NE(kept(as_paper[0]), kept(all[0])) << "the skin changes the estimate";
}

TEST(GltfLod, ColumnsHalveDownToThree) {
  EXPECT_EQ(lod_columns(8, 0), 8);
  EXPECT_EQ(lod_columns(8, 1), 4);
  EXPECT_EQ(lod_columns(8, 2), 3);
  EXPECT_EQ(lod_columns(16, 3), 3);
  EXPECT_EQ(lod_columns(3, 5), 3);
}

TEST(GltfLod, TheCardsCrossOnTheAxisAndSpanThePlant) {
  const Skeleton sk = test::grow_preset("elm");
  const auto cards = impostor_cards(sk);
  ASSERT_TRUE(cards);
  ASSERT_EQ(cards->size(), 2u);
  const SkeletonBounds box = skeleton_bounds(sk);
  for (const ImpostorCard& card : *cards) {
    EXPECT_NEAR(glm::length(card.normal), 1, 1e-12);
    EXPECT_NEAR(glm::dot(card.normal, card.right), 0, 1e-12);
    EXPECT_NEAR(card.centre_m.y - card.half_height_m, box.lo.y, 1e-9);
    EXPECT_NEAR(card.centre_m.y + card.half_height_m, box.hi.y, 1e-9);
  }
  EXPECT_NEAR(glm::dot((*cards)[0].normal, (*cards)[1].normal), 0, 1e-12);
  EXPECT_FALSE(impostor_cards(Skeleton{}));
}

// A card renderer that paints the left half of every card opaque red.
CardRenderer half_red() {
  return [](const GltfPlant&, const ImpostorCard&, uint32_t width, uint32_t height) -> Expected<CardImage> {
    CardImage image{width, height, std::vector<uint8_t>(size_t{4} * width * height, 0)};
    for (uint32_t y = 0; y < height; ++y)
      for (uint32_t x = 0; x < width / 2; ++x) {
        image.rgba[4 * (size_t{y} * width + x) + 0] = 255;
        image.rgba[4 * (size_t{y} * width + x) + 3] = 255;
      }
    return image;
  };
}

TEST(GltfLod, TheExportHasOneNodeALevelUnderThePlantAndCardsWithTheRenderersImages) {
  GltfPlant plant;
  plant.name = "honda";
  plant.skeleton = test::grow_preset("abop_2_6_honda_leaves");
  const std::string path = (fs::temp_directory_path() / ("sylva-lod-" + std::to_string(::getpid()) + ".glb")).string();
  GltfExportOptions options{.mesh = true, .lod = 3, .card_pixels = 64, .card_renderer = half_red()};
  ASSERT_TRUE(export_gltf({plant}, path, options));
  tinygltf::Model model;
  ASSERT_TRUE(load_with_tinygltf(path, &model));
  const tinygltf::Node& root = model.nodes.at(static_cast<size_t>(model.scenes.at(0).nodes.at(0)));
  EXPECT_EQ(root.name, "honda");
  ASSERT_EQ(root.children.size(), 4u);
  size_t before = SIZE_MAX;
  for (size_t level = 0; level < 4; ++level) {
    const tinygltf::Node& node = model.nodes.at(static_cast<size_t>(root.children[level]));
    EXPECT_EQ(node.name, "honda_LOD" + std::to_string(level));
    size_t count = 0;
    for (const tinygltf::Primitive& p : model.meshes.at(static_cast<size_t>(node.mesh)).primitives)
      count += model.accessors.at(static_cast<size_t>(p.indices)).count / 3;
    EXPECT_LT(count, before) << "level " << level;
    before = count;
  }
  EXPECT_EQ(before, 4u);  // two quads
  ASSERT_EQ(model.images.size(), 2u);
  for (const tinygltf::Image& image : model.images) {
    EXPECT_EQ(image.height, 64);
    EXPECT_EQ(image.component, 4);
    EXPECT_EQ(image.image.at(0), 255);                                   // red, opaque, left
    EXPECT_EQ(image.image.at(4 * static_cast<size_t>(image.width) - 1), 0);  // clear, right
  }
  for (const tinygltf::Material& m : model.materials)
    if (m.name.starts_with("honda_card_")) {
      EXPECT_EQ(m.alphaMode, "MASK");
      EXPECT_TRUE(m.doubleSided);
    }

  // Refused, nothing written.
  fs::remove(path);
  auto refused = [&](GltfExportOptions o, const std::string& words) {
    Status s = export_gltf({plant}, path, o);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find(words), std::string::npos) << s.error().message;
    EXPECT_FALSE(fs::exists(path));
  };
  refused({.mesh = true, .lod = 7, .card_renderer = half_red()}, "from 1 to 6");
  refused({.lod = 2, .card_renderer = half_red()}, "export the mesh too");
  refused({.mesh = true, .lod = 2}, "card renderer");
  refused({.mesh = true, .lod = 2, .card_pixels = 4, .card_renderer = half_red()}, "8 to 4096");
  refused({.mesh = true,
           .lod = 1,
           .card_renderer = [](const GltfPlant&, const ImpostorCard&, uint32_t, uint32_t) -> Expected<CardImage> {
             return CardImage{2, 2, {1, 2, 3}};
           }},
          "wrong size");
}

}  // namespace
}  // namespace sylva
