// normal_map.h — a bark height map baked into a tangent-space normal map (gltf_export.h: glTF
// 2.0 has no ratified height map, so the export carries the relief as a normalTexture).
//
// Texture axes: image column i is s (around the stem), image row j is t (along the stem),
// row 0 at the top — the convention of OpenImageIO and of glTF (texture coordinate (0, 0)
// is the top-left corner of the image). Texel (i, j) sits at s = (i + 0.5)/width,
// t = (j + 0.5)/height; textures tile in both directions.
//
// Surface model: height h in [0, 1], 1 = the outermost surface, 0 = the bottom of a
// furrow; the relief lies depth_m·(1 − h) metres below the outermost surface. Locally the
// surface is taken as flat: in the orthonormal frame (ŝ, t̂, n) — unit directions of
// increasing s and t on the surface, n the outward normal — the relief is the graph
// z = depth_m·h(x_s, x_t) (up to a constant), whose unit normal is
//     n_relief ∝ (−depth_m·∂h/∂x_s, −depth_m·∂h/∂x_t, 1).
// x_s, x_t are metres along ŝ, t̂: one texel spans texel_s_m around and texel_t_m along
// (bark_normal_map_metric gives them for a stem). Derivatives are central differences
// with wrap-around at the edges; their error is O(texel²) times the third derivative.
//
// Encoding (glTF 2.0 normalTexture, linear 8-bit RGB): "+X is right and +Y is up" in
// the image, so X = +ŝ and Y = −t̂ (up in the image is toward row 0, decreasing t):
//     R = (1 + x)/2,  G = (1 + y)/2,  B = (1 + z)/2,  with (x, y, z) =
//     (−depth_m·∂h/∂x_s, +depth_m·∂h/∂x_t, 1) / length.
// A glTF viewer rebuilds the shading normal as x·T + y·B + z·N with B = cross(N, T)·w
// (TANGENT.w); the exporter therefore sets w so that B points toward decreasing t
// (gltf_export.h). A flat height map encodes as (0.5, 0.5, 1) = (128, 128, 255).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/util/diagnostic.h"

namespace sylva {

// A height image as floats, row-major from the top-left corner.
struct HeightMap {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<float> values;  // width·height heights (the first channel of the file)
  float at(uint32_t column, uint32_t row) const { return values[static_cast<size_t>(row) * width + column]; }
};

// Reads any image OpenImageIO reads (PNG 8/16-bit, EXR, TIFF, ...); the first channel of
// its first subimage, integer formats scaled to [0, 1], float formats as stored. A
// missing or unreadable file, an empty image, or a non-finite value is an error naming
// `path` (a Diagnostic for the file as a whole).
Expected<HeightMap> read_height_map(const std::string& path);

// What one texel measures on the surface, and how deep the relief is (metres, all > 0
// except depth_m >= 0).
struct NormalMapMetric {
  double texel_s_m = 1;  // around the stem
  double texel_t_m = 1;  // along the stem
  double depth_m = 0;    // relief depth: height 0 lies depth_m below height 1
};

// The metric of a `width` × `height` bark texture on a stem of radius r_ref_m, repeated
// u_repeat times around and v_per_metre times per metre along it:
//   texel_s_m = 2π·r_ref_m / (u_repeat·width),  texel_t_m = 1 / (v_per_metre·height).
NormalMapMetric bark_normal_map_metric(uint32_t width, uint32_t height, double r_ref_m, double u_repeat,
                                       double v_per_metre, double relief_depth_m);

// Unit tangent-space normals (x, y, z) of the encoding above, row-major like `map`.
// Preconditions: map not empty, metric texels > 0 and finite.
std::vector<glm::dvec3> bake_tangent_normals(const HeightMap& map, const NormalMapMetric& metric);

// The 8-bit RGB encoding of unit tangent-space normals: round(255·(1 + c)/2) per component.
std::vector<uint8_t> encode_normals_rgb8(const std::vector<glm::dvec3>& normals);

// A PNG file in memory (OpenImageIO's writer, no time stamp: identical pixels give
// identical bytes) of 8-bit interleaved pixels, `channels` per pixel (1 to 4).
// Returns the bytes, or nothing if the encoder failed.
std::optional<std::string> encode_png_in_memory(uint32_t width, uint32_t height, int channels,
                                                const std::vector<uint8_t>& pixels);

}  // namespace sylva
