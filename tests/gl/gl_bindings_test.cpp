// gl_bindings_test.cpp — where the shaders meet the C++ (shaders/bindings.glsl, core/gl/
// bindings.h): every #define of bindings.glsl has its C++ twin with the same value, the
// driver puts every storage block and sampler of the built programs where bindings.h says,
// and lays every record out as its C++ mirror; and the GL plumbing (gl_objects.h): handles
// own their objects, check_gl names the error.
#include <gtest/gtest.h>

#include <cstddef>
#include <map>
#include <sstream>
#include <string>

#include "core/gl/bindings.h"
#include "core/gl/gl_api.h"
#include "core/gl/gl_objects.h"
#include "core/gl/gl_program.h"
#include "core/gl/gl_shaders.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

// bindings.glsl's "#define NAME VALUE" lines (VALUE decimal or 0x hex, an optional u).
std::map<std::string, uint32_t> glsl_defines() {
  std::map<std::string, uint32_t> out;
  std::istringstream in{std::string(embedded_shader(kBindingsFile))};
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string directive, name, value;
    if (!(words >> directive >> name >> value) || directive != "#define") continue;
    if (value.back() == 'u') value.pop_back();
    out[name] = static_cast<uint32_t>(std::stoul(value, nullptr, 0));
  }
  return out;
}

TEST(GlBindings, EveryDefineOfBindingsGlslHasItsCppTwin) {
  std::map<std::string, uint32_t> glsl = glsl_defines();
  EXPECT_GE(glsl.size(), 15u) << "bindings.glsl was not parsed";
  for (const gl::GlslConstant& c : gl::kGlslConstants) {
    auto found = glsl.find(c.name);
    if (found == glsl.end()) {
      ADD_FAILURE() << c.name << " is in bindings.h but not in bindings.glsl";
      continue;
    }
    EXPECT_EQ(found->second, c.value) << c.name;
    glsl.erase(found);
  }
  for (const auto& [name, value] : glsl) ADD_FAILURE() << name << " " << value << " is in bindings.glsl only";
}

// A program variant built for the test, deleted after it.
GlProgramObject build(const ShaderProgramSource& source) { return GlProgramObject(build_gl_program(source).id); }

GLint resource(GLuint program, GLenum interface, const std::string& name, GLenum property) {
  const GLuint index = glGetProgramResourceIndex(program, interface, name.c_str());
  if (index == GL_INVALID_INDEX) {
    ADD_FAILURE() << name << " is not an active resource of the program";
    return -1;
  }
  GLint value = -1;
  glGetProgramResourceiv(program, interface, index, 1, &property, 1, nullptr, &value);
  return value;
}

GLint block_binding(GLuint program, const std::string& block) {
  return resource(program, GL_SHADER_STORAGE_BLOCK, block, GL_BUFFER_BINDING);
}
GLint offset(GLuint program, const std::string& variable) {
  return resource(program, GL_BUFFER_VARIABLE, variable, GL_OFFSET);
}
// The stride of the array of records `variable` belongs to: the top-level array's for a
// member of a struct array, the array's own for an array of a basic type.
GLint stride(GLuint program, const std::string& variable) {
  const GLint top_level = resource(program, GL_BUFFER_VARIABLE, variable, GL_TOP_LEVEL_ARRAY_STRIDE);
  return top_level != 0 ? top_level : resource(program, GL_BUFFER_VARIABLE, variable, GL_ARRAY_STRIDE);
}
GLint sampler_unit(GLuint program, const char* name) {
  GLint unit = -1;
  const GLint location = glGetUniformLocation(program, name);
  EXPECT_GE(location, 0) << name;
  if (location >= 0) glGetUniformiv(program, location, &unit);
  return unit;
}

