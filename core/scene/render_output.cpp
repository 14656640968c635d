// render_output.cpp — a render's beauty and AOVs laid out into files.
#include "core/scene/render_output.h"

#include <filesystem>
#include <utility>

#include "core/util/color.h"
#include "core/util/image_io.h"

namespace sylva {

std::string aov_path(const std::string& image_path, const std::string& aov_name) {
  if (lower_extension(image_path) == ".exr") return image_path;
  std::filesystem::path p(image_path);
  p.replace_extension();
  return p.string() + "." + aov_name + ".exr";
}

std::vector<std::string> render_output_paths(const std::string& image_path, uint32_t aovs) {
  std::vector<std::string> paths;
  const std::pair<uint32_t, const char*> names[] = {
      {kAovDepth, "depth"}, {kAovNormal, "normal"}, {kAovUv, "uv"}, {kAovId, "id"}, {kAovFog, "fog"}};
  if (lower_extension(image_path) != ".exr")
    for (const auto& [bit, name] : names)
      if (aovs & bit) paths.push_back(aov_path(image_path, name));
  paths.push_back(image_path);
  return paths;
}

Expected<std::vector<std::string>> write_render(const std::string& path, const RenderImage& image) {
  std::vector<std::string> written;
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
      {"fog", &image.fog, {"fog.R", "fog.G", "fog.B", "fog.T"}},
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
    if (Status e = write_image_atomically(path, image.width, image.height, names, buffer, formats, false); !e)
      return std::move(e.error());
    written.push_back(path);
    return written;
  }

  // Every file is written to its temporary before any is renamed (all or nothing); the
  // AOVs are renamed first, so the picture itself appears last, when the rest is in place.
  std::vector<PendingFile> pending;
  for (const Aov& a : aovs) {
    if (a.data->empty()) continue;
    const std::string side = aov_path(path, a.name);
    Expected<PendingFile> file =
        write_pending_image(side, image.width, image.height, a.channels, *a.data, {ChannelFormat::float32}, false);
    if (!file) return std::move(file.error());
    pending.push_back(std::move(*file));
    written.push_back(side);
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
  Expected<PendingFile> file = write_pending_image(path, image.width, image.height, names, beauty,
                                                  {linear ? ChannelFormat::float32 : ChannelFormat::uint8}, !linear);
  if (!file) return std::move(file.error());
  pending.push_back(std::move(*file));
  written.push_back(path);
  if (Status e = commit_files(pending); !e) return std::move(e.error());
  return written;
}

}  // namespace sylva
