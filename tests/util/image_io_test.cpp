// image_io_test.cpp — core/util/image_io.h at its boundary (docs/limits.md): an image
// whose header claims more pixels than the limit is refused from the header, before any
// renderer allocates for it.
#include "core/util/image_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace sylva {
namespace {

// A valid PNG header for 100000 × 100000 RGB pixels (CRCs correct), with no pixel data.
const std::string kHugePngHeader(
    "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x01\x86\xa0\x00\x01\x86\xa0\x08\x02"
    "\x00\x00\x00\x27\x30\x9c\x9f\x00\x00\x00\x08\x49\x44\x41\x54\x78\x9c\x03\x00\x00\x00\x00\x01\x48\x06\x89"
    "\xd2\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82",
    65);

TEST(ImageIo, AHeaderClaimingTooManyPixelsIsRefusedBeforeReading) {
  std::string dir = ::testing::TempDir() + "sylva-image-io-XXXXXX";
  ASSERT_NE(::mkdtemp(dir.data()), nullptr);
  const std::string path = dir + "/huge.png";
  { std::ofstream(path, std::ios::binary) << kHugePngHeader; }
  const Status opens = check_image_opens(path);
  ASSERT_FALSE(opens.ok());
  EXPECT_EQ(opens.error().message,
            "the image is too large or empty: the image must be from 1 to 65536 pixels on each side, not "
            "100000x100000");

  // A small image opens.
  ASSERT_TRUE(write_image_atomically(dir + "/small.png", 2, 2, {"R", "G", "B"}, std::vector<float>(12, 0.5f),
                                     {ChannelFormat::uint8}, true)
                  .ok());
  EXPECT_TRUE(check_image_opens(dir + "/small.png").ok());
  std::filesystem::remove_all(dir);
}

TEST(ImageIo, AnImageWhosePixelDataIsCutShortIsRefused) {
  // A PNG and an EXR of noise (so their compressed data is long), cut to 60 % of their
  // bytes: the headers still read, the pixel data does not, and the check names it.
  std::string dir = ::testing::TempDir() + "sylva-image-io-XXXXXX";
  ASSERT_NE(::mkdtemp(dir.data()), nullptr);
  std::vector<float> noise(128 * 128 * 3);
  uint32_t state = 12345;
  for (float& v : noise) v = static_cast<float>((state = state * 1664525u + 1013904223u) >> 8) / 16777216.0f;
  for (const auto& [name, format] : {std::pair{"noise.png", ChannelFormat::uint8}, {"noise.exr", ChannelFormat::half}}) {
    const std::string path = dir + "/" + name;
    ASSERT_TRUE(write_image_atomically(path, 128, 128, {"R", "G", "B"}, noise, {format}, true).ok()) << name;
    EXPECT_TRUE(check_image_opens(path).ok()) << name;
    const auto size = std::filesystem::file_size(path);
    std::filesystem::resize_file(path, size * 6 / 10);
    const Status cut = check_image_opens(path);
    ASSERT_FALSE(cut.ok()) << name << " cut short was accepted";
    EXPECT_EQ(cut.error().file, path);
    EXPECT_NE(cut.error().message.find("the image's pixel data cannot be read (truncated or corrupt) at row"),
              std::string::npos)
        << name << ": " << cut.error().message;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sylva
