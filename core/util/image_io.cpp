// image_io.cpp — OpenImageIO output, made atomic by a temporary file and rename().
#include "core/util/image_io.h"

#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/util/limits.h"

namespace sylva {

namespace {

OIIO::TypeDesc oiio_type(ChannelFormat f) {
  switch (f) {
    case ChannelFormat::uint8: return OIIO::TypeDesc::UINT8;
    case ChannelFormat::half: return OIIO::TypeDesc::HALF;
    case ChannelFormat::float32: return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::FLOAT;
}

}  // namespace

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

Status write_image_atomically(const std::string& path, uint32_t width, uint32_t height,
                              const std::vector<std::string>& channel_names, const std::vector<float>& pixels,
                              const std::vector<ChannelFormat>& formats, bool srgb) {
  Expected<PendingFile> pending = write_pending_image(path, width, height, channel_names, pixels, formats, srgb);
  if (!pending) return std::move(pending.error());
  std::vector<PendingFile> files;
  files.push_back(std::move(*pending));
  return commit_files(files);
}

Expected<PendingFile> write_pending_image(const std::string& path, uint32_t width, uint32_t height,
                                          const std::vector<std::string>& channel_names,
                                          const std::vector<float>& pixels,
                                          const std::vector<ChannelFormat>& formats, bool srgb) {
  const size_t channels = channel_names.size();
  if (path.empty() || path.back() == '/') return file_diagnostic(path, "not a file name");
  if (channels == 0 || pixels.size() != static_cast<size_t>(width) * height * channels ||
      (formats.size() != 1 && formats.size() != channels))
    return file_diagnostic(path, "internal error: image buffer does not match its channels");

  // The plugin is chosen by the target's extension; the temporary name has none.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return file_diagnostic(path, "cannot write this image format: " + OIIO::geterror());
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

  Expected<PendingFile> pending = PendingFile::create(path);
  if (!pending) return pending;
  const std::string& temp = pending->temporary();
  auto fail = [&](const std::string& what) { return file_diagnostic(path, what); };
  if (!out->open(temp, spec)) return fail("cannot write: " + out->geterror());
  if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) {
    std::string why = out->geterror();
    out->close();
    return fail("cannot write: " + why);
  }
  if (!out->close()) return fail("cannot write: " + out->geterror());
  out.reset();
  // Make the bytes durable before the rename publishes them.
  if (Status synced = pending->sync(); !synced) return std::move(synced.error());
  return pending;
}

Status check_image_opens(const std::string& path) {
  note_input_file(path);  // a texture of the scene: never an output too
  auto input = OIIO::ImageInput::open(path);
  if (input) {
    // The header's size, before any renderer allocates for it (docs/limits.md).
    const OIIO::ImageSpec& spec = input->spec();
    if (auto problem = image_size_problem(static_cast<uint64_t>(std::max(spec.width, 0)),
                                          static_cast<uint64_t>(std::max(spec.height, 0))))
      return file_diagnostic(path, "the image is too large or empty: " + *problem);
    // The pixel data must decode to its end: a file cut short keeps a valid header, and a
    // renderer or viewer would show what it lacks as black (or a glTF embed a broken
    // image). Decoded 64 rows at a time as 8-bit, so the check takes little memory.
    const int channels = std::max(spec.nchannels, 1);
    const uint64_t row_bytes = static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(channels);
    if (row_bytes > (uint64_t{1} << 28))
      return file_diagnostic(path, "the image has " + std::to_string(channels) + " channels, too many to read");
    const int rows = static_cast<int>(std::clamp<uint64_t>((uint64_t{16} << 20) / row_bytes, 1, 64));
    std::vector<unsigned char> buffer(row_bytes * static_cast<uint64_t>(rows));
    for (int y = spec.y; y < spec.y + spec.height; y += rows) {
      const int end = std::min(y + rows, spec.y + spec.height);
      if (!input->read_scanlines(0, 0, y, end, spec.z, 0, channels, OIIO::TypeDesc::UINT8, buffer.data())) {
        std::string why = input->geterror();
        if (why.empty()) why = OIIO::geterror();
        return file_diagnostic(path, "the image's pixel data cannot be read (truncated or corrupt) at row " +
                                         std::to_string(y - spec.y) + " of " + std::to_string(spec.height) +
                                         (why.empty() ? "" : ": " + why));
      }
    }
    return {};
  }
  std::string reason = OIIO::geterror();
  if (reason.empty()) reason = "OpenImageIO cannot read it";
  return file_diagnostic(path, reason);
}

bool can_write_image_format(const std::string& path) {
  return OIIO::ImageOutput::create(path) != nullptr;
}

}  // namespace sylva
