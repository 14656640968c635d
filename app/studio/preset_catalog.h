// preset_catalog.h — the studio's preset browser (issue 31 §5): every preset with what its
// header says it is, and a thumbnail rendered once by the CPU ray caster and kept on disk.
//
// A grammar's header is its first block of `#` comment lines (presets_test.cpp requires
// one): the title is its first line after "NAME - " (e.g. "an American elm (Ulmus
// americana) in summer: ..."), the description that block's first paragraph as one line.
// A scene's title counts its plants and names their grammars.
//
// Thumbnails: drawn by `sylva render`'s loader and CPU ray caster (fog left out: a
// thumbnail shows the plants) at a small size, on one background thread, in the order asked.
// Each is written to CACHE/<key>.png, the key a 64-bit hash of the file's bytes (and, for a
// scene, of its grammars' bytes) and the thumbnail size, so a preset is rendered once until
// it changes; a later request reads the PNG back. A preset that does not load gets an
// error text instead of pixels.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace sylva::studio {

struct PresetEntry {
  std::string path;         // as found under the folder
  std::string label;        // relative to the presets folder: "elm.lsys", "scenes/pine.scene.json"
  std::string title;        // one line: what the header says it is (empty if it says nothing)
  std::string description;  // the header's first paragraph as one line (empty if none)
};

// The .lsys grammars and .scene.json scenes in `folder` and `folder`/scenes, by label.
std::vector<PresetEntry> list_presets(const std::string& folder);

// The title and description of the preset at `path` (label relative to `folder`).
PresetEntry describe_preset(const std::string& path, const std::string& folder);

struct Thumbnail {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // sRGB-encoded, top row first; empty with an error
  std::string error;          // why there is no picture
};

// The cache file name (without folder) of the thumbnail of `path` at width × height.
std::string thumbnail_cache_name(const std::string& path, uint32_t width, uint32_t height);

// Renders the thumbnail of `path` now (the worker's job; for tests and benches).
Thumbnail render_thumbnail(const std::string& path, uint32_t width, uint32_t height);

class ThumbnailWorker {
 public:
  ThumbnailWorker(std::string cache_folder, uint32_t width, uint32_t height);
  ~ThumbnailWorker();  // stops after the thumbnail in progress
  ThumbnailWorker(const ThumbnailWorker&) = delete;
  ThumbnailWorker& operator=(const ThumbnailWorker&) = delete;

  // Adds `path` to the queue unless it was asked for before.
  void request(const std::string& path);
  // The thumbnails finished since the last call, with their paths.
  std::vector<std::pair<std::string, Thumbnail>> take_finished();
  bool idle() const;                // nothing queued or in progress
  uint64_t rendered() const { return rendered_.load(); }      // drawn by the ray caster
  uint64_t from_cache() const { return from_cache_.load(); }  // read back from the cache

 private:
  void run();
  const std::string cache_;
  const uint32_t width_, height_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::string> queue_;
  std::vector<std::string> asked_;
  std::vector<std::pair<std::string, Thumbnail>> finished_;
  bool working_ = false, stop_ = false;
  std::atomic<uint64_t> rendered_{0}, from_cache_{0};
  std::thread thread_;
};

}  // namespace sylva::studio
