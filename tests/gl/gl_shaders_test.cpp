// gl_shaders_test.cpp — every shader variant the GL backend can build compiles: through
// glslangValidator (the Khronos reference front end; Debian glslang-tools), and through
// the driver of the current context with an info log free of warnings. Both see exactly
// the text assemble_shader gives the renderer.
#include "core/gl/gl_shaders.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/gl/gl_api.h"
#include "core/gl/gl_program.h"
#include "tests/support/process.h"
#include "tests/support/gl_checks.h"
#include "tests/support/requirements.h"

namespace sylva {
namespace {

TEST(GlShaders, EveryVariantPassesGlslangValidator) {
  const std::string validator = SYLVA_GLSLANG_VALIDATOR;
  if (validator.empty()) SYLVA_SKIP_WITHOUT_TOOL("glslangValidator was not found at configure time (Debian: glslang-tools)");
  TempDir dir;
  int checked = 0;
  for (const ShaderProgramSource& program : all_shader_programs())
    for (const ShaderStageSource* stage : {&program.vertex, &program.fragment}) {
      const bool vertex = stage->stage == ShaderStage::vertex;
      const std::string file = dir.file("stage" + std::to_string(checked++) + ".glsl");
      std::ofstream(file) << assemble_shader(*stage);
      ProcessResult r = run_process({validator, "-S", vertex ? "vert" : "frag", file});
      EXPECT_EQ(r.exit_code, 0) << program.name << " " << (vertex ? "vertex" : "fragment") << ":\n"
                                << format_shader_log(*stage, r.out + r.err);
    }
  EXPECT_EQ(checked, 2 * static_cast<int>(all_shader_programs().size()));
}

TEST(GlShaders, EveryVariantCompilesAndLinksInTheDriverWithoutWarnings) {
  SYLVA_REQUIRE_GL();
  for (const ShaderProgramSource& program : all_shader_programs()) {
    GlProgram built;
    try {
      built = build_gl_program(program);
    } catch (const GlError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    EXPECT_NE(built.id, 0u);
    EXPECT_EQ(built.info_log.find("warning"), std::string::npos) << program.name << ":\n" << built.info_log;
    EXPECT_EQ(built.info_log.find("error"), std::string::npos) << program.name << ":\n" << built.info_log;
    glDeleteProgram(built.id);
  }
}

TEST(GlShaders, ACompileErrorNamesTheVariantTheFileAndTheLine) {
  SYLVA_REQUIRE_GL();
  ShaderProgramSource broken = shade_program(true);
  broken.name = "broken";
  // bark.glsl replaced by another file: shade.frag.glsl's plant_maps is undeclared there,
  // in the second source string (a file other than the first must be named right).
  broken.fragment.files = {"ray_frustum.glsl", "shade.frag.glsl"};
  try {
    build_gl_program(broken);
    FAIL() << "a broken shader compiled";
  } catch (const GlError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("broken"), std::string::npos) << message;
    EXPECT_NE(message.find("plant_maps"), std::string::npos) << message;
    // Mesa 22 (llvmpipe) numbers this error's source string 0 whatever `#line 1 1` says, so
    // the file name is checked on the reference front end's log.
    const std::string validator = SYLVA_GLSLANG_VALIDATOR;
    if (validator.empty()) return;
    TempDir dir;
    const std::string file = dir.file("broken.frag");
    std::ofstream(file) << assemble_shader(broken.fragment);
    ProcessResult r = run_process({validator, "-S", "frag", file});
    const std::string log = format_shader_log(broken.fragment, r.out + r.err);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(log.find("shade.frag.glsl:"), std::string::npos) << log;
  }
}

TEST(GlShaders, SceneFeaturesSelectTheirCodeByDefines) {
  FrustaFeatures plain, relief, bark;
  relief.relief = true;
  relief.texture_units = 1;
  bark.bark = true;
  bark.texture_units = 3;
  const std::string plain_text = assemble_shader(frusta_program(FrustaPass::gbuffer, plain).fragment);
  EXPECT_EQ(plain_text.find("ReliefHitF intersect_relief_f("), std::string::npos) << "no height map, no relief code";
  EXPECT_EQ(plain_text.find("textureGrad("), std::string::npos) << "no albedo texture, no texture code";
  EXPECT_EQ(plain_text.find("sampler2D"), std::string::npos) << "no albedo texture, no texture code";
  const ShaderProgramSource relief_program = frusta_program(FrustaPass::gbuffer, relief);
  EXPECT_EQ(relief_program.name, "frusta[GBUFFER_PASS RELIEF TEXTURE_UNITS=1]");
  EXPECT_NE(assemble_shader(relief_program.fragment).find("ReliefHitF intersect_relief_f("), std::string::npos);
  const ShaderProgramSource bark_program = frusta_program(FrustaPass::gbuffer, bark);
  EXPECT_EQ(bark_program.name, "frusta[GBUFFER_PASS BARK TEXTURE_UNITS=3]");
  EXPECT_NE(assemble_shader(bark_program.fragment).find("#define BARK_TEXTURE_UNITS 3\n"), std::string::npos);
  // The shadow map marches the relief, and needs neither textures nor the albedo.
  relief.bark = true;
  relief.want_uv = true;
  EXPECT_EQ(frusta_program(FrustaPass::shadow, relief).name, "frusta[SHADOW_PASS RELIEF]");
  relief.conservative_depth = false;
  EXPECT_EQ(frusta_program(FrustaPass::gbuffer, relief).name,
            "frusta[GBUFFER_PASS WANT_UV RELIEF BARK TEXTURE_UNITS=1 NO_CONSERVATIVE_DEPTH]");
  // Every switch is among the variants the validator and the driver compile.
  std::string names;
  for (const ShaderProgramSource& p : all_shader_programs()) names += p.name + " ";
  for (const char* name : {"frusta[GBUFFER_PASS RELIEF BARK TEXTURE_UNITS=2]",
                           "frusta[GBUFFER_PASS EYE_INSIDE WANT_UV RELIEF BARK TEXTURE_UNITS=2]",
                           "frusta[SHADOW_PASS RELIEF]", "frusta[GBUFFER_PASS NO_CONSERVATIVE_DEPTH]",
                           "frusta[SHADOW_PASS RELIEF NO_CONSERVATIVE_DEPTH]"})
    EXPECT_NE(names.find(name), std::string::npos) << name << " missing from " << names;
}

TEST(GlShaders, SourcesAreAssembledWithVersionDefinesAndFileNumbers) {
  const ShaderProgramSource program = frusta_program(FrustaPass::shadow, false);
  const std::string text = assemble_shader(program.fragment);
  EXPECT_EQ(text.rfind("#version 450 core\n#define SHADOW_PASS\n#line 1 0\n", 0), 0u) << text.substr(0, 80);
  EXPECT_NE(text.find("FrustumHitF intersect_frustum_f("), std::string::npos);
  // The fragment stage's files: ray_frustum, skin, views, instances, frusta_common, frusta.frag.
  ASSERT_EQ(program.fragment.files.size(), 6u);
  EXPECT_EQ(format_shader_log(program.fragment, "0:12(3): error: x\nERROR: 5:4: y\n"),
            "ray_frustum.glsl:12(3): error: x\nERROR: frusta.frag.glsl:4: y\n");
}

}  // namespace
}  // namespace sylva