TEST(GlBindings, TheDriverPutsEveryBlockAndSamplerWhereBindingsHSays) {
  SYLVA_REQUIRE_GL();
  FrustaFeatures everything;
  everything.want_uv = everything.relief = everything.bark = true;
  everything.texture_units = 2;
  const GlProgramObject frusta = build(frusta_program(FrustaPass::gbuffer, everything));
  const GlProgramObject inside = build(frusta_program(FrustaPass::gbuffer_eye_inside, everything));
  const GlProgramObject mesh = build(mesh_program(MeshPass::gbuffer, 1));
  const GlProgramObject shade = build(shade_program(true));
  const GlProgramObject present = build(present_program(false));

  EXPECT_EQ(block_binding(frusta.id(), "Segments"), static_cast<GLint>(gl::kSegmentsBinding));
  EXPECT_EQ(block_binding(frusta.id(), "SegmentIds"), static_cast<GLint>(gl::kSegmentIdsBinding));
  EXPECT_EQ(block_binding(inside.id(), "SegmentList"), static_cast<GLint>(gl::kSegmentListBinding));
  EXPECT_EQ(block_binding(frusta.id(), "PlantMapsBuffer"), static_cast<GLint>(gl::kPlantMapsBinding));
  EXPECT_EQ(block_binding(frusta.id(), "HeightTexels"), static_cast<GLint>(gl::kHeightTexelsBinding));
  EXPECT_EQ(block_binding(frusta.id(), "MaterialMapsBuffer"), static_cast<GLint>(gl::kMaterialMapsBinding));
  EXPECT_EQ(block_binding(shade.id(), "PlantBark"), static_cast<GLint>(gl::kPlantBarkBinding));
  EXPECT_EQ(block_binding(mesh.id(), "MeshFrusta"), static_cast<GLint>(gl::kMeshFrustaBinding));

  EXPECT_EQ(sampler_unit(frusta.id(), "u_bark_textures[0]"), static_cast<GLint>(gl::kBarkTexturesUnit));
  EXPECT_EQ(sampler_unit(frusta.id(), "u_bark_textures[1]"), static_cast<GLint>(gl::kBarkTexturesUnit + 1));
  EXPECT_EQ(sampler_unit(shade.id(), "g_normal_distance"), static_cast<GLint>(gl::kGNormalDistanceUnit));
  EXPECT_EQ(sampler_unit(shade.id(), "g_geometric_u"), static_cast<GLint>(gl::kGGeometricUUnit));
  EXPECT_EQ(sampler_unit(shade.id(), "g_ids"), static_cast<GLint>(gl::kGIdsUnit));
  EXPECT_EQ(sampler_unit(shade.id(), "g_albedo"), static_cast<GLint>(gl::kGAlbedoUnit));
  EXPECT_EQ(sampler_unit(shade.id(), "shadow_map"), static_cast<GLint>(gl::kShadowMapUnit));
  EXPECT_EQ(sampler_unit(present.id(), "u_accumulation"), static_cast<GLint>(gl::kAccumulationUnit));
  EXPECT_EQ(resource(shade.id(), GL_UNIFORM, "u_material_albedo[0]", GL_ARRAY_SIZE),
            static_cast<GLint>(gl::kMaxMaterials));
}

