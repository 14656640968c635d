// leaf_images_test.cpp — the table's leaf images (leaf_images.h): the merged layer, its
// bilinear lookup at a leaf's (u, v), cut-outs, one-sidedness, the segments' mean albedo,
// and the scene keys that name them.
#include "core/scene/leaf_images.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scene/materials.h"
#include "core/scene/scene_json.h"
#include "core/util/color.h"
#include "tests/support/test_textures.h"

namespace sylva {
namespace {

// A 4 × 2 RGBA image: its left half transparent blue, its right half opaque; the right
// half's top row (the leaf's tip side) red, its bottom row (the petiole's) green.
void write_half_leaf(const std::string& path) {
  test::write_rgba_png(path, 4, 2, [](uint32_t x, uint32_t y) -> std::array<float, 4> {
    if (x < 2) return {0, 0, 1, 0};
    return y == 0 ? std::array<float, 4>{1, 0, 0, 1} : std::array<float, 4>{0, 1, 0, 1};
  });
}

TEST(LeafImages, AnAlbedoImagesOwnAlphaCutsTheLeafAndItsRowsRunFromTipToPetiole) {
  test::TempFolder dir;
  write_half_leaf(dir.file("leaf.png"));
  std::map<uint32_t, SceneMaterial> table;
  table[1].albedo_image = dir.file("leaf.png");
  auto loaded = LeafImages::load(table);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const LeafImages& images = **loaded;
  EXPECT_FALSE(images.empty());
  EXPECT_EQ(images.width(), 4u);
  EXPECT_EQ(images.height(), 2u);
  EXPECT_EQ(images.layer_of(1), 0);
  EXPECT_EQ(images.layer_of(2), -1);
  EXPECT_TRUE(images.has_albedo(1));
  EXPECT_TRUE(images.has_cutout(1));  // the image's own alpha channel
  EXPECT_FALSE(images.one_sided(1));
  // Texel centres at u = (x + 0.5) / 4: the left half is gone, the right half is there.
  EXPECT_FALSE(images.opaque(1, 0.125, 0.5));
  EXPECT_TRUE(images.opaque(1, 0.875, 0.5));
  EXPECT_NEAR(images.alpha(1, 0.5, 0.5), 0.5, 1e-12);  // between texel centres 1 and 2
  // v = 0.75 is the top row's centre (red: the tip side), v = 0.25 the bottom's (green).
  const glm::dvec3 tip = images.albedo(1, 0.875, 0.75), petiole = images.albedo(1, 0.875, 0.25);
  EXPECT_NEAR(tip.x, 1, 1e-12);
  EXPECT_NEAR(tip.y, 0, 1e-12);
  EXPECT_NEAR(petiole.y, 1, 1e-12);
  EXPECT_NEAR(petiole.x, 0, 1e-12);
  // Clamped at the edges: beyond the last texel centre it stays.
  EXPECT_NEAR(images.albedo(1, 1.0, 1.0).x, 1, 1e-12);
  // Halfway between the rows: the encoded values averaged, then decoded.
  EXPECT_NEAR(images.albedo(1, 0.875, 0.5).x, srgb_to_linear(0.5 * (1 + 0)), 1e-3);
  // Segments of material 1 take the mean over the opaque texels: half red, half green.
  EXPECT_NEAR(images.mean_albedo(1).x, 0.5, 1e-12);
  EXPECT_NEAR(images.mean_albedo(1).y, 0.5, 1e-12);
  EXPECT_NEAR(images.mean_albedo(1).z, 0, 1e-12);
  const MaterialLook look = segment_look(table, nullptr, 1, &images);
  EXPECT_NEAR(look.albedo.x, 0.5, 1e-12);
  // A material without an image keeps its look.
  EXPECT_NEAR(segment_look(table, nullptr, 2, &images).albedo.x, default_material_albedo(2)[0], 1e-12);
}

TEST(LeafImages, ASeparateAlphaImageIsResampledToTheAlbedosSizeAndOneSidednessIsKept) {
  test::TempFolder dir;
  write_half_leaf(dir.file("albedo.png"));
  // A 2 × 1 gray mask: left 0, right 1 — resampled onto the 4 × 2 layer.
  test::write_rgb_png(dir.file("mask.png"), 2, 1, [](uint32_t x, uint32_t) -> std::array<float, 3> {
    return {x == 0 ? 0.0f : 1.0f, 0, 0};
  });
  std::map<uint32_t, SceneMaterial> table;
  table[1].albedo_rgb = glm::dvec3(0.2, 0.3, 0.1);
  table[1].alpha_image = dir.file("mask.png");
  table[2].two_sided = false;
  auto loaded = LeafImages::load(table);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const LeafImages& images = **loaded;
  EXPECT_EQ(images.width(), 2u);  // the largest image: the mask alone is read for the layer
  EXPECT_EQ(images.height(), 1u);
  EXPECT_FALSE(images.has_albedo(1));  // the colour stays the table's
  EXPECT_TRUE(images.has_cutout(1));
  EXPECT_FALSE(images.opaque(1, 0.1, 0.5));
  EXPECT_TRUE(images.opaque(1, 0.9, 0.5));
  EXPECT_TRUE(images.one_sided(2));
  EXPECT_EQ(images.layer_of(2), -1);
  EXPECT_NEAR(segment_look(table, nullptr, 1, &images).albedo.y, 0.3, 1e-12);
}

TEST(LeafImages, ATableWithoutImagesOrOneSidedMaterialsIsEmptyAndABrokenFileIsNamed) {
  std::map<uint32_t, SceneMaterial> table;
  table[1].albedo_rgb = glm::dvec3(0.2, 0.3, 0.1);
  auto plain = LeafImages::load(table);
  ASSERT_TRUE(plain);
  EXPECT_TRUE((*plain)->empty());
  test::TempFolder dir;
  table[1].albedo_image = dir.file("missing.png");
  auto broken = LeafImages::load(table);
  ASSERT_FALSE(broken);
  EXPECT_EQ(broken.error().file, dir.file("missing.png"));
  EXPECT_NE(broken.error().message.find("leaf albedo image"), std::string::npos) << broken.error().message;
}

TEST(LeafImages, TheSceneKeysNameTheImagesRelativeToTheSceneAndWriteBackTheSame) {
  test::TempFolder dir;
  write_half_leaf(dir.file("leaf.png"));
  write_half_leaf(dir.file("mask.png"));
  const std::string text = R"({"plants": [], "materials": [
      {"index": 1, "albedo": "leaf.png", "alpha": "mask.png", "two_sided": false, "specular": 0.3},
      {"index": 2, "albedo": [0.1, 0.2, 0.3]}]})";
  Expected<Scene> s = parse_scene_json(text, "m.scene.json", dir.path());
  ASSERT_TRUE(s.ok()) << s.error().format();
  const SceneMaterial& m = s->materials.at(1);
  EXPECT_EQ(m.albedo_image, dir.file("leaf.png"));
  EXPECT_EQ(m.alpha_image, dir.file("mask.png"));
  EXPECT_FALSE(m.two_sided);
  EXPECT_FALSE(m.albedo_rgb);
  EXPECT_TRUE(s->materials.at(2).two_sided);  // the default
  Expected<std::string> written = write_scene_json(*s, dir.path());
  ASSERT_TRUE(written.ok()) << written.error().message;
  EXPECT_NE(written->find("\"albedo\": \"leaf.png\""), std::string::npos) << *written;  // relative again
  Expected<Scene> again = parse_scene_json(*written, "m.scene.json", dir.path());
  ASSERT_TRUE(again.ok()) << again.error().format();
  EXPECT_EQ(again->materials, s->materials);
}

