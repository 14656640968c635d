// studio_main.cpp — `sylva studio [INPUT] [--screenshot OUT.png [--frames N]] [--size WxH]`
// (docs/spec/studio.md): the GLFW window with an OpenGL 4.5 core context, Dear
// ImGui's GLFW and OpenGL 3 backends (inside Debian's libimgui.a), the StudioApp and the
// GL viewport, and the loop that drives them.
//
// Under Xvfb (llvmpipe) the front buffer cannot be read back, so --screenshot reads the
// back buffer after ImGui has drawn it and before the swap.
// OpenGL from gl_api.h (the core prototypes); GLFW must not include its own GL header.
#include "core/gl/gl_api.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <signal.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <memory>
#include <thread>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include "app/front/args.h"
#include "app/studio/cpu_viewport.h"
#include "app/studio/gl_viewport.h"
#include "app/studio/studio.h"
#include "app/studio/studio_app.h"
#include "core/gl/gl_context.h"
#include "core/util/image_io.h"

namespace sylva::studio {

namespace {

void print_help() {
  std::cout << "usage: sylva studio [INPUT] [--size WxH] [--skin smooth|paper] [--backend auto|gl|cpu]\n"
               "                    [--screenshot OUT.png [--frames N]]\n\n"
               "Opens the studio: edit a grammar and watch the plant regrow. INPUT is a .lsys grammar\n"
               "or a .scene.json scene (the editor shows its first plant's grammar); without one, the\n"
               "preset browser opens. Needs a display (on a machine without one: xvfb-run -a sylva studio ...).\n\n"
               "  --size WxH          window size in pixels (default 1280x800)\n"
               "  --skin S            how chains meet, for every plant (over the scene's skin keys):\n"
               "                      smooth or paper (Bhagvat et al. 2009's mitred chains); the view's\n"
               "                      skin control starts there\n"
               "  --backend B         what draws the viewport: auto (default): OpenGL, but the CPU ray\n"
               "                      caster, drawn coarse to fine, where the window's GL is a software\n"
               "                      rasteriser (Mesa's llvmpipe: the CPU is several times faster);\n"
               "                      gl: OpenGL always; cpu: the CPU ray caster always\n"
               "  --screenshot FILE   grow the plant, draw N frames after it is on screen, write the\n"
               "                      window's pixels to FILE (PNG, atomically) and exit 0; exit 1 with\n"
               "                      the located error, writing nothing, if INPUT does not parse\n"
               "  --frames N          frames to draw before the screenshot (default 3)\n"
               "  -h, --help          show this help\n\n"
               "In the window: Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) undo and redo whole edits, Ctrl+F find,\n"
               "Ctrl+G go to line, Ctrl+S save; in the viewport left drag orbits, middle drag or\n"
               "Shift+left drag pans, the wheel zooms, F frames the plant.\n";
}

struct StudioArgs {
  std::string input;
  std::string screenshot;
  int frames = 3;
  int width = 1280, height = 800;
  bool help = false;
  std::optional<SkinStyle> skin;
  std::string backend = "auto";
};

StudioArgs parse_args(const std::vector<std::string>& args) {
  StudioArgs a;
  cli::FlagTable table;
  table.flags = {
      cli::help_flag(a.help),
      cli::text_flag({"--screenshot"}, a.screenshot),
      cli::skin_flag(a.skin),
      cli::value_flag({"--backend"},
                      [&a](const std::string&, const std::string& v) {
                        a.backend = v;
                        if (v != "auto" && v != "gl" && v != "cpu")
                          throw cli::UsageError{"--backend " + v + ": expected auto, gl or cpu"};
                      }),
      cli::value_flag({"--frames"},
                      [&a](const std::string&, const std::string& v) {
                        auto n = cli::parse_u64(v);
                        if (!n || *n > 10000)
                          throw cli::UsageError{"--frames " + v + ": expected an integer from 0 to 10000"};
                        a.frames = static_cast<int>(*n);
                      }),
      cli::value_flag({"--size"},
                      [&a](const std::string&, const std::string& v) {
                        const size_t x = v.find('x');
                        auto w = x == std::string::npos ? std::nullopt : cli::parse_u64(v.substr(0, x));
                        auto h = x == std::string::npos ? std::nullopt : cli::parse_u64(v.substr(x + 1));
                        if (!w || !h || *w < 64 || *h < 64 || *w > 16384 || *h > 16384)
                          throw cli::UsageError{"--size " + v + ": expected WxH, each from 64 to 16384"};
                        a.width = static_cast<int>(*w);
                        a.height = static_cast<int>(*h);
                      }),
  };
  table.positional = [&a](const std::string& input) {
    if (!a.input.empty()) throw cli::UsageError{"unexpected argument '" + input + "' (one INPUT only)"};
    a.input = input;
  };
  cli::parse_flags(args, table);
  if (!a.screenshot.empty() && a.input.empty()) throw cli::UsageError{"--screenshot needs an INPUT"};
  if (!a.screenshot.empty() && !can_write_image_format(a.screenshot))
    throw cli::UsageError{"--screenshot " + a.screenshot + ": OpenImageIO cannot write this format"};
  return a;
}

void on_glfw_error(int code, const char* message) { std::fprintf(stderr, "sylva studio: GLFW %d: %s\n", code, message); }

// The window's pixels, read from the back buffer (before the swap), top row first.
std::optional<std::string> write_screenshot(const std::string& path, int w, int h) {
  std::vector<uint8_t> px(static_cast<size_t>(w) * h * 4);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
  std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k)
        rgb[(static_cast<size_t>(y) * w + x) * 3 + k] = px[(static_cast<size_t>(h - 1 - y) * w + x) * 4 + k] / 255.0f;
  if (Status written = write_image_atomically(path, static_cast<uint32_t>(w), static_cast<uint32_t>(h), {"R", "G", "B"},
                                              rgb, {ChannelFormat::uint8}, true);
      !written) {
    std::string text = written.error().format();
    text.pop_back();  // the one line, without format()'s newline
    return text;
  }
  return std::nullopt;
}

// For the xdotool smoke test (SYLVA_STUDIO_TRACE=1): what happened, one line each.
void trace(const char* what, const std::string& detail) {
  static const bool on = std::getenv("SYLVA_STUDIO_TRACE") != nullptr;
  if (!on) return;
  std::printf("studio: %s %s\n", what, detail.c_str());
  std::fflush(stdout);
}

// SIGTERM, SIGHUP or SIGINT received while the window is open (0: none). The main loop,
// which wakes at least every 0.25 s, writes the autosave and ends the studio as the
// signal would (docs/spec/studio.md "never losing work"; vim and nano keep their buffers).
volatile std::sig_atomic_t g_stop_signal = 0;

// Ctrl chords from GLFW's key callback (StudioApp::queue_chord): a chord pressed and
// released between two frames is kept. ImGui's callback, installed first, is chained.
StudioApp* g_chord_app = nullptr;
GLFWkeyfun g_imgui_key_callback = nullptr;

void on_key(GLFWwindow* window, int key, int scancode, int action, int mods) {
  if (g_imgui_key_callback) g_imgui_key_callback(window, key, scancode, action, mods);
  if (g_chord_app && action == GLFW_PRESS && (mods & GLFW_MOD_CONTROL) && key >= 'A' && key <= 'Z')
    g_chord_app->queue_chord(key, (mods & GLFW_MOD_SHIFT) != 0);
}

void on_stop_signal(int signal) { g_stop_signal = signal; }

// Installs on_stop_signal for the three signals while it lives (replacing the `sylva`
// command's remove-the-temporaries handlers: the loop finishes any write first), then
// puts the previous handlers back.
class StopSignals {
 public:
  StopSignals() {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &action, &previous_[i]);
  }
  ~StopSignals() {
    for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &previous_[i], nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  static constexpr std::array<int, 3> kSignals{SIGTERM, SIGHUP, SIGINT};
  std::array<struct sigaction, 3> previous_{};
};

}  // namespace

