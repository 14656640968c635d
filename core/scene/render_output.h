// render_output.h — a render's images in files (docs/spec/cli.md): the beauty and every AOV the
// image holds, each file written atomically (util/image_io.h).
//
// Encodings by the target's extension:
//   .exr             linear; beauty R G B A as half, AOVs as extra float channels in the
//                    same file (Z; N.X N.Y N.Z; U V; id.plant id.chain id.segment;
//                    fog.R fog.G fog.B fog.T)
//   .hdr .pfm .tif .tiff   linear float beauty; AOVs in side files as for a PNG
//   anything else OIIO writes (.png, .jpg, ...)   8-bit sRGB-encoded beauty; each AOV
//                    goes to its own EXR next to it, named after the image without its
//                    extension: saguaro.png → saguaro.depth.exr, saguaro.normal.exr,
//                    saguaro.uv.exr, saguaro.id.exr, saguaro.fog.exr
#pragma once

#include <string>
#include <vector>

#include "core/scene/render_types.h"
#include "core/util/diagnostic.h"

namespace sylva {

// The file each AOV goes to for `image_path` (itself for an EXR; a side file otherwise).
std::string aov_path(const std::string& image_path, const std::string& aov_name);

// Every file write_render writes for `image_path` and the AOV bits `aovs` (render_types.h).
std::vector<std::string> render_output_paths(const std::string& image_path, uint32_t aovs);

// Writes a render: the beauty and every AOV the image holds, as described above, all or
// nothing (docs/limits.md "Outputs"): every file is complete in its temporary before the
// first replaces its target. Returns the paths written, or the first error.
Expected<std::vector<std::string>> write_render(const std::string& path, const RenderImage& image);

}  // namespace sylva
