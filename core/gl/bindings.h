// bindings.h — the C++ side of shaders/bindings.glsl: every shader storage binding point
// and texture unit of the GL backend, the constants C++ and GLSL must agree on, and the C++
// mirrors of the records the shaders read, their layouts pinned by static_assert.
// bindings.glsl's SEGMENTS_BINDING is kSegmentsBinding here, and so on;
// tests/gl/gl_bindings_test.cpp compares every #define of bindings.glsl with kGlslConstants
// and asks the driver for each binding and for the offsets and strides of every record
// below, so a change on one side alone fails a test.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/scene/materials.h"
#include "core/geometry/crotch.h"
#include "core/geometry/skin.h"

namespace sylva::gl {

// Shader storage buffers (std430), by binding point.
inline constexpr uint32_t kSegmentsBinding = 0;      // GpuSegment per frustum (skin.h)
inline constexpr uint32_t kSegmentIdsBinding = 1;    // uint32 plant, chain, segment, 0 per frustum
inline constexpr uint32_t kSegmentListBinding = 2;   // uint32 frustum indices, EYE_INSIDE, per frame
inline constexpr uint32_t kPlantBarkBinding = 3;     // PlantBarkRecord per plant
inline constexpr uint32_t kPlantMapsBinding = 4;     // PlantMapsRecord per plant
inline constexpr uint32_t kHeightTexelsBinding = 5;  // float height texels
inline constexpr uint32_t kMeshFrustaBinding = 6;    // MeshFrustumRecord per frustum (gl_mesh.h)
inline constexpr uint32_t kFogConesBinding = 7;      // GpuShadowConeRecord per shadow cone (fog)
inline constexpr uint32_t kFogNodesBinding = 8;      // the cone intervals' list nodes (fog_lists.glsl)
inline constexpr uint32_t kFogHeadsBinding = 9;      // uint32 per pixel: its list's first node
inline constexpr uint32_t kFogOverflowBinding = 10;  // uint32 per pixel: 1 = its list is incomplete
inline constexpr uint32_t kFogCountersBinding = 11;  // GlFogCounters
inline constexpr uint32_t kInstancesBinding = 12;    // GpuInstance per plant drawn as an instance (INSTANCED)
inline constexpr uint32_t kMaterialMapsBinding = 13; // MaterialMapsRecord per material slot
inline constexpr uint32_t kFogMapsBinding = 14;      // GpuSunMapRecord per sun map (fog mode map)
inline constexpr uint32_t kFogMapSlotsBinding = 15;  // uint32 per tile of every map: its slot (global)
inline constexpr uint32_t kFogMapRangesBinding = 16; // vec2 per slot: its smallest and largest height
inline constexpr uint32_t kFogMapTexelsBinding = 17; // float per texel of every slot (32 × 32 a slot)
inline constexpr uint32_t kCrotchesBinding = 18;     // GpuCrotchRecord per blended crotch (CROTCH_FADE)
inline constexpr uint32_t kCrotchListsBinding = 19;  // uint32: per record its crotches, the groups' records

// Texture units.
inline constexpr uint32_t kBarkTexturesUnit = 0;  // bark image i at kBarkTexturesUnit + i
inline constexpr uint32_t kGNormalDistanceUnit = 16;
inline constexpr uint32_t kGGeometricUUnit = 17;
inline constexpr uint32_t kGIdsUnit = 18;
inline constexpr uint32_t kGAlbedoUnit = 19;
inline constexpr uint32_t kShadowMapUnit = 20;
inline constexpr uint32_t kAccumulationUnit = 21;
inline constexpr uint32_t kLeafImagesUnit = 22;  // leaf_images.h's layers, one 2D array texture

// Constants.
inline constexpr uint32_t kMaxBarkImages = 16;  // GL 4.5 guarantees 16 texture units a stage
inline constexpr uint32_t kMaxMaterials = 256;  // shade.frag.glsl's u_material_albedo: a colour index (8 bits) each
inline constexpr uint32_t kPlantIndexBits = 24;  // G-buffer ids.x = plant | material << 24
inline constexpr uint32_t kPlantIndexMask = (1u << kPlantIndexBits) - 1;
inline constexpr uint32_t kMaxPlants = 1u << kPlantIndexBits;
inline constexpr uint32_t kLeafChain = 0xFFFFFFFEu;  // G-buffer ids.y of a leaf (ids.z: its index)
inline constexpr uint32_t kPyramidVertices = 36;  // vertex pulling: 36 vertices a frustum
inline constexpr uint32_t kFogListEnd = 0xFFFFFFFFu;  // the end of a pixel's interval list
inline constexpr uint32_t kFogMaxIntervals = 16;      // merged intervals the resolve holds per pixel
inline constexpr uint32_t kFogMaxListNodes = 1024;    // nodes the resolve walks per pixel (more: marched whole)
inline constexpr uint32_t kFogMaxMaps = 64;           // sun maps the fog pass walks (kFogMaxMapDirections)
inline constexpr uint32_t kFogMapNoSlot = 0xFFFFFFFFu;  // a tile not allocated (SunDepthMap::kNoSlot)
inline constexpr uint32_t kFogMapTile = 32;           // texels a tile's side (SunDepthMap::kTile)

static_assert(kBarkTexturesUnit + kMaxBarkImages <= kGNormalDistanceUnit,
              "the bark images' units must not reach the G-buffer's");
static_assert(kMaterialTableSize <= kMaxMaterials, "materials.h's table must fit shade.frag.glsl's");
// The material index is 8 bits in a GpuSegment (skin.h) and in the G-buffer's ids.x.
static_assert(kPlantIndexBits + 8 <= 32);

// bindings.glsl's #defines with their values, for the test that keeps the two in step.
struct GlslConstant {
  const char* name;
  uint32_t value;
};
inline constexpr GlslConstant kGlslConstants[] = {
    {"SEGMENTS_BINDING", kSegmentsBinding},
    {"SEGMENT_IDS_BINDING", kSegmentIdsBinding},
    {"SEGMENT_LIST_BINDING", kSegmentListBinding},
    {"PLANT_BARK_BINDING", kPlantBarkBinding},
    {"PLANT_MAPS_BINDING", kPlantMapsBinding},
    {"HEIGHT_TEXELS_BINDING", kHeightTexelsBinding},
    {"MESH_FRUSTA_BINDING", kMeshFrustaBinding},
    {"BARK_TEXTURES_UNIT", kBarkTexturesUnit},
    {"G_NORMAL_DISTANCE_UNIT", kGNormalDistanceUnit},
    {"G_GEOMETRIC_U_UNIT", kGGeometricUUnit},
    {"G_IDS_UNIT", kGIdsUnit},
    {"G_ALBEDO_UNIT", kGAlbedoUnit},
    {"SHADOW_MAP_UNIT", kShadowMapUnit},
    {"ACCUMULATION_UNIT", kAccumulationUnit},
    {"LEAF_IMAGES_UNIT", kLeafImagesUnit},
    {"MAX_BARK_IMAGES", kMaxBarkImages},
    {"MAX_MATERIALS", kMaxMaterials},
    {"PLANT_INDEX_BITS", kPlantIndexBits},
    {"PLANT_INDEX_MASK", kPlantIndexMask},
    {"LEAF_CHAIN", kLeafChain},
    {"PYRAMID_VERTICES", kPyramidVertices},
    {"FOG_CONES_BINDING", kFogConesBinding},
    {"FOG_NODES_BINDING", kFogNodesBinding},
    {"FOG_HEADS_BINDING", kFogHeadsBinding},
    {"FOG_OVERFLOW_BINDING", kFogOverflowBinding},
    {"FOG_COUNTERS_BINDING", kFogCountersBinding},
    {"INSTANCES_BINDING", kInstancesBinding},
    {"MATERIAL_MAPS_BINDING", kMaterialMapsBinding},
    {"FOG_MAPS_BINDING", kFogMapsBinding},
    {"FOG_MAP_SLOTS_BINDING", kFogMapSlotsBinding},
    {"FOG_MAP_RANGES_BINDING", kFogMapRangesBinding},
    {"FOG_MAP_TEXELS_BINDING", kFogMapTexelsBinding},
    {"CROTCHES_BINDING", kCrotchesBinding},
    {"CROTCH_LISTS_BINDING", kCrotchListsBinding},
    {"CROTCH_DEPTH_SAMPLES", kCrotchDepthSamples},
    {"FOG_MAP_NO_SLOT", kFogMapNoSlot},
    {"FOG_MAP_TILE", kFogMapTile},
    {"FOG_MAX_MAPS", kFogMaxMaps},
    {"FOG_LIST_END", kFogListEnd},
    {"FOG_MAX_INTERVALS", kFogMaxIntervals},
    {"FOG_MAX_LIST_NODES", kFogMaxListNodes},
};

// ---- Records (std430 arrays in shader storage) ----------------------------------------

// The frusta's records are skin.h's GpuSegment (64 bytes, skin.glsl's twin) and four
// uint32 ids a frustum.
static_assert(sizeof(GpuSegment) == 64);

// shade.frag.glsl's plant_bark[plant]: the bark colour (Bark::albedo_rgb), w = 1 where it
// replaces material 0.
struct PlantBarkRecord {
  float rgb[3] = {0, 0, 0};
  float replaces_material0 = 0;
};
static_assert(sizeof(PlantBarkRecord) == 16);

// bark.glsl's PlantMaps: per plant, its bark textures' parameters.
struct PlantMapsRecord {
  float u_repeat = 1, v_per_metre = 1, relief_depth_m = 0;
  // Index into u_bark_textures of material 0's bark albedo; kAlbedoFromTable: none, the
  // material table's MaterialMapsRecord decides; kAlbedoNone: none (the bark's colour).
  int32_t albedo_unit = -1;
  int32_t height_unit = -1;                    // index into u_bark_textures; −1: none
  uint32_t height_first = 0;                   // first texel in HeightTexels
  int32_t height_width = 1, height_height = 1;
};
static_assert(sizeof(PlantMapsRecord) == 32 && offsetof(PlantMapsRecord, albedo_unit) == 12 &&
              offsetof(PlantMapsRecord, height_first) == 20 && offsetof(PlantMapsRecord, height_height) == 28);

inline constexpr int32_t kAlbedoFromTable = -1, kAlbedoNone = -2;  // PlantMapsRecord::albedo_unit

// bark.glsl's MaterialMaps: per material slot, the albedo image the scene's table lays on
// its segments (scene.h segment_texture), kMaxMaterials of them.
struct MaterialMapsRecord {
  float u_repeat = 1, v_per_metre = 1;
  int32_t albedo_unit = -1;  // index into u_bark_textures; −1: none
  int32_t unused = 0;
};
static_assert(sizeof(MaterialMapsRecord) == 16 && offsetof(MaterialMapsRecord, albedo_unit) == 8);

// mesh.vert.glsl's MeshFrustum (std430: vec4, uvec4).
struct MeshFrustumRecord {
  float origin_hi[4];  // the plant's origin, float-exact; w unused
  uint32_t ids[4];     // plant | material << kPlantIndexBits, chain, segment, 0
};
static_assert(sizeof(MeshFrustumRecord) == 32 && offsetof(MeshFrustumRecord, ids) == 16);

// shadow_cones.glsl's GpuShadowCone: one shadow cone (shadow_cones.h cone_geometry) as an
// apex-free conical frustum, positions relative to the cone set's origin.
struct GpuShadowConeRecord {
  float base_radius0[4];  // base, r(0)
  float axis_end[4];      // unit axis away from the sun, end (the solid's length along it)
  float slope_plant[4];   // dr/ds, the occluder's plant (as a float), 0, 0
};
static_assert(sizeof(GpuShadowConeRecord) == 48 && offsetof(GpuShadowConeRecord, axis_end) == 16 &&
              offsetof(GpuShadowConeRecord, slope_plant) == 32);

// fog_map.glsl's GpuSunMap: one sun-space depth map's frame (core/light/sun_map.h), its centre
// relative to the map set's origin (GlFogMaps::origin), and where its tiles and slots start
// in the shared arrays.
struct GpuSunMapRecord {
  float centre_half[4];   // centre − origin, half_extent_m
  float to_sun_texel[4];  // s (unit), texel_m
  float e0_size[4];       // e0, size (texels a side)
  float e1_tiles[4];      // e1, tiles a side
  uint32_t first_tile[4]; // the map's first entry in the slots array, 0, 0, 0
};
static_assert(sizeof(GpuSunMapRecord) == 80 && offsetof(GpuSunMapRecord, first_tile) == 64);

// crotch.glsl's GpuCrotch: one blended crotch (core/geometry/crotch.h Crotch) of a plant
// with a relief, for the relief's fade into its fillet (gl_crotch_fade.h). Positions are
// relative to origin_hi (the origin_hi of its first parent record, float-exact); the
// groups' record indices lie in CrotchLists from parent_first / lateral_first.
struct GpuCrotchRecord {
  float origin_hi[3];
  float centre[3];
  float start[3];
  float direction[3];
  float radius, k, lateral_radius, depth_step;
  uint32_t parent_first, parent_count, lateral_first, lateral_count, depth_count;
  float depth[kCrotchDepthSamples];
};
static_assert(sizeof(GpuCrotchRecord) == 4 * (21 + kCrotchDepthSamples) && offsetof(GpuCrotchRecord, radius) == 48 &&
              offsetof(GpuCrotchRecord, parent_first) == 64 && offsetof(GpuCrotchRecord, depth) == 84);

// fog_lists.glsl's FogNode (12 bytes) and FogCounters.
struct FogNodeRecord {
  float t_in = 0, t_out = 0;
  uint32_t next = kFogListEnd;
};
static_assert(sizeof(FogNodeRecord) == 12);
struct GlFogCounters {
  uint32_t next_node = 0;          // nodes taken in the last cone pass (may exceed the capacity)
  uint32_t fragments = 0;          // interval fragments over the frame
  uint32_t overflow_fragments = 0; // of them, those that found the node buffer full
  uint32_t overflow_pixels = 0;    // pixels the resolve marched whole
  uint32_t largest_pass = 0;       // the most nodes one pass asked for
};
static_assert(sizeof(GlFogCounters) == 20);

// ---- Uniform blocks (std140): none ----------------------------------------------------
// The views every geometry pass draws in (views.glsl: the camera, the sun's orthographic
// view) and the shading parameters are default-block uniforms, set by name per program
// (gl_views.h, gl_program.h). A std140 block for the views was built and measured: on
// llvmpipe the same values read from a uniform block compile to different float code (ulp
// differences in depth, normals and a few pixels), and the GL backend's pictures must stay
// byte-identical across such a refactor. A block added later gets its binding here, its
// std140 mirror struct with static_asserts on its offsets, and a line in the layout test.

}  // namespace sylva::gl
