// preset_catalog_test.cpp — the preset browser (issue 31 §5): what each preset's header
// says it is, thumbnails rendered once and read back from their cache, and the browser
// drawing them.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "app/studio/preset_catalog.h"
#include "core/util/file_io.h"
#include "tests/studio/headless_ui.h"
#include "tests/support/process.h"

namespace sylva::studio {
namespace {

namespace fs = std::filesystem;
const std::string kPresets = std::string(SYLVA_SOURCE_DIR) + "/presets";

TEST(PresetCatalog, EveryPresetIsListedWithWhatItsHeaderSaysItIs) {
  const std::vector<PresetEntry> all = list_presets(kPresets);
  std::map<std::string, PresetEntry> by_label;
  for (const PresetEntry& e : all) by_label[e.label] = e;
  ASSERT_TRUE(by_label.count("elm_in_leaf.lsys"));
  ASSERT_TRUE(by_label.count("scenes/pine.scene.json"));
  EXPECT_TRUE(std::is_sorted(all.begin(), all.end(), [](auto& a, auto& b) { return a.path < b.path; }));
  // A grammar: the header's first line after "NAME - ", to the end of its first sentence...
  const PresetEntry& elm = by_label["elm_in_leaf.lsys"];
  EXPECT_TRUE(elm.title.starts_with("an American elm (Ulmus americana) in summer")) << elm.title;
  EXPECT_EQ(elm.title.find("elm_in_leaf.lsys -"), std::string::npos) << elm.title;
  // ...and its first paragraph on one line.
  EXPECT_TRUE(elm.description.starts_with("elm_in_leaf.lsys - an American elm")) << elm.description;
  EXPECT_NE(elm.description.find("polygon leaves"), std::string::npos) << elm.description;
  EXPECT_EQ(elm.description.find('\n'), std::string::npos);
  EXPECT_EQ(elm.description.find("Source:"), std::string::npos) << "the first paragraph only";
  // Every grammar preset says something (presets_test.cpp requires the header).
  for (const PresetEntry& e : all)
    if (e.label.ends_with(".lsys")) {
      EXPECT_FALSE(e.title.empty()) << e.label;
    }
  // A scene: its plants and grammars, its fog.
  const PresetEntry& pine = by_label["scenes/pine.scene.json"];
  EXPECT_TRUE(pine.title.starts_with("a scene of 1 plant: pine")) << pine.title;
  ASSERT_TRUE(by_label.count("scenes/pine_stand_low_sun.scene.json"));
  EXPECT_NE(by_label["scenes/pine_stand_low_sun.scene.json"].title.find("; fog"), std::string::npos);
}

// A presets folder of two: the saguaro and a grammar that does not parse.
struct ThumbnailFolder {
  ThumbnailFolder() {
    fs::create_directories(dir.file("presets"));
    fs::copy_file(kPresets + "/saguaro.lsys", dir.file("presets/saguaro.lsys"));
    EXPECT_TRUE(write_file_atomically(dir.file("presets/broken.lsys"), "# broken - no axiom\nA -> (\n").ok());
  }
  std::string presets() const { return dir.file("presets"); }
  std::string cache() const { return dir.file("cache"); }
  TempDir dir;
};

std::map<std::string, Thumbnail> wait_for(ThumbnailWorker& worker, size_t n) {
  std::map<std::string, Thumbnail> out;
  for (int i = 0; i < 6000 && out.size() < n; ++i) {
    for (auto& [path, t] : worker.take_finished()) out[fs::path(path).filename().string()] = std::move(t);
    if (out.size() < n) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return out;
}

TEST(PresetCatalog, ThumbnailsAreRenderedOnceAndReadBackFromTheirCacheUntilThePresetChanges) {
  ThumbnailFolder f;
  std::vector<uint8_t> first;
  {
    ThumbnailWorker worker(f.cache(), 48, 36);
    for (const char* name : {"saguaro.lsys", "broken.lsys", "saguaro.lsys"}) worker.request(f.presets() + "/" + name);
    std::map<std::string, Thumbnail> got = wait_for(worker, 2);
    ASSERT_EQ(got.size(), 2u);
    const Thumbnail& saguaro = got["saguaro.lsys"];
    ASSERT_TRUE(saguaro.error.empty()) << saguaro.error;
    ASSERT_EQ(saguaro.width, 48u);
    ASSERT_EQ(saguaro.height, 36u);
    ASSERT_EQ(saguaro.rgba.size(), 48u * 36u * 4u);
    // A picture, not a flat fill: sky above, ground and cactus below differ.
    EXPECT_NE(std::vector<uint8_t>(saguaro.rgba.begin(), saguaro.rgba.begin() + 4),
              std::vector<uint8_t>(saguaro.rgba.end() - 4, saguaro.rgba.end()));
    first = saguaro.rgba;
    EXPECT_FALSE(got["broken.lsys"].error.empty());
    EXPECT_TRUE(got["broken.lsys"].rgba.empty());
    EXPECT_EQ(worker.rendered(), 2u);  // asked twice, drawn once
    EXPECT_EQ(worker.from_cache(), 0u);
    EXPECT_TRUE(worker.idle());
  }
  ASSERT_TRUE(fs::exists(f.cache() + "/" + thumbnail_cache_name(f.presets() + "/saguaro.lsys", 48, 36)));
  {
    ThumbnailWorker again(f.cache(), 48, 36);
    again.request(f.presets() + "/saguaro.lsys");
    std::map<std::string, Thumbnail> got = wait_for(again, 1);
    EXPECT_EQ(again.from_cache(), 1u);
    EXPECT_EQ(again.rendered(), 0u);
    EXPECT_EQ(got["saguaro.lsys"].rgba, first) << "the cached PNG holds the picture exactly";
  }
  // Another size, or an edited preset, is another thumbnail.
  EXPECT_NE(thumbnail_cache_name(f.presets() + "/saguaro.lsys", 48, 36),
            thumbnail_cache_name(f.presets() + "/saguaro.lsys", 96, 72));
  const std::string before = thumbnail_cache_name(f.presets() + "/saguaro.lsys", 48, 36);
  ASSERT_TRUE(write_file_atomically(f.presets() + "/saguaro.lsys",
                                    read_text_file(f.presets() + "/saguaro.lsys").value() + "\n# edited\n")
                  .ok());
  EXPECT_NE(thumbnail_cache_name(f.presets() + "/saguaro.lsys", 48, 36), before);
}

TEST(PresetCatalog, TheBrowserShowsEachPresetsThumbnailAndTitle) {
  ThumbnailFolder f;
  test::FakeViewport viewport;
  test::HeadlessUi ui;
  StudioOptions o;
  o.presets_dir = f.presets();
  o.thumbnail_cache = f.cache();
  auto app = std::make_unique<StudioApp>(o, &viewport);
  ui.frames(*app, 2);
  ASSERT_TRUE(app->rect("thumbnail:saguaro.lsys"));
  ASSERT_TRUE(app->rect("preset:saguaro.lsys"));
  ASSERT_TRUE(app->rect("preset title:saguaro.lsys"));
  // The title sits under the label, beside the thumbnail.
  EXPECT_GT(app->rect("preset title:saguaro.lsys")->min.y, app->rect("preset:saguaro.lsys")->min.y);
  EXPECT_GT(app->rect("preset:saguaro.lsys")->min.x, app->rect("thumbnail:saguaro.lsys")->max.x);
  ASSERT_TRUE(ui.until(*app, [&] { return !viewport.textures.empty(); }));
  ui.frames(*app, 2);
  ASSERT_EQ(viewport.textures.size(), 1u) << "the broken preset gets no texture";
  EXPECT_EQ(viewport.textures[0].width, kThumbnailWidth);
  EXPECT_EQ(viewport.textures[0].height, kThumbnailHeight);
  EXPECT_EQ(viewport.textures[0].bytes, size_t{kThumbnailWidth} * kThumbnailHeight * 4);
  app.reset();
  EXPECT_EQ(viewport.freed_textures, 1);
}

}  // namespace
}  // namespace sylva::studio
