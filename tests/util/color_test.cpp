// color_test.cpp — the sRGB transfer function both ways (util/color.h).
#include "core/util/color.h"

#include <gtest/gtest.h>

namespace sylva {
namespace {

TEST(Color, SrgbDecodingIsIec61966) {
  EXPECT_EQ(srgb_to_linear(0), 0);
  EXPECT_NEAR(srgb_to_linear(1), 1, 1e-15);
  EXPECT_NEAR(srgb_to_linear(0.04045), 0.04045 / 12.92, 1e-15);
  EXPECT_NEAR(srgb_to_linear(0.5), 0.21404114048223255, 1e-12);
  for (float v = 0; v <= 1; v += 0.01f) EXPECT_NEAR(linear_to_srgb(static_cast<float>(srgb_to_linear(v))), v, 1e-5);
}

TEST(Color, EncodingClampsAndMapsNanToZero) {
  EXPECT_EQ(linear_to_srgb(-1.0f), 0.0f);
  EXPECT_NEAR(linear_to_srgb(2.0f), 1.0f, 1e-6);
  EXPECT_EQ(linear_to_srgb(std::numeric_limits<float>::quiet_NaN()), 0.0f);
  EXPECT_NEAR(linear_to_srgb(0.0031308f), 12.92f * 0.0031308f, 1e-6);
}

}  // namespace
}  // namespace sylva
