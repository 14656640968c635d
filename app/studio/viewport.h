// viewport.h — what the studio's UI needs from the thing that draws the plants: the GL
// viewport (gl_viewport.h) in the window, a recording fake in the headless tests. The
// UI thread calls every method; nothing here may block on the worker.
//
// The redo ladder (cpfg's New L-system / New view / New rendering menu items):
// set_plants() is called when the plants or how they are skinned changed (a regrow, a
// skin or geometry option, bark on/off); image() re-renders only when the camera, sun or
// size changed since the last picture, and never re-skins or re-uploads. A viewport may
// make its pictures on another thread: image() then returns the newest finished one at
// once, and says whether it already shows the newest plants.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <imgui.h>

#include "core/light/sun_map.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"

namespace sylva {
class ConeSet;
}

namespace sylva::studio {

struct ViewImage {
  ImTextureID texture = nullptr;  // null: nothing to show
  bool flip_v = false;            // the texture's rows are bottom-up (a GL framebuffer)
  uint32_t width = 0, height = 0;
  bool current = true;            // shows the plants of the last set_plants (not older ones)
};

struct ViewStats {
  std::vector<RenderPass> passes;  // the last picture's passes ("(GPU)" ones are GPU time)
  double render_ms = 0;            // wall time of the last picture on the UI thread
  double upload_ms = 0;            // wall time of the last set_plants (skin + upload)
  uint64_t frusta = 0;
  std::string renderer;            // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string error;               // why nothing is drawn (gl_unsupported, GlError)
  bool preview = false;            // the picture shown is new plants' quick first one (half
                                   //   the pixels a side, a small shadow map); the full
                                   //   one follows unless newer plants come first
  uint64_t previews = 0;           // previews made so far
};

class Viewport {
 public:
  virtual ~Viewport() = default;
  // `scene`'s plants (every skeleton set) are the new plants.
  virtual void set_plants(const Scene& scene, const RenderOptions& options) = 0;
  // The picture of `scene` (its camera, sun, sky, ground, width × height) over the
  // plants last set.
  virtual ViewImage image(const Scene& scene) = 0;
  virtual const ViewStats& stats() const = 0;
  // The shadow cones of the plants last set and the scene's sun, for the fog's cone modes
  // (medium, fast, auto; cone_worker.h builds them). A new sun or new plants do not drop
  // the last cones: they keep drawing until newer come; before the first the fog is drawn
  // brute. A camera move never needs new ones.
  virtual void set_fog_cones(std::shared_ptr<const ConeSet> cones) = 0;
  // The same for fog mode map's sun maps (the cone worker builds them for mode map).
  virtual void set_fog_maps(std::shared_ptr<const std::vector<SunDepthMap>> maps) = 0;
  // A texture of `rgba` (width × height, sRGB-encoded, top row first) for the UI to draw
  // (the preset browser's thumbnails), or null where the viewport makes none; freed with
  // free_texture.
  virtual ImTextureID make_texture(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
    (void)width, (void)height, (void)rgba;
    return nullptr;
  }
  virtual void free_texture(ImTextureID texture) { (void)texture; }
  // Whether a picture is being made (the UI keeps drawing frames to show it when done).
  virtual bool busy() const { return false; }
  // Renders `scene` at its width × height with `options` through the same renderer as
  // `sylva render` and writes it to `path` (format by extension, atomically); the error
  // text or nothing.
  virtual std::optional<std::string> write_image(const Scene& scene, const RenderOptions& options,
                                                 const std::string& path) = 0;
};

}  // namespace sylva::studio
