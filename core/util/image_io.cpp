// image_io.cpp — OpenImageIO output, made atomic by a temporary file and rename().
#include "core/util/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>

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

// Decodes every row of the open `input`, 64 at a time as 8 bits (little memory): the
// last row proves the file whole, where a file cut short keeps a valid header. The
// reason it stops ("row Y of H: ...") when a row does not decode.
std::optional<std::string> undecodable_row(OIIO::ImageInput& input) {
  const OIIO::ImageSpec& spec = input.spec();
  const int channels = std::max(spec.nchannels, 1);
  const uint64_t row_values = static_cast<uint64_t>(std::max(spec.width, 0)) * static_cast<uint64_t>(channels);
  const int rows = static_cast<int>(std::clamp<uint64_t>((uint64_t{16} << 20) / std::max<uint64_t>(row_values, 1), 1, 64));
  std::vector<unsigned char> buffer(row_values * static_cast<uint64_t>(rows));
  for (int y = spec.y; y < spec.y + spec.height; y += rows) {
    const int end = std::min(y + rows, spec.y + spec.height);
    if (!input.read_scanlines(0, 0, y, end, spec.z, 0, channels, OIIO::TypeDesc::UINT8, buffer.data())) {
      std::string why = input.geterror();
      if (why.empty()) why = OIIO::geterror();
      return "row " + std::to_string(y - spec.y) + " of " + std::to_string(spec.height) + (why.empty() ? "" : ": " + why);
    }
  }
  return std::nullopt;
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

std::optional<std::string> image_format_size_problem(const std::string& path, uint64_t width, uint64_t height) {
  // The formats whose encoders have a side limit of their own below image_size_problem's
  // (libjpeg's JPEG_MAX_DIMENSION: past it libjpeg's default error handler ends the
  // process; libwebp's WEBP_MAX_DIMENSION; TGA's 16-bit header fields).
  struct SideLimit {
    const char* extension;
    uint64_t side;
  };
  static constexpr SideLimit kLimits[] = {{".jpg", 65500},  {".jpeg", 65500}, {".jpe", 65500}, {".jfif", 65500},
                                          {".webp", 16383}, {".tga", 65535},  {".tpic", 65535}};
  const std::string ext = lower_extension(path);
  for (const SideLimit& limit : kLimits)
    if (ext == limit.extension && (width > limit.side || height > limit.side))
      return "a " + ext.substr(1) + " image is at most " + std::to_string(limit.side) + " pixels a side; " +
             std::to_string(width) + "x" + std::to_string(height) + " asked (use .png or .exr)";
  return std::nullopt;
}

namespace {

// Decodes every row of an encoded image (from memory when `bytes` is given, read with the
// plugin of `path`'s extension; else from the file `file`) and checks its size: what the
// encoder produced is a whole image of the size asked, not one cut short by a full disk
// or an encoder that failed without saying so.
Status check_encoded_image(const std::string& path, const std::string& file, const std::vector<unsigned char>* bytes,
                           uint32_t width, uint32_t height, size_t channels) {
  auto fail = [&](const std::string& why) {
    return file_diagnostic(path, "the image written cannot be read back (" + why + "); nothing was written");
  };
  std::unique_ptr<OIIO::Filesystem::IOMemReader> memory;
  if (bytes) memory = std::make_unique<OIIO::Filesystem::IOMemReader>(bytes->data(), bytes->size());
  auto input = OIIO::ImageInput::open(bytes ? path : file, nullptr, memory.get());
  if (!input) {
    const std::string why = OIIO::geterror();
    return fail(why.empty() ? "no reader opens it" : why);
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width != static_cast<int>(width) || spec.height != static_cast<int>(height) ||
      spec.nchannels < 1 || static_cast<size_t>(spec.nchannels) > channels)
    return fail("it reads as " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " with " +
                std::to_string(spec.nchannels) + " channels, " + std::to_string(width) + "x" +
                std::to_string(height) + " with " + std::to_string(channels) + " were written");
  if (auto row = undecodable_row(*input)) return fail(*row);
  return {};
}

}  // namespace

Expected<PendingFile> write_pending_image(const std::string& path, uint32_t width, uint32_t height,
                                          const std::vector<std::string>& channel_names,
                                          const std::vector<float>& pixels,
                                          const std::vector<ChannelFormat>& formats, bool srgb) {
  const size_t channels = channel_names.size();
  if (path.empty() || path.back() == '/') return file_diagnostic(path, "not a file name");
  if (channels == 0 || pixels.size() != static_cast<size_t>(width) * height * channels ||
      (formats.size() != 1 && formats.size() != channels))
    return file_diagnostic(path, "internal error: image buffer does not match its channels");
  if (auto problem = image_format_size_problem(path, width, height)) return file_diagnostic(path, *problem);

  // The plugin is chosen by the target's extension.
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
  auto fail = [&](const std::string& what) { return file_diagnostic(path, what); };
  auto encode = [&](const std::string& file) -> Status {
    if (!out->open(file, spec)) return fail("cannot write: " + out->geterror());
    if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) {
      std::string why = out->geterror();
      out->close();
      return fail("cannot write: " + why);
    }
    if (!out->close()) return fail("cannot write: " + out->geterror());
    return {};
  };

  // Encoded in memory where the plugin can (every format sylva documents): the plugins do
  // not all report a short write or a full disk (PNG's does not), and some name their
  // codec by the file name's extension (.jp2 or .j2k), which a temporary lacks. The bytes
  // are decoded back, then written by write_pending_file, which checks every write().
  if (out->supports("ioproxy")) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    if (!out->set_ioproxy(&proxy)) return fail("cannot write: " + out->geterror());
    if (Status encoded = encode(path); !encoded) return std::move(encoded.error());
    out.reset();
    if (Status whole = check_encoded_image(path, path, &bytes, width, height, channels); !whole)
      return std::move(whole.error());
    return write_pending_file(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }
  // Otherwise into a temporary named like the target, read back from there.
  Expected<PendingFile> pending = PendingFile::create(path);
  if (!pending) return pending;
  if (Status encoded = encode(pending->temporary()); !encoded) return std::move(encoded.error());
  out.reset();
  if (Status whole = check_encoded_image(path, pending->temporary(), nullptr, width, height, channels); !whole)
    return std::move(whole.error());
  // Make the bytes durable before the rename publishes them.
  if (Status synced = pending->sync(); !synced) return std::move(synced.error());
  return pending;
}

Status check_image_opens(const std::string& path) {
  if (Status named = check_path_has_no_nul(path); !named) return named;
  note_input_file(path);  // a texture of the scene: never an output too
  auto input = OIIO::ImageInput::open(path);
  if (input) {
    // The header's size, before any renderer allocates for it (docs/limits.md).
    const OIIO::ImageSpec& spec = input->spec();
    if (auto problem = image_size_problem(static_cast<uint64_t>(std::max(spec.width, 0)),
                                          static_cast<uint64_t>(std::max(spec.height, 0))))
      return file_diagnostic(path, "the image is too large or empty: " + *problem);
    // The pixel data must decode to its end: a renderer or viewer would show what a file
    // cut short lacks as black (or a glTF embed a broken image).
    const int channels = std::max(spec.nchannels, 1);
    if (static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(channels) > (uint64_t{1} << 28))
      return file_diagnostic(path, "the image has " + std::to_string(channels) + " channels, too many to read");
    if (auto row = undecodable_row(*input))
      return file_diagnostic(path, "the image's pixel data cannot be read (truncated or corrupt) at " + *row);
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
