// gl_context_test.cpp — the headless EGL context (gl_context.h).
#include "core/gl/gl_context.h"

#include <gtest/gtest.h>

#include "core/gl/gl_api.h"
#include "tests/support/gl_checks.h"

namespace sylva {
namespace {

TEST(GlContext, HeadlessContextIsOpenGl45Core) {
  SYLVA_REQUIRE_GL();
  std::string why;
  GlContext* context = gl_test::shared_context(&why);
  GLint major = 0, minor = 0, profile = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_GE(major * 10 + minor, 45);
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
  EXPECT_FALSE(context->info().renderer.empty());
  std::printf("[ context ] %s\n", context->info().describe().c_str());
}

TEST(GlContext, TimerQueriesCount) {
  SYLVA_REQUIRE_GL();
  GLint bits = 0;
  glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
  EXPECT_GT(bits, 0) << "GL_TIME_ELAPSED has no counter bits: --verbose GPU times would read 0";
}

}  // namespace
}  // namespace sylva
