// gl_views_test.cpp — the views' float split (gl_views.h): a position 10^6 m out keeps its
// low bits in lo, so that hi + lo, added back in the shaders, is the double to ~2^-48.
#include "core/gl/gl_views.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sylva {
namespace {

TEST(GlViews, AMillionMetresOutTheSplitKeepsTheLowBits) {
  for (const glm::dvec3 v : {glm::dvec3(1000000.0274970178, 0.4031818740678888, -999999.99),
                             glm::dvec3(-3.0e6 + 1e-3, 12345.678901234, 7e5 + 0.3)}) {
    const GlFloatSplit s = split_to_floats(v);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(s.hi[i], static_cast<float>(v[i])) << i;
      const double sum = static_cast<double>(s.hi[i]) + static_cast<double>(s.lo[i]);
      EXPECT_LE(std::abs(sum - v[i]), std::abs(v[i]) * 0x1p-46) << i;
    }
    EXPECT_NE(s.lo.x, 0.0f) << "the low part was lost";
  }
}

TEST(GlViews, TheCameraViewSplitsTheEye) {
  render_common::CameraFrame frame;
  frame.eye = {1e6 + 0.0275, 2, -1e6 + 0.01};
  frame.right = {1, 0, 0};
  frame.up = {0, 1, 0};
  frame.forward = {0, 0, -1};
  frame.half_width = 0.5, frame.half_height = 0.375;
  const GlCameraView view = camera_view(frame, 1e-4, 640, 480);
  EXPECT_NEAR(view.eye_lo.x, 0.0275, 1e-6);
  EXPECT_NEAR(static_cast<double>(view.eye_hi.z) + view.eye_lo.z, -1e6 + 0.01, 1e-8);
  EXPECT_EQ(view.image_size, glm::vec2(640, 480));
  EXPECT_EQ(view.near, 1e-4f);
}

}  // namespace
}  // namespace sylva