int run_studio(const std::vector<std::string>& raw_args) {
  const StudioArgs a = parse_args(raw_args);
  if (a.help) {
    print_help();
    return cli::kOk;
  }
  // The window first: a grammar's errors come from the worker once the app runs (a
  // --screenshot of a grammar that does not parse then exits 1 with the located error).
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit()) {
    std::cerr << "sylva studio: error: cannot open a window (no display? on a machine without one run "
                 "'xvfb-run -a sylva studio ...')\n";
    return cli::kInputError;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* window = glfwCreateWindow(a.width, a.height, "sylva studio", nullptr, nullptr);
  if (!window) {
    std::cerr << "sylva studio: error: cannot create an OpenGL 4.5 core window\n";
    glfwTerminate();
    return cli::kInputError;
  }
  glfwSetWindowPos(window, 0, 0);
  glfwMakeContextCurrent(window);
  glfwSwapInterval(a.screenshot.empty() ? 1 : 0);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 450");
  // Whole-document undo (undo_history.h): the text widget must not undo by itself.
  io.KeyMap[ImGuiKey_Z] = -1;
  io.KeyMap[ImGuiKey_Y] = -1;

  int code = cli::kOk;
  {
    // --backend auto: the CPU ray caster where the window's GL is a software rasteriser.
    std::unique_ptr<Viewport> viewport_ptr;
    const char* gl_renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const bool software = gl_renderer && is_software_renderer(gl_renderer);
    if (a.backend == "cpu" || (a.backend == "auto" && software)) {
      const std::string why = a.backend == "cpu" ? "--backend cpu"
                                                 : std::string(gl_renderer) + " is a software rasteriser; --backend gl forces it";
      // A screenshot waits for the finest picture, however long it takes.
      viewport_ptr = std::make_unique<CpuViewport>([] { glfwPostEmptyEvent(); }, why,
                                                   a.screenshot.empty() ? 1500.0 : std::numeric_limits<double>::infinity());
    } else {
      try {
        viewport_ptr = std::make_unique<GlViewport>([] { glfwPostEmptyEvent(); });
      } catch (const std::exception& e) {
        std::cerr << "sylva studio: error: " << e.what() << "\n";
        code = cli::kInputError;
      }
    }
    StudioOptions options;
    const char* presets = std::getenv("SYLVA_PRESETS");
    options.presets_dir = presets ? presets : SYLVA_PRESETS_DIR;
    // The preset browser's thumbnails: rendered once, kept in the user's cache folder.
    if (const char* cache = std::getenv("XDG_CACHE_HOME"); cache && *cache)
      options.thumbnail_cache = std::string(cache) + "/sylva/thumbnails";
    else if (const char* home = std::getenv("HOME"); home && *home)
      options.thumbnail_cache = std::string(home) + "/.cache/sylva/thumbnails";
    options.skin = a.skin;
    StudioApp app(options, viewport_ptr.get());
    app.worker().on_result([] { glfwPostEmptyEvent(); });
    g_chord_app = &app;
    g_imgui_key_callback = glfwSetKeyCallback(window, on_key);
    if (code == cli::kOk && !a.input.empty())
      if (auto err = app.open(a.input)) {
        std::cerr << *err << (err->empty() || err->back() != '\n' ? "\n" : "");
        code = cli::kInputError;
      }
    const auto start = std::chrono::steady_clock::now();
    int frames_after_plant = -1;
    uint64_t traced_plants = 0;
    std::string traced_error, title;
    const StopSignals stop_signals;
    while (code == cli::kOk) {
      // Sleep until input, a worker result (glfwPostEmptyEvent) or a timer tick, unless
      // something is in motion.
      if (!a.screenshot.empty() || app.wants_frames()) glfwPollEvents();
      else glfwWaitEventsTimeout(0.25);
      if (const int signal = g_stop_signal) {
        // Killed (SIGTERM, SIGHUP, SIGINT): keep the edits in the autosave first.
        if (auto err = app.autosave_now()) std::cerr << "sylva studio: error: autosave: " << *err << "\n";
        code = 128 + signal;
        break;
      }
      if (glfwWindowShouldClose(window)) {
        glfwSetWindowShouldClose(window, GLFW_FALSE);
        app.request_close();
      }
      if (app.quit_requested()) break;
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      app.frame(glfwGetTime());
      ImGui::Render();
      int fw = 0, fh = 0;
      glfwGetFramebufferSize(window, &fw, &fh);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      glViewport(0, 0, fw, fh);
      glClearColor(0.1f, 0.1f, 0.12f, 1);
      glClear(GL_COLOR_BUFFER_BIT);
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (app.title() != title) glfwSetWindowTitle(window, (title = app.title()).c_str());

      if (app.plants_applied() != traced_plants && app.plant_drawn()) {
        traced_plants = app.plants_applied();
        trace("plant", std::to_string(app.plant()->segments) + " segments");
        const ImVec2 o = app.editor().text_origin();  // where line 1's text starts
        trace("editor", std::to_string(o.x) + " " + std::to_string(o.y) + " " +
                            std::to_string(app.editor().line_height()));
      }
      const std::string err_line = app.error() ? app.error()->format().substr(0, app.error()->format().find('\n')) : "";
      if (err_line != traced_error) trace("error", traced_error = err_line);

      if (!a.screenshot.empty()) {
        if (app.error() && !app.plant() && !app.worker().busy()) {
          std::cerr << app.error()->format();
          code = cli::kInputError;
          break;
        }
        // The finished picture: the plant drawn, and nothing finer on its way.
        if (app.plant_drawn() && !app.worker().busy() && !(viewport_ptr && viewport_ptr->busy())) ++frames_after_plant;
        if (frames_after_plant >= a.frames) {
          if (auto err = write_screenshot(a.screenshot, fw, fh)) {
            std::cerr << *err << "\n";
            code = cli::kInputError;
          }
          break;
        }
        if (std::chrono::steady_clock::now() - start > std::chrono::minutes(5)) {
          std::cerr << "sylva studio: error: the plant did not appear within 5 minutes\n";
          code = cli::kInternalError;
          break;
        }
      }
      glfwSwapBuffers(window);
    }
    glfwSetKeyCallback(window, g_imgui_key_callback);  // the app goes; ImGui's stays
    g_chord_app = nullptr;
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  if (const int signal = g_stop_signal) {
    // The buffer is saved: now end as the signal would have (exit status 128 + signal).
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
  return code;
}

}  // namespace sylva::studio
