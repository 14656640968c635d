// preset_catalog.cpp — see preset_catalog.h.
#include "app/studio/preset_catalog.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <variant>

#include "app/front/render_input.h"
#include "app/studio/view_picture.h"
#include "core/cpu/render_cpu.h"
#include "core/scene/scene_json.h"
#include "core/util/file_io.h"
#include "core/util/image_io.h"

namespace sylva::studio {

namespace {

// The header block of a grammar: its leading `#` comment lines, without the `# `.
std::vector<std::string> header_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line) && !line.empty() && line[0] == '#' && !line.starts_with("#define") &&
         !line.starts_with("#include")) {
    size_t start = 1;
    while (start < line.size() && line[start] == ' ') ++start;
    lines.push_back(line.substr(start));
  }
  return lines;
}

std::string joined(const std::vector<std::string>& lines, size_t first, size_t end) {
  std::string out;
  for (size_t i = first; i < end; ++i) {
    if (lines[i].empty()) continue;
    if (!out.empty()) out += ' ';
    out += lines[i];
  }
  return out;
}

uint64_t fnv1a(uint64_t h, const std::string& bytes) {
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  return h;
}

}  // namespace

PresetEntry describe_preset(const std::string& path, const std::string& folder) {
  PresetEntry e;
  e.path = path;
  std::error_code ec;
  e.label = std::filesystem::relative(path, folder, ec).string();
  if (ec || e.label.empty()) e.label = std::filesystem::path(path).filename().string();
  if (path.ends_with(".scene.json")) {
    Expected<Scene> scene = read_scene_file(path);
    if (!scene) {
      e.title = "does not read: " + scene.error().message;
      return e;
    }
    std::vector<std::string> grammars;
    for (const ScenePlant& p : scene->plants) {
      const std::string stem = std::filesystem::path(p.grammar).filename().string();
      if (!p.grammar.empty() && std::find(grammars.begin(), grammars.end(), stem) == grammars.end())
        grammars.push_back(stem);
    }
    e.title = "a scene of " + std::to_string(scene->plants.size()) +
              (scene->plants.size() == 1 ? " plant" : " plants");
    for (size_t i = 0; i < grammars.size(); ++i) e.title += (i ? ", " : ": ") + grammars[i];
    if (scene->fog) e.title += "; fog";
    if (scene->animation) e.title += "; animated";
    return e;
  }
  Expected<std::string> text = read_text_file(path);
  if (!text) return e;
  const std::vector<std::string> lines = header_lines(*text);
  if (lines.empty()) return e;
  size_t paragraph_end = 0;
  while (paragraph_end < lines.size() && !lines[paragraph_end].empty()) ++paragraph_end;
  e.description = joined(lines, 0, paragraph_end);
  // "NAME - what it is": the title is what it is, up to the end of the first sentence.
  std::string title = e.description;
  if (size_t dash = title.find(" - "); dash != std::string::npos && dash < 60) title = title.substr(dash + 3);
  if (size_t stop = title.find(". "); stop != std::string::npos) title = title.substr(0, stop + 1);
  e.title = title;
  return e;
}

std::vector<PresetEntry> list_presets(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const char* sub : {"", "scenes"}) {
    const std::filesystem::path dir = std::filesystem::path(folder) / sub;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
      const std::string p = e.path().string();
      if (p.ends_with(".lsys") || p.ends_with(".scene.json")) files.push_back(p);
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<PresetEntry> out;
  for (const std::string& f : files) out.push_back(describe_preset(f, folder));
  return out;
}

