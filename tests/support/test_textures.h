// test_textures.h — small synthetic texture files for the texture and relief tests,
// written with sylva's own image writer into a temporary folder removed afterwards.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/util/image_io.h"

namespace sylva::test {

// A fresh temporary folder, removed with its contents at the end of the scope.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "sylva-texture-test-XXXXXX").string();
    EXPECT_NE(::mkdtemp(pattern.data()), nullptr);
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// An 8-bit PNG of N channels named `names` whose texel (x, y) (row y from the top) holds
// `texel(x, y)`: colour sRGB-encoded values in [0, 1] (stored as round(255·v)), alpha linear.
template <size_t N>
void write_png8(const std::string& path, uint32_t width, uint32_t height, const std::vector<std::string>& names,
                const std::function<std::array<float, N>(uint32_t, uint32_t)>& texel) {
  std::vector<float> pixels;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x)
      for (float c : texel(x, y)) pixels.push_back(c);
  const auto error = write_image_atomically(path, width, height, names, pixels, {ChannelFormat::uint8}, true);
  ASSERT_TRUE(error.ok()) << error.error().message;
}

// An 8-bit RGB PNG (write_png8).
inline void write_rgb_png(const std::string& path, uint32_t width, uint32_t height,
                          const std::function<std::array<float, 3>(uint32_t, uint32_t)>& encoded) {
  write_png8<3>(path, width, height, {"R", "G", "B"}, encoded);
}

// An 8-bit RGBA PNG (write_png8): RGB sRGB-encoded, A = alpha in [0, 1].
inline void write_rgba_png(const std::string& path, uint32_t width, uint32_t height,
                           const std::function<std::array<float, 4>(uint32_t, uint32_t)>& texel) {
  write_png8<4>(path, width, height, {"R", "G", "B", "A"}, texel);
}

// A one-channel float image (EXR, TIFF, ...) with value(x, y) at texel (x, y).
inline void write_gray_float(const std::string& path, uint32_t width, uint32_t height,
                             const std::function<float(uint32_t, uint32_t)>& value) {
  std::vector<float> pixels;
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) pixels.push_back(value(x, y));
  const auto error = write_image_atomically(path, width, height, {"Y"}, pixels,
                                            {ChannelFormat::float32}, false);
  ASSERT_TRUE(error.ok()) << error.error().message;
}

}  // namespace sylva::test
