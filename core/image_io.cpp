// image_io.cpp — OpenImageIO output, made atomic by a temporary file and rename().
#include "core/image_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace sylva {

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

OIIO::TypeDesc oiio_type(ChannelFormat f) {
  switch (f) {
    case ChannelFormat::uint8: return OIIO::TypeDesc::UINT8;
    case ChannelFormat::half: return OIIO::TypeDesc::HALF;
    case ChannelFormat::float32: return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::FLOAT;
}

std::string temporary_path_for(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  std::filesystem::path p(path);
  std::string name = "." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(counter.fetch_add(1));
  return (p.parent_path() / name).string();
}

}  // namespace

float linear_to_srgb(float linear) {
  float x = std::clamp(linear, 0.0f, 1.0f);
  if (!(x == x)) x = 0;  // NaN
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1 / 2.4f) - 0.055f;
}

std::optional<FileError> write_image_atomically(const std::string& path, uint32_t width, uint32_t height,
                                                const std::vector<std::string>& channel_names,
                                                const std::vector<float>& pixels,
                                                const std::vector<ChannelFormat>& formats, bool srgb) {
  const size_t channels = channel_names.size();
  if (path.empty() || path.back() == '/') return FileError{path, "not a file name", 0};
  if (channels == 0 || pixels.size() != static_cast<size_t>(width) * height * channels ||
      (formats.size() != 1 && formats.size() != channels))
    return FileError{path, "internal error: image buffer does not match its channels", 0};

  // The plugin is chosen by the target's extension; the temporary name has none.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return FileError{path, "cannot write this image format: " + OIIO::geterror(), 0};
  OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), static_cast<int>(channels),
                       oiio_type(formats[0]));
  spec.channelnames = channel_names;
  if (formats.size() == channels && std::any_of(formats.begin(), formats.end(),
                                                [&](ChannelFormat f) { return f != formats[0]; })) {
    spec.channelformats.clear();
    for (ChannelFormat f : formats) spec.channelformats.push_back(oiio_type(f));
  }
  spec.alpha_channel = -1;
  for (size_t c = 0; c < channels; ++c)
    if (channel_names[c] == "A") spec.alpha_channel = static_cast<int>(c);
  spec.z_channel = -1;
  for (size_t c = 0; c < channels; ++c)
    if (channel_names[c] == "Z") spec.z_channel = static_cast<int>(c);
  spec.attribute("oiio:ColorSpace", srgb ? "sRGB" : "Linear");
  spec.attribute("Software", "sylva");
  // A fixed date keeps images byte-identical for identical input (OpenEXR writes capDate).
  spec.attribute("DateTime", "1970:01:01 00:00:00");
  if (lower_extension(path) == ".exr") spec.attribute("compression", "zip");

  const std::string temp = temporary_path_for(path);
  auto fail = [&](const std::string& what) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    return FileError{path, what, 0};
  };
  if (!out->open(temp, spec)) return fail("cannot write: " + out->geterror());
  if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) {
    std::string why = out->geterror();
    out->close();
    return fail("cannot write: " + why);
  }
  if (!out->close()) return fail("cannot write: " + out->geterror());
  out.reset();

  // Make the bytes durable before the rename publishes them.
  int fd = ::open(temp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    int error = errno;
    if (fd >= 0) ::close(fd);
    FileError e = fail(std::string("cannot sync the temporary file: ") + std::strerror(error));
    e.error_number = error;
    return e;
  }
  ::close(fd);
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    int error = errno;
    FileError e = fail(std::string("cannot rename the temporary file over it: ") + std::strerror(error));
    e.error_number = error;
    return e;
  }
  return std::nullopt;
}

bool can_write_image_format(const std::string& path) {
  return OIIO::ImageOutput::create(path) != nullptr;
}

std::string aov_path(const std::string& image_path, const std::string& aov_name) {
  if (lower_extension(image_path) == ".exr") return image_path;
  std::filesystem::path p(image_path);
  p.replace_extension();
  return p.string() + "." + aov_name + ".exr";
}

ImageWriteResult write_render(const std::string& path, const RenderImage& image) {
  ImageWriteResult result;
  const std::string ext = lower_extension(path);
  const size_t pixels = static_cast<size_t>(image.width) * image.height;
  struct Aov {
    const char* name;
    const std::vector<float>* data;
    std::vector<std::string> channels;
  };
  const Aov aovs[] = {
      {"depth", &image.depth, {"Z"}},
      {"normal", &image.normal, {"N.X", "N.Y", "N.Z"}},
      {"uv", &image.uv, {"U", "V"}},
      {"id", &image.id, {"id.plant", "id.chain", "id.segment"}},
  };

  if (ext == ".exr") {
    // One file: beauty as half, every AOV as float channels after it.
    std::vector<std::string> names = {"R", "G", "B", "A"};
    std::vector<ChannelFormat> formats(4, ChannelFormat::half);
    for (const Aov& a : aovs)
      if (!a.data->empty())
        for (const std::string& c : a.channels) names.push_back(c), formats.push_back(ChannelFormat::float32);
    const size_t n = names.size();
    std::vector<float> buffer(pixels * n);
    for (size_t p = 0; p < pixels; ++p) {
      float* dst = &buffer[p * n];
      for (int c = 0; c < 4; ++c) *dst++ = image.beauty[p * 4 + c];
      for (const Aov& a : aovs)
        if (!a.data->empty())
          for (size_t c = 0; c < a.channels.size(); ++c) *dst++ = (*a.data)[p * a.channels.size() + c];
    }
    if (auto e = write_image_atomically(path, image.width, image.height, names, buffer, formats, false))
      result.error = e;
    else
      result.written.push_back(path);
    return result;
  }

  // AOVs first: the picture itself appears last, when everything else is in place.
  for (const Aov& a : aovs) {
    if (a.data->empty()) continue;
    const std::string side = aov_path(path, a.name);
    if (auto e = write_image_atomically(side, image.width, image.height, a.channels, *a.data,
                                        {ChannelFormat::float32}, false)) {
      result.error = e;
      return result;
    }
    result.written.push_back(side);
  }
  const bool linear = ext == ".hdr" || ext == ".pfm" || ext == ".tif" || ext == ".tiff";
  std::vector<float> beauty = image.beauty;
  std::vector<std::string> names = {"R", "G", "B", "A"};
  if (ext == ".hdr" || ext == ".jpg" || ext == ".jpeg" || ext == ".pfm") {
    // Formats without alpha: drop it (A is 1 everywhere anyway).
    names.pop_back();
    std::vector<float> rgb(pixels * 3);
    for (size_t p = 0; p < pixels; ++p)
      for (int c = 0; c < 3; ++c) rgb[p * 3 + c] = beauty[p * 4 + c];
    beauty.swap(rgb);
  }
  if (!linear)
    for (size_t i = 0; i < beauty.size(); ++i)
      if (names.size() == 3 || i % 4 != 3) beauty[i] = linear_to_srgb(beauty[i]);
  if (auto e = write_image_atomically(path, image.width, image.height, names, beauty,
                                      {linear ? ChannelFormat::float32 : ChannelFormat::uint8}, !linear))
    result.error = e;
  else
    result.written.push_back(path);
  return result;
}

}  // namespace sylva
