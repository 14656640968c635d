// image_io.h — writing images with OpenImageIO, atomically (docs/spec/cli.md): the pixels go to a
// temporary file in the target's folder through OIIO, which is fsynced and then renamed
// over the target, so a failed or interrupted write never leaves a truncated file and
// never damages one that was there. Knows nothing of renders: core/scene/render_output.h lays
// a render's beauty and AOVs out into files.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/util/diagnostic.h"
#include "core/util/file_io.h"

namespace sylva {

// How one channel is stored in the file.
enum class ChannelFormat : uint8_t { uint8, half, float32 };

// Writes `pixels` (interleaved float, row-major from the top-left, one value per channel
// named in `channel_names`) to `path` in the format OIIO picks from its extension,
// atomically. `formats` gives each channel's storage (one entry: all channels); uint8
// channels are expected already encoded in [0, 1] (values are clamped and rounded).
// `srgb`: tag the file as sRGB (else linear).
// Failure: a Diagnostic for `path` as a whole (with the errno where a system call failed).
// The target must pass check_output_path (file_io.h).
Status write_image_atomically(const std::string& path, uint32_t width, uint32_t height,
                              const std::vector<std::string>& channel_names, const std::vector<float>& pixels,
                              const std::vector<ChannelFormat>& formats, bool srgb);

// The first half of write_image_atomically: the complete image in a temporary next to
// `path`, to be renamed with others by commit_files (file_io.h), all or nothing. The
// image is encoded in memory and decoded back to its last row before a byte reaches the
// disk, then written with every write() checked: an encoder that fails without saying so
// or a full disk is a Diagnostic, never a truncated or empty file. A size past the
// format's own limit (image_format_size_problem) is refused before the encoder runs.
Expected<PendingFile> write_pending_image(const std::string& path, uint32_t width, uint32_t height,
                                          const std::vector<std::string>& channel_names,
                                          const std::vector<float>& pixels,
                                          const std::vector<ChannelFormat>& formats, bool srgb);

// The lower-case extension of `path`, with its dot (".png"; "" when there is none).
std::string lower_extension(const std::string& path);

// Whether OpenImageIO can open `path` as an image of an accepted size whose pixel data
// decodes to its end (a file cut short is refused, naming the row); if not, a Diagnostic
// for `path` whose message says why (OIIO's reason where it gives one).
Status check_image_opens(const std::string& path);

// Whether OpenImageIO has a writer for `path`'s extension (checked before rendering).
// image_format_size_problem: why an image of width x height cannot be written in
// `path`'s format (JPEG: at most 65,500 pixels a side; WebP 16,383; TGA 65,535), or none.
bool can_write_image_format(const std::string& path);
std::optional<std::string> image_format_size_problem(const std::string& path, uint64_t width, uint64_t height);

}  // namespace sylva
