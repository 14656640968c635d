// headless_ui.h — Dear ImGui without a window or GL (the first of the studio's three test
// tiers: headless, screenshots, the real window driven by xdotool): a context with a built font atlas, a fixed display size and simulated input,
// one frame per call, driving a StudioApp exactly as the window's loop does. Keys are
// mapped as GLFW maps them (letters are their upper-case ASCII codes), and the text
// widget's own undo keys are unmapped as in studio_main.cpp.
#pragma once

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>

#include <unistd.h>

#include <imgui.h>

#include "app/studio/studio_app.h"
#include "app/studio/viewport.h"

namespace sylva::studio::test {

// A viewport that records what the UI asked of it (the redo ladder), drawing nothing.
class FakeViewport : public Viewport {
 public:
  void set_plants(const Scene& scene, const RenderOptions&) override {
    ++set_plants_calls;
    segments = 0;
    wood_m = 0;
    skins.clear();
    for (const ScenePlant& p : scene.plants) {
      if (p.skeleton) {
        segments += p.skeleton->segment_count();
        for (const Chain& c : p.skeleton->chains)
          for (uint32_t j = 1; j < c.joint_count; ++j) {
            const Joint& a = p.skeleton->joints[c.first_joint + j - 1];
            const Joint& b = p.skeleton->joints[c.first_joint + j];
            wood_m += std::hypot(b.position_m[0] - a.position_m[0], b.position_m[1] - a.position_m[1],
                                 b.position_m[2] - a.position_m[2]);
          }
      }
      skins.push_back(p.skin);
    }
  }
  ViewImage image(const Scene& scene) override {
    const std::vector<double> key = {scene.camera.eye.x, scene.camera.eye.y, scene.camera.eye.z,
                                     scene.sun.direction.x, static_cast<double>(scene.width)};
    if (key != last_key || set_plants_calls != last_plants) ++renders;
    last_key = key;
    last_plants = set_plants_calls;
    return ViewImage{reinterpret_cast<ImTextureID>(static_cast<intptr_t>(1)), false, scene.width, scene.height};
  }
  void set_fog_cones(std::shared_ptr<const ConeSet> cones) override {
    ++fog_cones_calls;
    last_cones = std::move(cones);
  }
  void set_fog_maps(std::shared_ptr<const std::vector<SunDepthMap>> maps) override {
    ++fog_maps_calls;
    last_maps = std::move(maps);
  }
  const ViewStats& stats() const override { return stats_; }
  std::optional<std::string> write_image(const Scene&, const RenderOptions&, const std::string&) override {
    return std::string("no renderer in the headless tests");
  }
  ImTextureID make_texture(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) override {
    textures.push_back({width, height, rgba.size()});
    return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(100 + textures.size()));
  }
  void free_texture(ImTextureID) override { ++freed_textures; }
  struct Texture {
    uint32_t width, height;
    size_t bytes;
  };
  std::vector<Texture> textures;  // every make_texture, in order
  int freed_textures = 0;
  int set_plants_calls = 0, renders = 0, last_plants = -1, fog_cones_calls = 0, fog_maps_calls = 0;
  std::shared_ptr<const ConeSet> last_cones;
  std::shared_ptr<const std::vector<SunDepthMap>> last_maps;
  uint64_t segments = 0;
  double wood_m = 0;  // the plants' segment lengths summed, at the last set_plants
  std::vector<SkinStyle> skins;  // each plant's, as the last set_plants saw them
  std::vector<double> last_key;
  ViewStats stats_;
};

enum Key : int {
  kKeyTab = 258, kKeyLeft = 263, kKeyRight = 262, kKeyUp = 265, kKeyDown = 264, kKeyPageUp = 266,
  kKeyPageDown = 267, kKeyHome = 268, kKeyEnd = 269, kKeyInsert = 260, kKeyDelete = 261,
  kKeyBackspace = 259, kKeySpace = 32, kKeyEnter = 257, kKeyEscape = 256, kKeyPadEnter = 335,
};

