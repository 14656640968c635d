// render_gl_instancing_test.cpp — plants that share a skeleton drawn as instances
// (docs/scatter.md "Instancing"; instances.glsl GpuInstance): the skeleton's records, leaves
// and polygon-baseline triangles uploaded once, one instanced draw per skeleton, and the same
// picture, AOVs and ids as every plant skinned in the world, in the G-buffer and the shadow
// map alike.
#include "core/gl/render_gl.h"

#include <gtest/gtest.h>

#include "core/gl/gl_mesh.h"
#include <cstdio>
#include <string>

#include "tests/support/test_scenes.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

RenderResult render(const Scene& s, bool instance, GeometryKind kind = GeometryKind::frusta) {
  RenderOptions o;
  o.aovs = kAovDepth | kAovNormal | kAovUv | kAovId;
  o.geometry.instance = instance;
  o.geometry.kind = kind;
  return gl_test::gl_render(s, o);
}

// The grove drawn both ways agrees: ids, depth, normals, v and beauty (see below).
void expect_same_pictures(const Scene& s, const RenderResult& flat, const RenderResult& instanced) {
  const RenderImage &a = flat.image, &b = instanced.image;
  const size_t pixels = static_cast<size_t>(s.width) * s.height;
  std::printf("[ instancing ] ids %zu, depth %zu, beauty %zu of %zu pixels differ\n", test::differing_pixels(a.id, b.id, 3, 0),
              test::differing_pixels(a.depth, b.depth, 1, 1e-5), test::differing_pixels(a.beauty, b.beauty, 4, 1e-4), pixels);
  // Float in another frame: a silhouette pixel may flip (none did on llvmpipe; allow 0.5 %),
  // depth and normals to float's rounding, the beauty to the shading's.
  EXPECT_LE(test::differing_pixels(a.id, b.id, 3, 0), pixels / 200);
  EXPECT_LE(test::differing_pixels(a.depth, b.depth, 1, 1e-5), pixels / 200);
  EXPECT_LE(test::differing_pixels(a.normal, b.normal, 3, 1e-4), pixels / 200);
  // v_m only: u starts at another angle around a turned plant's stems (the skin's
  // axis_frame does not turn with it; tests/cpu/instance_tracer_test.cpp says more).
  EXPECT_LE(test::differing_pixels(test::v_of_uv(a), test::v_of_uv(b), 1, 1e-4), pixels / 200);
  EXPECT_LE(test::differing_pixels(a.beauty, b.beauty, 4, 1e-4), pixels / 200);
}

TEST(RenderGlInstancing, AGroveOfSharedSkeletonsDrawsAsEveryPlantSkinnedInTheWorld) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::instanced_grove();
  const RenderResult flat = render(s, false), instanced = render(s, true);
  const RenderPass* skin = test::find_pass(instanced, "skin");
  ASSERT_NE(skin, nullptr);
  EXPECT_NE(skin->detail.find("12 plants as instances of 2 skeletons"), std::string::npos) << skin->detail;
  EXPECT_EQ(test::find_pass(flat, "skin")->detail.find("instances"), std::string::npos);
  // The six forks' leaves: one skeleton's, drawn six times.
  const RenderPass* leaves = test::find_pass(instanced, "leaves triangulate");
  ASSERT_NE(leaves, nullptr);
  EXPECT_NE(leaves->detail.find("6 plants as instances of 1 skeletons"), std::string::npos) << leaves->detail;
  EXPECT_EQ(instanced.frusta, flat.frusta);
  expect_same_pictures(s, flat, instanced);
}

