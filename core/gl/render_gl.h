// render_gl.h — the OpenGL ray caster (issue 4; paper 000 sec. 2.5, 2.6, 4): the analytic
// frusta drawn on the GPU with the shading model of the CPU reference (render_cpu.h), so
// the two give the same picture within the tolerances of tests/gl/render_gl_test.cpp.
//
// How a frame is made (shaders/*.glsl, mirroring the CPU code function by function):
//   upload (once)  one 64-byte GpuSegment record per frustum (skin.h) and 16 bytes of ids
//                  (plant, chain, segment) in shader storage buffers; nothing per vertex.
//                  Bark images, each distinct file once, with MIP chains; per plant its
//                  texture parameters (bark.glsl's PlantMaps).
//   shadow map     when the sun shines: the same ray-casting shaders, depth only, in an
//                  orthographic view along the sun direction fitted to the plants' bounds.
//   frusta         vertex pulling builds each frustum's 12-triangle bounding pyramid (sec.
//                  2.6); the fragment shader intersects the pixel's ray with the frustum
//                  (intersect_frustum_f's GLSL twin) — or, for a relief-mapped plant,
//                  marches its relief inside the pyramid of the shell (sec. 3,
//                  relief.glsl, also in the shadow map) — discards misses, writes the
//                  real hit depth and a G-buffer (normals, distance, ids, u/v_m, and the
//                  bark texture's albedo looked up over the ray differentials' footprint).
//   mesh           instead of the frusta when GeometryOptions::kind is mesh (gl_mesh.h,
//                  the paper's polygon baseline GS / GS+R): the CPU mesh path's triangles,
//                  uploaded once, rasterised into the same G-buffer and, depth only, into
//                  the shadow map; the shading is the same.
//   shade          one fullscreen pass: ground plane, sky, sun (Lambert + normalised
//                  Blinn-Phong) with the shadow map, sky ambient — render_cpu.cpp's lit().
// --spp N repeats shadow map (if the sun is a disc), frusta and shade N times with the
// CPU's stratified pixel offsets (one offset per pass for all pixels, the rasteriser
// sampling where the rays go) and, for a disc sun, a sun direction drawn on the disc per
// pass: both converge to the CPU's estimate. AOVs come from the pixel centres.
//
// Where it differs from the CPU, by design (and measured by the tests):
//   - float instead of double (the GpuSegment record, float ray casting): depth agrees to
//     ~1e-6 relative; normals to ~1e-6 rad.
//   - shadows from a shadow map: a texel is ~1/2 pixel, receivers are offset along their
//     normal by 2 texels (no acne), so shadow edges can move by that much.
//   - at --spp 1 a disc sun is treated as its centre (hard shadows); the CPU then takes
//     one random point of the disc per pixel (noisy penumbrae). Both converge with --spp.
//   - relief (relief.glsl, the twin of relief.cpp) marches in float: hits agree with the
//     CPU's double march to about the bisection's last bracket; a sample that float
//     rounds to the other side of the height field can move a hit by one uniform step.
//     The relief's filtered normal reads GL's MIP chain (glGenerateMipmap's box filter,
//     trilinear) where the CPU reads OpenImageIO's (its automip, trilinear).
//   - bark albedo (bark.glsl): the same texture coordinates and ray-differential
//     footprint as texture.h, the encoded values filtered then sRGB-decoded, but GL's
//     isotropic trilinear filter where OpenImageIO filters anisotropically (up to 32
//     taps along the footprint's major axis): at grazing angles the GL albedo is blurrier.
//   - a relief plant's shadow lookups start a pixel footprint above the hit (as the
//     CPU's shadow rays do), or two shadow-map texels where that is more.
//   - at most 16 distinct bark images per scene (gl_unsupported says so).
//   - meshes are rasterised, not ray traced (gl_mesh.h): coverage rules instead of
//     Embree's watertight test at silhouettes, and attributes interpolated from vertices
//     snapped to the sub-pixel grid (normals ~1e-4, depth ~1e-7 relative); the bark
//     albedo's footprint from the screen derivatives of (u, v_m).
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "core/gl/gl_context.h"
#include "core/render_types.h"
#include "core/scene.h"

namespace sylva {

// Why the GL backend cannot render `scene` with `options` as the CPU would (more bark
// images than it binds), or nullopt when it can.
std::optional<std::string> gl_unsupported(const Scene& scene, const RenderOptions& options);

// A scene's plants on the GPU: skinned and uploaded once, rendered any number of times.
// Preconditions: an OpenGL 4.5 core context (a GlContext or a window's) is current on the
// calling thread for the renderer's whole life; every plant's skeleton is set. The
// renderer sets the context's clip control to (lower left, zero to one) and owns the GL
// objects it creates. Failures throw GlError.
class GlRenderer {
 public:
  GlRenderer(const Scene& scene, const RenderOptions& options);
  ~GlRenderer();
  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;

  // Renders the camera, image size, sun, sky and ground of `scene` over the uploaded
  // plants (the plants of `scene` are not read again). Passes carry GPU time from
  // GL_TIME_ELAPSED queries where the name says "(GPU)".
  RenderResult render(const Scene& scene);

  // Animation (paper 000 sec. 4, the dancing cacti): re-skins the plants of `scene` — the
  // same plants as the constructor's, their skeletons moved — and re-uploads only the
  // segment records (the ids too where the number of frusta changed). Returns the bytes
  // uploaded. Throws std::invalid_argument for a different number of plants.
  uint64_t update_plants(const Scene& scene);

  // Whether the frusta programs declare conservative depth (layout(depth_less) /
  // depth_greater, frusta.frag.glsl; default true): false builds the NO_CONSERVATIVE_DEPTH
  // variants from the next render on, the same pictures, for timing what early depth
  // testing is worth.
  void set_conservative_depth(bool on);

  uint64_t frusta() const;          // frusta uploaded
  uint64_t uploaded_bytes() const;  // bytes in the segment and id buffers
  // What was done once: "skin", "upload", "programs" (compile and link).
  const std::vector<RenderPass>& setup_passes() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Renders `scene` on the current context: GlRenderer(scene, options).render(scene), with
// the setup passes first. Throws GlError (gl_unsupported's reason included).
RenderResult render_gl(const Scene& scene, const RenderOptions& options);

}  // namespace sylva