class HeadlessUi {
 public:
  HeadlessUi() {
    IMGUI_CHECKVERSION();
    context_ = ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    io.DisplaySize = ImVec2(1280, 800);
    unsigned char* pixels = nullptr;
    int w = 0, h = 0;
    io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);
    io.Fonts->SetTexID(reinterpret_cast<ImTextureID>(static_cast<intptr_t>(2)));
    const int map[][2] = {{ImGuiKey_Tab, kKeyTab}, {ImGuiKey_LeftArrow, kKeyLeft}, {ImGuiKey_RightArrow, kKeyRight},
                          {ImGuiKey_UpArrow, kKeyUp}, {ImGuiKey_DownArrow, kKeyDown}, {ImGuiKey_PageUp, kKeyPageUp},
                          {ImGuiKey_PageDown, kKeyPageDown}, {ImGuiKey_Home, kKeyHome}, {ImGuiKey_End, kKeyEnd},
                          {ImGuiKey_Insert, kKeyInsert}, {ImGuiKey_Delete, kKeyDelete},
                          {ImGuiKey_Backspace, kKeyBackspace}, {ImGuiKey_Space, kKeySpace},
                          {ImGuiKey_Enter, kKeyEnter}, {ImGuiKey_Escape, kKeyEscape},
                          {ImGuiKey_KeyPadEnter, kKeyPadEnter}, {ImGuiKey_A, 'A'}, {ImGuiKey_C, 'C'},
                          {ImGuiKey_V, 'V'}, {ImGuiKey_X, 'X'}, {ImGuiKey_Y, -1}, {ImGuiKey_Z, -1}};
    for (const auto& m : map) io.KeyMap[m[0]] = m[1];
  }
  ~HeadlessUi() { ImGui::DestroyContext(context_); }
  HeadlessUi(const HeadlessUi&) = delete;
  HeadlessUi& operator=(const HeadlessUi&) = delete;

  double now() const { return now_; }
  void advance(double seconds) { now_ += seconds; }

  // One frame: input as it is now, 1/60 s later than the last.
  void frame(StudioApp& app) {
    ImGuiIO& io = ImGui::GetIO();
    io.DeltaTime = 1.0f / 60;
    now_ += 1.0 / 60;
    ImGui::NewFrame();
    app.frame(now_);
    ImGui::Render();
    io.MouseWheel = 0;
  }
  void frames(StudioApp& app, int n) {
    for (int i = 0; i < n; ++i) frame(app);
  }
  void move(StudioApp& app, ImVec2 p) {
    ImGui::GetIO().MousePos = p;
    frame(app);
  }
  void click(StudioApp& app, ImVec2 p, int button = 0) {
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = p;
    frame(app);
    io.MouseDown[button] = true;
    frame(app);
    io.MouseDown[button] = false;
    frame(app);
  }
  // Press and release `key` with the given modifiers.
  void key(StudioApp& app, int key, bool ctrl = false, bool shift = false) {
    ImGuiIO& io = ImGui::GetIO();
    io.KeyCtrl = ctrl;
    io.KeyShift = shift;
    io.KeysDown[key] = true;
    frame(app);
    io.KeysDown[key] = false;
    frame(app);
    io.KeyCtrl = io.KeyShift = false;
    frame(app);
  }
  void type(StudioApp& app, const std::string& text) {
    for (char c : text) {
      ImGui::GetIO().AddInputCharacter(static_cast<unsigned char>(c));
      frame(app);
    }
  }
  // Frames (with the worker running for real) until `done` or `timeout_s` of wall time: a
  // hang guard, far above the second or two the worker takes on an idle machine.
  bool until(StudioApp& app, const std::function<bool()>& done, double timeout_s = 300) {
    const auto start = std::chrono::steady_clock::now();
    while (!done()) {
      if (std::chrono::steady_clock::now() - start > std::chrono::duration<double>(timeout_s)) return false;
      frame(app);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }
  // Drags the viewport 50 pixels to the right with the left button (an orbit); false when
  // the app drew no viewport.
  bool orbit(StudioApp& app) {
    auto view = app.rect("viewport");
    if (!view) return false;
    ImGuiIO& io = ImGui::GetIO();
    io.MousePos = view->centre();
    frame(app);
    io.MouseDown[0] = true;
    for (int i = 0; i < 5; ++i) io.MousePos.x += 10, frame(app);
    io.MouseDown[0] = false;
    frames(app, 2);
    return true;
  }
  // Until the worker is idle and its result is on screen.
  bool settle(StudioApp& app, double timeout_s = 300) {
    return until(app, [&] { return !app.worker().busy() && !app.worker().result_waiting(); }, timeout_s) &&
           (frames(app, 3), true);
  }

 private:
  ImGuiContext* context_;
  double now_ = 1000;
};

// A fresh folder under the test temp dir, removed afterwards.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() / ("sylva_studio_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace sylva::studio::test