TEST(RenderGlInstancing, TheLeavesOfASharedSkeletonAreUploadedOnceAndDrawnPerPlant) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::instanced_grove();
  RenderOptions o;
  o.geometry.instance = false;
  const std::unique_ptr<GlMesh> flat = GlMesh::leaves_of(s, o);
  o.geometry.instance = true;
  const std::unique_ptr<GlMesh> instanced = GlMesh::leaves_of(s, o);
  ASSERT_TRUE(flat && instanced);
  // Six forks with one square leaf (2 triangles) each, the crooked stem and the cylinders none.
  EXPECT_EQ(flat->triangles(), 12u);
  EXPECT_EQ(flat->drawn_triangles(), 12u);
  EXPECT_EQ(flat->instanced_plants(), 0u);
  EXPECT_EQ(instanced->triangles(), 2u);
  EXPECT_EQ(instanced->drawn_triangles(), 12u);
  EXPECT_EQ(instanced->instanced_plants(), 6u);
  // One plant's leaves (vertices, triangles, records) once, then 48 B per plant's transform.
  EXPECT_EQ(flat->gpu_bytes() % 6, 0u);
  EXPECT_EQ(instanced->gpu_bytes(), flat->gpu_bytes() / 6 + 6 * 48);
  // A sphere per leaf in the world; a sphere per plant drawn through its transform.
  EXPECT_EQ(flat->bounding_spheres().size(), 6u);
  EXPECT_EQ(instanced->bounding_spheres().size(), 6u);
  EXPECT_NE(instanced->gbuffer_variant().find("INSTANCED"), std::string::npos);
  EXPECT_EQ(flat->gbuffer_variant().find("INSTANCED"), std::string::npos);
}

TEST(RenderGlInstancing, OneSidedLeavesTurnWithTheirPlant) {
  SYLVA_REQUIRE_GL();
  // A one-sided leaf is there from its front only (leaf_images.h): the instanced draw must
  // turn the leaf's normal with the plant, or turned plants show the wrong side.
  Scene s = test::instanced_grove();
  SceneMaterial m;
  m.albedo_rgb = glm::dvec3(0.3, 0.6, 0.2);
  m.two_sided = false;
  s.materials[2] = m;
  const RenderResult flat = render(s, false), instanced = render(s, true);
  ASSERT_NE(test::find_pass(instanced, "leaves triangulate"), nullptr);
  expect_same_pictures(s, flat, instanced);
  // Some leaves are seen from their backs (fewer leaf pixels than two-sided), so a leaf
  // turned the wrong way would show.
  const auto leaf_pixels = [](const RenderImage& image) {
    size_t n = 0;
    for (size_t i = 0; 3 * i < image.id.size(); ++i) n += image.id[3 * i + 1] == kAovLeafChain;
    return n;
  };
  const size_t one_sided = leaf_pixels(instanced.image), two_sided = leaf_pixels(render(test::instanced_grove(), true).image);
  std::printf("[ instancing ] leaf pixels: %zu one-sided, %zu two-sided\n", one_sided, two_sided);
  EXPECT_GT(one_sided, 0u);
  EXPECT_LT(one_sided, two_sided);
}

TEST(RenderGlInstancing, ThePolygonBaselineOfSharedSkeletonsDrawsAsEveryPlantTessellatedInTheWorld) {
  SYLVA_REQUIRE_GL();
  // Unturned plants: tessellate.h places a stem's facets from its skin's axis_frame, which
  // does not turn with the plant, so a turned plant tessellated in the world has its facets
  // at other angles than its instance (another polygon; the next test turns them).
  Scene s = test::instanced_grove();
  for (ScenePlant& p : s.plants) p.rotate_y_deg = 0;
  const RenderResult flat = render(s, false, GeometryKind::mesh), instanced = render(s, true, GeometryKind::mesh);
  const RenderPass* skin = test::find_pass(instanced, "skin");
  ASSERT_NE(skin, nullptr);
  EXPECT_NE(skin->detail.find("12 plants as instances of 2 skeletons"), std::string::npos) << skin->detail;
  EXPECT_EQ(instanced.frusta, flat.frusta);
  expect_same_pictures(s, flat, instanced);

  RenderOptions o;
  o.geometry.kind = GeometryKind::mesh;
  o.skin.blend_crotches = false;  // the frusta's triangles (instances share the fillets any of them needs)
  o.geometry.instance = false;
  const GlMesh flat_mesh(s, o);
  o.geometry.instance = true;
  const GlMesh instanced_mesh(s, o);
  EXPECT_EQ(instanced_mesh.drawn_triangles(), flat_mesh.triangles());
  EXPECT_LT(instanced_mesh.triangles() * 3, flat_mesh.triangles());  // 3 skeletons' for 13 plants
  EXPECT_EQ(instanced_mesh.instanced_plants(), 12u);
  EXPECT_EQ(instanced_mesh.frusta(), flat_mesh.frusta());
}

