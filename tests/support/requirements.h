// requirements.h — a test that needs what a machine may lack (an OpenGL 4.5 context; a
// program such as blender, xvfb-run, ffmpeg or glslangValidator) skips, saying why, on a
// developer's machine. Where the environment says the thing is required, the same test
// fails instead, so that a broken driver or a missing package cannot turn a suite green by
// skipping: .ci/run sets SYLVA_REQUIRE_GL=1 (an EGL context must be made) and
// SYLVA_REQUIRE_TOOLS=1 (every program scripts/setup.sh installs must be there).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

namespace sylva::test {

// Whether environment variable `name` is "1".
inline bool required(const char* name) {
  const char* value = std::getenv(name);
  return value && std::strcmp(value, "1") == 0;
}

}  // namespace sylva::test

// Skips the current test with `message` (stream syntax allowed: "no GL: " << why), or fails
// it when the environment variable `env` (a string literal) is "1". A statement of a test
// body (it returns from the function).
#define SYLVA_SKIP_UNLESS_REQUIRED(env, message)                               \
  do {                                                                         \
    if (::sylva::test::required(env))                                          \
      GTEST_FAIL() << message << " (" env "=1: required here)";                \
    else                                                                       \
      GTEST_SKIP() << message;                                                 \
  } while (0)

// No OpenGL 4.5 context: skip, or fail under SYLVA_REQUIRE_GL=1.
#define SYLVA_SKIP_WITHOUT_GL(message) SYLVA_SKIP_UNLESS_REQUIRED("SYLVA_REQUIRE_GL", message)
// A program scripts/setup.sh installs is missing: skip, or fail under SYLVA_REQUIRE_TOOLS=1.
#define SYLVA_SKIP_WITHOUT_TOOL(message) SYLVA_SKIP_UNLESS_REQUIRED("SYLVA_REQUIRE_TOOLS", message)