TEST(GlBindings, TheDriverLaysEveryRecordOutAsItsCppMirror) {
  SYLVA_REQUIRE_GL();
  FrustaFeatures relief_bark;
  relief_bark.relief = relief_bark.bark = true;
  relief_bark.texture_units = 2;
  const GlProgramObject frusta = build(frusta_program(FrustaPass::gbuffer, relief_bark));
  const GlProgramObject mesh = build(mesh_program(MeshPass::gbuffer, 1));
  const GlProgramObject shade = build(shade_program(true));
  const GLuint f = frusta.id();

  // skin.h's GpuSegment, 64 bytes a frustum.
  EXPECT_EQ(stride(f, "segments[0].origin_hi[0]"), static_cast<GLint>(sizeof(GpuSegment)));
  EXPECT_EQ(offset(f, "segments[0].origin_hi[0]"), static_cast<GLint>(offsetof(GpuSegment, origin_hi)));
  EXPECT_EQ(offset(f, "segments[0].axis_scaled[0]"), static_cast<GLint>(offsetof(GpuSegment, axis_scaled)));
  EXPECT_EQ(offset(f, "segments[0].radius0"), static_cast<GLint>(offsetof(GpuSegment, radius0)));
  EXPECT_EQ(offset(f, "segments[0].radius1"), static_cast<GLint>(offsetof(GpuSegment, radius1)));
  EXPECT_EQ(offset(f, "segments[0].lower_axis_y"), static_cast<GLint>(offsetof(GpuSegment, lower_axis_y)));
  EXPECT_EQ(offset(f, "segments[0].upper_axis_y"), static_cast<GLint>(offsetof(GpuSegment, upper_axis_y)));
  EXPECT_EQ(offset(f, "segments[0].v_lower_m"), static_cast<GLint>(offsetof(GpuSegment, v_lower_m)));
  EXPECT_EQ(offset(f, "segments[0].meta"), static_cast<GLint>(offsetof(GpuSegment, meta)));
  EXPECT_EQ(offset(f, "segments[0].bits[0]"), static_cast<GLint>(offsetof(GpuSegment, bits)));
  // Four uint32 ids a frustum.
  EXPECT_EQ(stride(f, "segment_ids[0]"), 16);

  // bark.glsl's PlantMaps.
  EXPECT_EQ(stride(f, "plant_maps[0].u_repeat"), static_cast<GLint>(sizeof(gl::PlantMapsRecord)));
  EXPECT_EQ(offset(f, "plant_maps[0].v_per_metre"), static_cast<GLint>(offsetof(gl::PlantMapsRecord, v_per_metre)));
  EXPECT_EQ(offset(f, "plant_maps[0].relief_depth_m"),
            static_cast<GLint>(offsetof(gl::PlantMapsRecord, relief_depth_m)));
  EXPECT_EQ(offset(f, "plant_maps[0].albedo_unit"), static_cast<GLint>(offsetof(gl::PlantMapsRecord, albedo_unit)));
  EXPECT_EQ(offset(f, "plant_maps[0].height_unit"), static_cast<GLint>(offsetof(gl::PlantMapsRecord, height_unit)));
  EXPECT_EQ(offset(f, "plant_maps[0].height_first"), static_cast<GLint>(offsetof(gl::PlantMapsRecord, height_first)));
  EXPECT_EQ(offset(f, "plant_maps[0].height_width"), static_cast<GLint>(offsetof(gl::PlantMapsRecord, height_width)));
  EXPECT_EQ(offset(f, "plant_maps[0].height_height"),
            static_cast<GLint>(offsetof(gl::PlantMapsRecord, height_height)));
  EXPECT_EQ(stride(f, "height_texels[0]"), static_cast<GLint>(sizeof(float)));
  // bark.glsl's MaterialMaps.
  EXPECT_EQ(stride(f, "material_maps[0].u_repeat"), static_cast<GLint>(sizeof(gl::MaterialMapsRecord)));
  EXPECT_EQ(offset(f, "material_maps[0].v_per_metre"),
            static_cast<GLint>(offsetof(gl::MaterialMapsRecord, v_per_metre)));
  EXPECT_EQ(offset(f, "material_maps[0].albedo_unit"),
            static_cast<GLint>(offsetof(gl::MaterialMapsRecord, albedo_unit)));

  // shade.frag.glsl's bark colours, mesh.vert.glsl's frustum records.
  EXPECT_EQ(stride(shade.id(), "plant_bark[0]"), static_cast<GLint>(sizeof(gl::PlantBarkRecord)));
  EXPECT_EQ(stride(mesh.id(), "mesh_frusta[0].origin_hi"), static_cast<GLint>(sizeof(gl::MeshFrustumRecord)));
  EXPECT_EQ(offset(mesh.id(), "mesh_frusta[0].ids"), static_cast<GLint>(offsetof(gl::MeshFrustumRecord, ids)));

  // fog_map.glsl's sun maps (fog mode map): the frame records and where the arrays bind.
  const GlProgramObject fog_map = build(fog_program(true, GlFogMode::map));
  const GLuint m = fog_map.id();
  EXPECT_EQ(stride(m, "fog_maps[0].centre_half"), static_cast<GLint>(sizeof(gl::GpuSunMapRecord)));
  EXPECT_EQ(offset(m, "fog_maps[0].to_sun_texel"), static_cast<GLint>(offsetof(gl::GpuSunMapRecord, to_sun_texel)));
  EXPECT_EQ(offset(m, "fog_maps[0].e0_size"), static_cast<GLint>(offsetof(gl::GpuSunMapRecord, e0_size)));
  EXPECT_EQ(offset(m, "fog_maps[0].e1_tiles"), static_cast<GLint>(offsetof(gl::GpuSunMapRecord, e1_tiles)));
  EXPECT_EQ(offset(m, "fog_maps[0].first_tile"), static_cast<GLint>(offsetof(gl::GpuSunMapRecord, first_tile)));
  EXPECT_EQ(block_binding(m, "FogMaps"), static_cast<GLint>(gl::kFogMapsBinding));
  EXPECT_EQ(block_binding(m, "FogMapSlots"), static_cast<GLint>(gl::kFogMapSlotsBinding));
  EXPECT_EQ(block_binding(m, "FogMapRanges"), static_cast<GLint>(gl::kFogMapRangesBinding));
  EXPECT_EQ(block_binding(m, "FogMapTexels"), static_cast<GLint>(gl::kFogMapTexelsBinding));

  // crotch.glsl's blended crotches (CROTCH_FADE: the relief's fade into the fillets).
  FrustaFeatures fade;
  fade.relief = fade.crotch_fade = true;
  fade.texture_units = 1;
  const GlProgramObject faded = build(frusta_program(FrustaPass::gbuffer, fade));
  const GLuint c = faded.id();
  EXPECT_EQ(stride(c, "crotches[0].origin_hi[0]"), static_cast<GLint>(sizeof(gl::GpuCrotchRecord)));
  EXPECT_EQ(offset(c, "crotches[0].centre[0]"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, centre)));
  EXPECT_EQ(offset(c, "crotches[0].start[0]"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, start)));
  EXPECT_EQ(offset(c, "crotches[0].direction[0]"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, direction)));
  EXPECT_EQ(offset(c, "crotches[0].radius"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, radius)));
  EXPECT_EQ(offset(c, "crotches[0].k"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, k)));
  EXPECT_EQ(offset(c, "crotches[0].lateral_radius"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, lateral_radius)));
  EXPECT_EQ(offset(c, "crotches[0].depth_step"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, depth_step)));
  EXPECT_EQ(offset(c, "crotches[0].parent_first"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, parent_first)));
  EXPECT_EQ(offset(c, "crotches[0].parent_count"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, parent_count)));
  EXPECT_EQ(offset(c, "crotches[0].lateral_first"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, lateral_first)));
  EXPECT_EQ(offset(c, "crotches[0].lateral_count"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, lateral_count)));
  EXPECT_EQ(offset(c, "crotches[0].depth_count"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, depth_count)));
  EXPECT_EQ(offset(c, "crotches[0].depth[0]"), static_cast<GLint>(offsetof(gl::GpuCrotchRecord, depth)));
  EXPECT_EQ(stride(c, "crotch_lists[0]"), static_cast<GLint>(sizeof(uint32_t)));
  EXPECT_EQ(block_binding(c, "Crotches"), static_cast<GLint>(gl::kCrotchesBinding));
  EXPECT_EQ(block_binding(c, "CrotchLists"), static_cast<GLint>(gl::kCrotchListsBinding));
}

