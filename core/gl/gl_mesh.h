// gl_mesh.h — the polygon baseline on the GPU (Bhagvat et al. 2009 sec. 4, "GS" and
// "GS+R"): the tessellated meshes of the CPU reference's mesh path rasterised into the
// G-buffer of the GL ray caster (render_gl.h), which then shades them exactly as it shades
// the ray-cast frusta. GlRenderer uses it when RenderOptions::geometry.kind is mesh.
//
// The meshes are the CPU's (render_cpu.cpp build_scene_geometry, GeometryKind::mesh), made
// by the same functions: each plant placed (place_plant), skinned (skin_skeleton with
// RenderOptions::skin), tessellated at GeometryOptions::mesh_level (tessellate.h: 16·4^m
// triangles per segment) and, where GeometryOptions::displace and the plant's bark has a
// height map and relief_depth_m > 0, displaced by it (GS+R: displace with the plant's
// scene_displacements function, core/scene/height_maps.h, through plant_mesh). Plants are not culled (the CPU culls only
// plants that cannot change a pixel).
//
// Instancing (RenderOptions::geometry.instance; docs/scatter.md "Instancing",
// gl_instances.h): plants that share a skeleton are tessellated once, in the skeleton's
// frame, and drawn with one glDrawElementsInstanced per skeleton through their transforms
// (mesh.vert.glsl INSTANCED; ids carry each instance's plant, v_m its world metres). The
// polygon baseline keeps a displaced plant (GS+R: the relief is in world metres) and, with a
// skin twist, a plant at a scale other than 1 in the world, as the frusta do; leaves depend
// on nothing of where a plant stands, so every shared skeleton's leaves are instanced.
//
// Upload, once (and again by update):
//   vertices  36 B each: position in metres relative to its plant's origin_hi (float; the
//             origin is a float-exact point at the plant's centre, and the shader adds
//             back eye − origin_hi as (eye_hi − origin_hi) + eye_lo, so 10^6 m offsets
//             keep float precision as frusta_common.glsl's records do), unit shading
//             normal, (u turns, v_m metres), frustum index;
//   indices   uint32, 3 per triangle (tessellate.h's, counter-clockwise from outside);
//   frusta    32 B each (bindings.h's MeshFrustumRecord): its plant's origin_hi, then
//             plant | material << 24, chain, segment (knuckle: joint), 0 — shader storage
//             binding kMeshFrustaBinding;
//   instances 48 B each (gl_instances.h GpuInstance), when plants share a skeleton: at
//             kInstancesBinding during the draw (the caller's buffer there is bound back).
//
// Drawing: the caller binds the framebuffer, clears it and sets the depth test; the draw
// sets the view (gl_views.h, as the renderer sets it for the frusta), binds its own program,
// vertex array and buffers, disables face culling (the CPU's Embree triangles are hit from
// both sides) and restores the vertex array and the culling state.
//   draw_gbuffer  shaders/mesh.*.glsl GBUFFER_PASS: frusta.vert.glsl's jittered reversed-Z
//                 infinite projection (depth = near / z_forward, so GL_GREATER against a
//                 cleared 0), and the G-buffer of frusta.frag.glsl: location 0 shading
//                 normal toward the eye + Euclidean distance, 1 geometric normal toward the
//                 eye + u, 2 plant | material << 24, chain, segment, v_m bits, 3 albedo:
//                 with bark_texture_units > 0 bark.glsl's segment_albedo over the screen
//                 derivatives of (u, v_m) (the ray differentials' footprint on a plane),
//                 a = 1 where the plant has an albedo texture; else 0 (the material
//                 table). The renderer binds bark.glsl's maps and images (render_gl.cpp).
//   draw_shadow   SHADOW_PASS: depth only in the orthographic sun view of frusta.vert.glsl
//                 (depth (s − s_near) / s_range, GL_LESS against a cleared 1).
//
// Against the CPU's MeshTracer (mesh_accel.h), by design: the rasteriser's coverage rules
// instead of Embree's watertight test (a silhouette pixel may differ); float interpolation
// of the vertex attributes instead of double barycentrics (depth ~1e-7 relative); the
// geometric normal from screen derivatives of the interpolated position in the plant's
// frame (the triangle's plane, to float precision) instead of the cross product of its
// edges; the bark albedo through GL's trilinear filter (bark.glsl says how it differs
// from OpenImageIO's).
//
// Preconditions: an OpenGL 4.5 core context is current on the calling thread for the
// object's whole life; every plant's skeleton is set. Failures throw GlError (GL) or
// std::runtime_error (a height map that cannot be opened).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/gl/gl_views.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva {

class LeafImages;     // leaf_images.h