TEST(RenderGlInstancing, AnInstancedPolygonBaselineMatchesTheCpusInstancedMesh) {
  SYLVA_REQUIRE_GL();
  // The CPU instances the mesh the same way (instance_tracer.h): the same facets, turned.
  Scene s = test::instanced_grove(192, 144);
  RenderOptions o;
  o.aovs = kAovDepth | kAovId;
  o.geometry.kind = GeometryKind::mesh;
  gl_test::expect_matches_cpu("instanced_grove_mesh", s, o);
}

TEST(RenderGlInstancing, TheEyeInsideAnInstancedPlantsPyramidStillSeesItsSurface) {
  SYLVA_REQUIRE_GL();
  // render_gl_test.cpp's EyeInsideABoundingPyramid... through a transform: two equal thick
  // cylinders, the eye inside the second one's pyramid (turned by 90°: its square cross
  // section stays |x|, |z| <= 1 about its axis) but outside its surface.
  const Skeleton sk = gl_test::chain_of({{{0, 0, 0}, 1.0, 0}, {{0, 4, 0}, 1.0, 0}});
  Scene s = gl_test::scene_around(sk, 128, 96);
  s.plants.push_back(s.plants.front());
  s.plants[1].position = {6, 0, 0};
  s.plants[1].rotate_y_deg = 90;
  s.camera.eye = {6.9, 2, 0.9};
  s.camera.target = {6, 2.5, -3};
  s.camera.fov_y_deg = 60;
  const RenderResult flat = render(s, false), instanced = render(s, true);
  ASSERT_NE(test::find_pass(instanced, "skin")->detail.find("2 plants as instances of 1 skeletons"),
            std::string::npos);
  for (const RenderResult* r : {&flat, &instanced}) {
    bool drawn_from_inside = false;
    for (const RenderPass& p : r->passes) drawn_from_inside |= p.detail.find("1 around the eye") != std::string::npos;
    EXPECT_TRUE(drawn_from_inside) << "the EYE_INSIDE pass did not run";
  }
  expect_same_pictures(s, flat, instanced);
  const std::vector<int> seen = test::pixels_per_plant(instanced.image, s.plants.size());
  EXPECT_GT(seen[1], 128 * 96 / 4);  // the near cylinder fills much of the picture
}

TEST(RenderGlInstancing, EachInstancedPlantReportsItsOwnIdInTheIdAov) {
  SYLVA_REQUIRE_GL();
  const Scene s = test::instanced_grove();
  const RenderResult r = render(s, true);
  const std::vector<int> seen = test::pixels_per_plant(r.image, s.plants.size());
  for (size_t p = 0; p < s.plants.size(); ++p) EXPECT_GT(seen[p], 0) << "plant " << p;
}

TEST(RenderGlInstancing, ASharedSkeletonIsUploadedOnce) {
  SYLVA_REQUIRE_GL();
  Scene s = test::instanced_grove();
  for (ScenePlant& p : s.plants) p.skeleton = test::cylinder(0.12, 0, 1.6);
  RenderOptions o;
  o.geometry.instance = false;
  const GlRenderer flat(s, o);
  o.geometry.instance = true;
  const GlRenderer instanced(s, o);
  EXPECT_EQ(flat.frusta(), 13u);
  EXPECT_EQ(instanced.frusta(), 13u);
  // One 64 B record and 16 B of ids, then 48 B per plant's transform, against 13 of each.
  EXPECT_EQ(flat.uploaded_bytes(), 13u * 80);
  EXPECT_EQ(instanced.uploaded_bytes(), 80u + 13 * 48);
}

TEST(RenderGlInstancing, AnInstancedGroveMatchesTheCpu) {
  SYLVA_REQUIRE_GL();
  Scene s = test::instanced_grove(192, 144);
  RenderOptions o;
  o.aovs = kAovDepth | kAovId;
  gl_test::expect_matches_cpu("instanced_grove", s, o);
}

}  // namespace
}  // namespace sylva