std::string thumbnail_cache_name(const std::string& path, uint32_t width, uint32_t height) {
  uint64_t h = 14695981039346656037ull;
  h = fnv1a(h, std::to_string(width) + "x" + std::to_string(height) + " v1\n");
  if (Expected<std::string> bytes = read_text_file(path)) h = fnv1a(h, *bytes);
  if (path.ends_with(".scene.json"))
    if (Expected<Scene> scene = read_scene_file(path)) {
      std::vector<std::string> grammars;
      for (const ScenePlant& p : scene->plants) grammars.push_back(p.grammar);
      std::sort(grammars.begin(), grammars.end());
      grammars.erase(std::unique(grammars.begin(), grammars.end()), grammars.end());
      for (const std::string& g : grammars)
        if (Expected<std::string> bytes = read_text_file(g)) h = fnv1a(h, g + "\n" + *bytes);
    }
  char name[32];
  std::snprintf(name, sizeof name, "%016llx.png", static_cast<unsigned long long>(h));
  return name;
}

Thumbnail render_thumbnail(const std::string& path, uint32_t width, uint32_t height) {
  Thumbnail t;
  cli::GrammarArgs args;
  args.grammar = path;
  std::vector<RenderPass> passes;
  auto loaded = cli::load_render_input(args, width, height, passes);
  if (std::holds_alternative<cli::ExitCode>(loaded)) {
    t.error = "does not load (open it to see why)";
    return t;
  }
  Scene scene = std::move(std::get<Scene>(loaded));
  scene.fog.reset();  // a thumbnail shows the plants
  RenderOptions options;
  options.spp = 4;
  options.threads = 1;  // beside the studio's own work
  const RenderResult r = render_cpu(scene, options);
  t.width = r.image.width;
  t.height = r.image.height;
  t.rgba = srgb8_rgba(r.image);
  return t;
}

namespace {

std::optional<Thumbnail> read_cached(const std::string& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  auto in = OIIO::ImageInput::open(file);
  if (!in || in->spec().nchannels != 4) return std::nullopt;
  Thumbnail t;
  t.width = static_cast<uint32_t>(in->spec().width);
  t.height = static_cast<uint32_t>(in->spec().height);
  t.rgba.resize(static_cast<size_t>(t.width) * t.height * 4);
  if (!in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, t.rgba.data())) return std::nullopt;
  return t;
}

void write_cached(const std::string& file, const Thumbnail& t) {
  std::vector<float> pixels(t.rgba.size());
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<float>(t.rgba[i]) / 255.0f;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(file).parent_path(), ec);
  // A cache that cannot be written only costs the next start a render.
  (void)write_image_atomically(file, t.width, t.height, {"R", "G", "B", "A"}, pixels, {ChannelFormat::uint8}, true);
}

}  // namespace

ThumbnailWorker::ThumbnailWorker(std::string cache_folder, uint32_t width, uint32_t height)
    : cache_(std::move(cache_folder)), width_(width), height_(height), thread_([this] { run(); }) {}

ThumbnailWorker::~ThumbnailWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void ThumbnailWorker::request(const std::string& path) {
  {
    std::lock_guard lock(mutex_);
    if (std::find(asked_.begin(), asked_.end(), path) != asked_.end()) return;
    asked_.push_back(path);
    queue_.push_back(path);
  }
  wake_.notify_all();
}

std::vector<std::pair<std::string, Thumbnail>> ThumbnailWorker::take_finished() {
  std::lock_guard lock(mutex_);
  return std::exchange(finished_, {});
}

bool ThumbnailWorker::idle() const {
  std::lock_guard lock(mutex_);
  return queue_.empty() && !working_;
}

void ThumbnailWorker::run() {
  for (;;) {
    std::string path;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      path = std::move(queue_.front());
      queue_.pop_front();
      working_ = true;
    }
    const std::string file = cache_ + "/" + thumbnail_cache_name(path, width_, height_);
    std::optional<Thumbnail> t = read_cached(file);
    if (t) {
      ++from_cache_;
    } else {
      t = render_thumbnail(path, width_, height_);
      ++rendered_;
      if (t->error.empty()) write_cached(file, *t);
    }
    std::lock_guard lock(mutex_);
    finished_.emplace_back(std::move(path), std::move(*t));
    working_ = false;
  }
}

}  // namespace sylva::studio
