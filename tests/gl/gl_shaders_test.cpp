// gl_shaders_test.cpp — every shader variant the GL backend can build compiles: through
// glslangValidator (the Khronos reference front end; Debian glslang-tools), and through
// the driver of the current context with an info log free of warnings. Both see exactly
// the text assemble_shader gives the renderer.
#include "core/gl_shaders.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/gl_api.h"
#include "core/gl_program.h"
#include "tests/app/process.h"
#include "tests/gl/gl_test_util.h"

namespace sylva {
namespace {

TEST(GlShaders, EveryVariantPassesGlslangValidator) {
  const std::string validator = SYLVA_GLSLANG_VALIDATOR;
  if (validator.empty()) GTEST_SKIP() << "glslangValidator was not found at configure time (Debian: glslang-tools)";
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
  broken.fragment.defines.push_back("texelFetch no_such_function");  // breaks shade.frag.glsl
  try {
    build_gl_program(broken);
    FAIL() << "a broken shader compiled";
  } catch (const GlError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("broken"), std::string::npos) << message;
    EXPECT_NE(message.find("shade.frag.glsl"), std::string::npos) << message;
  }
}

TEST(GlShaders, SourcesAreAssembledWithVersionDefinesAndFileNumbers) {
  const ShaderProgramSource program = frusta_program(FrustaPass::shadow, false);
  const std::string text = assemble_shader(program.fragment);
  EXPECT_EQ(text.rfind("#version 450 core\n#define SHADOW_PASS\n#line 1 0\n", 0), 0u) << text.substr(0, 80);
  EXPECT_NE(text.find("FrustumHitF intersect_frustum_f("), std::string::npos);
  EXPECT_EQ(format_shader_log(program.fragment, "0:12(3): error: x\nERROR: 3:4: y\n"),
            "ray_frustum.glsl:12(3): error: x\nERROR: frusta.frag.glsl:4: y\n");
}

}  // namespace
}  // namespace sylva