// Hostile sizes (issue 32, item 9): a 65536×1 and a 1×65536 image — a few hundred bytes each —
// once merged into a 65536² layer per material (32 GiB). The layers are bounded and the
// images keep their content, resampled onto the smaller layer.
TEST(LeafImages, ALongAndATallImageMergeIntoBoundedLayersThatKeepTheirContent) {
  test::TempFolder dir;
  // Long: left half red, right half green. Tall: top half blue, bottom half white.
  test::write_rgba_png(dir.file("long.png"), 65536, 1, [](uint32_t x, uint32_t) -> std::array<float, 4> {
    return x < 32768 ? std::array<float, 4>{1, 0, 0, 1} : std::array<float, 4>{0, 1, 0, 1};
  });
  test::write_rgba_png(dir.file("tall.png"), 1, 65536, [](uint32_t, uint32_t y) -> std::array<float, 4> {
    return y < 32768 ? std::array<float, 4>{0, 0, 1, 1} : std::array<float, 4>{1, 1, 1, 1};
  });
  std::map<uint32_t, SceneMaterial> table;
  table[1].albedo_image = dir.file("long.png");
  table[2].albedo_image = dir.file("tall.png");
  auto loaded = LeafImages::load(table);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const LeafImages& images = **loaded;
  EXPECT_LE(images.width(), kMaxLeafLayerSide);
  EXPECT_LE(images.height(), kMaxLeafLayerSide);
  EXPECT_LE(uint64_t{images.width()} * images.height() * images.layer_count(), kMaxLeafLayerTexels);
  EXPECT_EQ(images.width(), images.height());  // one factor for both sides
  EXPECT_GE(images.width(), 4096u);
  EXPECT_NEAR(images.albedo(1, 0.25, 0.5).x, 1, 1e-12);
  EXPECT_NEAR(images.albedo(1, 0.75, 0.5).y, 1, 1e-12);
  EXPECT_NEAR(images.albedo(1, 0.75, 0.5).x, 0, 1e-12);
  EXPECT_NEAR(images.albedo(2, 0.5, 0.75).z, 1, 1e-12);  // v = 0.75: the top half
  EXPECT_NEAR(images.albedo(2, 0.5, 0.75).x, 0, 1e-12);
  EXPECT_NEAR(images.albedo(2, 0.5, 0.25).x, 1, 1e-12);
  EXPECT_NEAR(images.mean_albedo(1).x, 0.5, 1e-3);
}

TEST(LeafImages, TheLayerSizeIsKeptWithinItsBoundsByOneFactor) {
  EXPECT_EQ(leaf_layer_size(4, 2, 3), std::make_pair(4u, 2u));
  EXPECT_EQ(leaf_layer_size(4096, 4096, 4), std::make_pair(4096u, 4096u));  // 2^26 exactly
  EXPECT_EQ(leaf_layer_size(8192, 8192, 4), std::make_pair(4096u, 4096u));
  EXPECT_EQ(leaf_layer_size(65536, 1, 1), std::make_pair(16384u, 1u));     // the side bound
  EXPECT_EQ(leaf_layer_size(1, 65536, 1), std::make_pair(1u, 16384u));
  const auto [w, h] = leaf_layer_size(12000, 7000, 5);
  EXPECT_LE(uint64_t{w} * h * 5, kMaxLeafLayerTexels);
  EXPECT_GT(uint64_t{w + 1} * (h + 1) * 5, kMaxLeafLayerTexels);  // not smaller than it must be
  EXPECT_NEAR(double(w) / h, 12000.0 / 7000.0, 1e-3);
}

}  // namespace
}  // namespace sylva