// A sphere around one frustum's triangles (displaced ones included), metres.
struct GlMeshSphere {
  glm::dvec3 centre{0};
  double radius = 0;
};
// One sphere holding every sphere of `spheres` (their box's centre; empty: radius 0 at the
// origin).
GlMeshSphere enclosing_sphere(const std::vector<GlMeshSphere>& spheres);

class GlMesh {
 public:
  // Tessellates (and displaces) every plant of `scene` as RenderOptions::geometry asks
  // and uploads the result; builds the G-buffer program, and the shadow program when the
  // scene's sun shines. `bark_texture_units` > 0: the number of bark images the renderer
  // binds for bark.glsl (the G-buffer program then writes the bark albedo). The height
  // maps of a displaced mesh are read here once (height_maps.h) and kept for update.
  GlMesh(const Scene& scene, const RenderOptions& options, int bark_texture_units = 0);
  // The leaves of `scene` (leaf_mesh.h; docs/spec/skeleton.md "Leaves") drawn the same way, with the
  // same programs (without bark: a leaf is never bark, materials.md): one record per leaf
  // with ids plant | material << 24, gl::kLeafChain, the leaf's index in its plant's
  // leaves, its back material + 1 (0: none; mesh.frag.glsl picks the side's); its flat Newell normal as every vertex's shading normal (mesh.frag.glsl turns
  // it toward the eye: two-sided), its leaf_uvs (leaf_mesh.h); a sphere per leaf. Null when no plant has leaves.
  // The frusta's renderer draws it after the frusta into the same G-buffer and shadow map.
  // `images` (leaf_images.h; null: plain leaves): the table's leaf images, cut-outs and
  // one-sided materials, uploaded as one 2D array texture (its bytes in gpu_bytes) and
  // applied in both passes (mesh_program's LEAF_IMAGES).
  static std::unique_ptr<GlMesh> leaves_of(const Scene& scene, const RenderOptions& options,
                                           std::shared_ptr<const LeafImages> images = nullptr);
  // The blended crotches' fillets (crotch_mesh.h skeleton_fillets, docs/joints.md
  // "Crotches") of the plants whose skin has SkinOptions::blend_crotches, drawn the same
  // way with the bark, after the ray-cast frusta into the same G-buffer and shadow map (the
  // CPU marches the same fillet; the mesh's facets are within about 8 mm of it on the test
  // limb). Null when no plant has a fillet.
  static std::unique_ptr<GlMesh> fillets_of(const Scene& scene, const RenderOptions& options,
                                            int bark_texture_units = 0);
  ~GlMesh();
  GlMesh(const GlMesh&) = delete;
  GlMesh& operator=(const GlMesh&) = delete;

  // Re-tessellates the plants of `scene` (moved skeletons: animation) and uploads the
  // meshes again, whole (the polygon baseline has no lighter record to send). Returns the
  // bytes uploaded.
  uint64_t update(const Scene& scene);

  // One G-buffer pass / one shadow-map pass (see the header comment for what the caller
  // sets up). `footprint_scale`: 1 / sqrt(spp), the bark albedo's ray differentials.
  void draw_gbuffer(const GlCameraView& camera, double footprint_scale);
  void draw_shadow(const GlSunView& view);

  uint64_t triangles() const;        // triangles uploaded
  uint64_t drawn_triangles() const;  // triangles drawn (an instanced skeleton's once per plant)
  uint64_t frusta() const;           // frusta drawn (0 for the leaves)
  size_t instanced_plants() const;   // plants drawn through their transforms (0: none shared)
  uint64_t gpu_bytes() const;        // bytes in the vertex, index, frustum and instance buffers
  int level() const;                 // GeometryOptions::mesh_level
  bool displaced() const;            // whether any plant was displaced (GS+R)
  // "GS 2" or "GS+R 2".
  std::string label() const;
  // The names of the passes' program variants (gl_shaders.h mesh_program).
  std::string gbuffer_variant() const;
  std::string shadow_variant() const;
  // Spheres that together hold every triangle drawn, for the renderer's near plane and
  // shadow-map frame: one per frustum (leaf) of a plant in the world, one per instanced plant.
  const std::vector<GlMeshSphere>& bounding_spheres() const;
  // What the constructor (or the last update) did: "skin", "tessellate", "displace" (when
  // a plant was), "upload", and "programs" (constructor only).
  const std::vector<RenderPass>& setup_passes() const;

 private:
  struct LeavesTag {};
  struct FilletsTag {};
  GlMesh(const Scene& scene, const RenderOptions& options, int bark_texture_units, FilletsTag);
  void finish_construction(const Scene& scene);
  GlMesh(const Scene& scene, const RenderOptions& options, std::shared_ptr<const LeafImages> images, LeavesTag);
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace sylva
