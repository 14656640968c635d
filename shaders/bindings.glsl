// bindings.glsl — where the GL backend's shaders meet its C++: every shader storage binding
// point, texture unit and uniform block, and the constants both sides must agree on.
// core/gl/bindings.h mirrors each line (its names: SEGMENTS_BINDING is kSegmentsBinding);
// tests/gl/gl_bindings_test.cpp checks the #defines against it and asks the driver for the
// records' layouts and every binding. gl_shaders.cpp puts this file at the head of every stage,
// so every shader file may use these names.

// Shader storage buffers (std430), by binding point.
#define SEGMENTS_BINDING 0        // frusta_common.glsl Segments: a GpuSegment per frustum (skin.glsl)
#define SEGMENT_IDS_BINDING 1     // frusta_common.glsl SegmentIds: plant, chain, segment, 0 per frustum
#define SEGMENT_LIST_BINDING 2    // frusta_common.glsl SegmentList: EYE_INSIDE's frusta, this frame
#define PLANT_BARK_BINDING 3      // shade.frag.glsl PlantBark: a bark colour per plant
#define PLANT_MAPS_BINDING 4      // bark.glsl PlantMapsBuffer: a PlantMaps per plant
#define HEIGHT_TEXELS_BINDING 5   // bark.glsl HeightTexels: height maps' finest levels
#define MESH_FRUSTA_BINDING 6     // mesh.vert.glsl MeshFrusta: a MeshFrustum per frustum
#define FOG_CONES_BINDING 7       // shadow_cones.glsl FogCones: a GpuShadowCone per shadow cone
#define FOG_NODES_BINDING 8       // fog_lists.glsl FogNodes: the cone intervals' list nodes
#define FOG_HEADS_BINDING 9       // fog_lists.glsl FogHeads: per pixel, its list's first node
#define FOG_OVERFLOW_BINDING 10   // fog_lists.glsl FogOverflow: per pixel, 1 = list incomplete
#define FOG_COUNTERS_BINDING 11   // fog_lists.glsl FogCounters: the frame's counts
#define INSTANCES_BINDING 12      // instances.glsl Instances: INSTANCED's per plant transforms
#define MATERIAL_MAPS_BINDING 13  // bark.glsl MaterialMapsBuffer: a MaterialMaps per material slot
#define FOG_MAPS_BINDING 14       // fog_map.glsl FogMaps: a GpuSunMap per sun map (fog mode map)
#define FOG_MAP_SLOTS_BINDING 15  // fog_map.glsl FogMapSlots: per tile of every map, its slot
#define FOG_MAP_RANGES_BINDING 16 // fog_map.glsl FogMapRanges: per slot, its smallest and largest height
#define FOG_MAP_TEXELS_BINDING 17 // fog_map.glsl FogMapTexels: per texel of every slot, its height
#define CROTCHES_BINDING 18       // crotch.glsl Crotches: a GpuCrotch per blended crotch (CROTCH_FADE)
#define CROTCH_LISTS_BINDING 19   // crotch.glsl CrotchLists: per record its crotches, the groups' records

// Texture units. Bark images take units BARK_TEXTURES_UNIT .. + MAX_BARK_IMAGES − 1; the
// G-buffer, the shadow map and the accumulated beauty sit above them, so no pass rebinds
// another's textures.
#define BARK_TEXTURES_UNIT 0      // bark.glsl u_bark_textures[i]
#define G_NORMAL_DISTANCE_UNIT 16 // shade.frag.glsl g_normal_distance (G-buffer attachment 0)
#define G_GEOMETRIC_U_UNIT 17     // g_geometric_u (attachment 1)
#define G_IDS_UNIT 18             // g_ids (attachment 2)
#define G_ALBEDO_UNIT 19          // g_albedo (attachment 3)
#define SHADOW_MAP_UNIT 20        // shade.frag.glsl shadow_map
#define ACCUMULATION_UNIT 21      // present.frag.glsl u_accumulation
#define LEAF_IMAGES_UNIT 22       // mesh.frag.glsl u_leaf_images (LEAF_IMAGES: leaf_images.h's layers)

// Constants.
#define MAX_BARK_IMAGES 16        // distinct bark images a scene may bind (GL 4.5 guarantees 16 units a stage)
#define MAX_MATERIALS 256         // shade.frag.glsl's material table (materials.h fills it)
#define PLANT_INDEX_BITS 24       // G-buffer ids.x: plant | material << PLANT_INDEX_BITS
#define PLANT_INDEX_MASK 0xFFFFFFu
#define LEAF_CHAIN 0xFFFFFFFEu    // G-buffer ids.y of a leaf (gl_mesh.h), ids.z its index
#define PYRAMID_VERTICES 36       // a frustum's bounding pyramid: 12 triangles (skin.glsl)
#define FOG_LIST_END 0xFFFFFFFFu  // the end of a pixel's interval list (fog_lists.glsl)
#define FOG_MAX_INTERVALS 16      // merged intervals the fog resolve holds per pixel (fog.frag.glsl)
#define FOG_MAX_LIST_NODES 1024u  // list nodes the fog resolve walks per pixel (more: marched whole)
#define FOG_MAP_NO_SLOT 0xFFFFFFFFu  // a sun map's tile that is not allocated (fog_map.glsl)
#define FOG_MAP_TILE 32           // texels a side of a sun map's tile (fog_map.glsl)
#define FOG_MAX_MAPS 64           // sun maps the fog resolve walks (fog.frag.glsl FOG_MAP)
#define CROTCH_DEPTH_SAMPLES 16   // a crotch's depth table (crotch.h kCrotchDepthSamples)

// Uniform blocks (std140): none. The views (views.glsl's camera and sun uniforms) and the
// shading parameters are default-block uniforms set by name (core/gl/gl_views.h,
// gl_program.h); bindings.h says why they are not a block.