TEST(GlObjects, AHandleOwnsItsObjectUntilResetAndMovesIt) {
  SYLVA_REQUIRE_GL();
  const float data[4] = {1, 2, 3, 4};
  GlBuffer buffer = make_gl_buffer(data, sizeof data);
  const GLuint name = buffer.id();
  ASSERT_NE(name, 0u);
  EXPECT_TRUE(glIsBuffer(name));
  GlBuffer moved(std::move(buffer));
  EXPECT_EQ(buffer.id(), 0u);  // NOLINT(bugprone-use-after-move): a moved-from handle is empty
  EXPECT_EQ(moved.id(), name);
  EXPECT_TRUE(glIsBuffer(name));
  moved.reset();
  EXPECT_FALSE(glIsBuffer(name)) << "reset deletes the object";
  {
    GlTexture texture = make_gl_texture_2d(GL_RGBA8, 4, 4);
    const GLuint texture_name = texture.id();
    GlTexture other = make_gl_texture_2d(GL_RGBA8, 2, 2);
    const GLuint other_name = other.id();
    other = std::move(texture);  // deletes what `other` held
    EXPECT_FALSE(glIsTexture(other_name));
    EXPECT_EQ(other.id(), texture_name);
  }
  GlBuffer empty = make_gl_buffer(nullptr, 0);  // a 64-byte placeholder: GL has no empty storage
  GLint64 size = 0;
  glGetNamedBufferParameteri64v(empty.id(), GL_BUFFER_SIZE, &size);
  EXPECT_EQ(size, 64);
  check_gl("handles");
}

TEST(GlObjects, CheckGlNamesTheError) {
  SYLVA_REQUIRE_GL();
  glEnable(GL_TEXTURE_2D);  // not a capability in the core profile
  try {
    check_gl("a test");
    FAIL() << "check_gl did not throw";
  } catch (const GlError& e) {
    EXPECT_EQ(std::string(e.what()), "a test: GL_INVALID_ENUM");
  }
  EXPECT_NO_THROW(check_gl("after"));  // the error was taken
}

}  // namespace
}  // namespace sylva
