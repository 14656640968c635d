// image_io.h — writing rendered images with OpenImageIO, atomically (cli.md): the pixels
// go to a temporary file in the target's folder through OIIO, which is fsynced and then
// renamed over the target, so a failed or interrupted write never leaves a truncated
// file and never damages one that was there.
//
// Encodings by the target's extension:
//   .exr             linear; beauty R G B A as half, AOVs as extra float channels in the
//                    same file (Z; N.X N.Y N.Z; U V; id.plant id.chain id.segment)
//   .hdr .pfm .tif .tiff   linear float beauty; AOVs in side files as for a PNG
//   anything else OIIO writes (.png, .jpg, ...)   8-bit sRGB-encoded beauty; each AOV
//                    goes to its own EXR next to it, named after the image without its
//                    extension: saguaro.png → saguaro.depth.exr, saguaro.normal.exr,
//                    saguaro.uv.exr, saguaro.id.exr
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "core/render_cpu.h"

namespace sylva {

// How one channel is stored in the file.
enum class ChannelFormat : uint8_t { uint8, half, float32 };

// Writes `pixels` (interleaved float, row-major from the top-left, one value per channel
// named in `channel_names`) to `path` in the format OIIO picks from its extension,
// atomically. `formats` gives each channel's storage (one entry: all channels); uint8
// channels are expected already encoded in [0, 1] (values are clamped and rounded).
// `srgb`: tag the file as sRGB (else linear).
std::optional<FileError> write_image_atomically(const std::string& path, uint32_t width,
                                                uint32_t height,
                                                const std::vector<std::string>& channel_names,
                                                const std::vector<float>& pixels,
                                                const std::vector<ChannelFormat>& formats,
                                                bool srgb);

// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1].
float linear_to_srgb(float linear);

// Whether OpenImageIO has a writer for `path`'s extension (checked before rendering).
bool can_write_image_format(const std::string& path);

// The file each AOV goes to for `image_path` (itself for an EXR; a side file otherwise).
std::string aov_path(const std::string& image_path, const std::string& aov_name);

// Writes a render: the beauty and every AOV the image holds, as described above.
// Returns the paths written, or the first error (files already renamed stay).
struct ImageWriteResult {
  std::vector<std::string> written;
  std::optional<FileError> error;
};
ImageWriteResult write_render(const std::string& path, const RenderImage& image);

}  // namespace sylva
