// studio_app.h — the studio's window contents and behaviour (docs/spec/studio.md),
// independent of GLFW and of GL: one call per frame between ImGui::NewFrame() and
// ImGui::Render() builds every widget from the app's state, and the app reacts to what
// the user did. The window (studio_main.cpp) and the headless tests (tests/studio/) drive
// the same object; the plants are drawn by a Viewport (viewport.h), which the tests fake.
//
// What happens where:
//   editor text ── debounce ──► GrowWorker (parse, derive, interpret, skeleton) ──► poll()
//   parameters ── continuous or on release ──►    "        (the ladder's top rung)
//   skin / bark / relief options ──► Viewport::set_plants (re-skin, re-upload)
//   camera / sun / size / fog medium ──► Viewport::image (re-render only)
//   plants / sun / photons (a fog cone mode) ──► ConeWorker ──► Viewport::set_fog_cones
// A parse or derivation error leaves the last good plant on screen and marks the text.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <imgui.h>

#include "app/studio/code_editor.h"
#include "app/studio/cone_worker.h"
#include "app/studio/define_controls.h"
#include "app/studio/document_files.h"
#include "app/studio/grow_worker.h"
#include "app/studio/light_overlay.h"
#include "app/studio/orbit_camera.h"
#include "app/studio/preset_catalog.h"
#include "app/studio/undo_history.h"
#include "app/studio/viewport.h"
#include "core/grow/grow.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "core/util/diagnostic.h"

namespace sylva::studio {

struct StudioOptions {
  std::string presets_dir;        // the preset browser's folder
  std::string thumbnail_cache;    // where the browser keeps its thumbnails (preset_catalog.h);
                                  //   empty: the browser shows none (the headless tests)
  double debounce_s = 0.15;       // a pause in typing before the text is grown again
  double snapshot_s = 0.8;        // a pause in typing before an undo step is taken
  double autosave_s = 3;          // how often an edited document is autosaved
  double watch_s = 0.5;           // how often the file on disk is checked for changes
  uint64_t max_modules = 50'000'000;
  std::optional<SkinStyle> skin;  // --skin: every plant's, over the scene's keys (the view's
                                  //   skin control starts here; none: the scene's)
};

// The fog "add fog" makes (issue 31 §5: Fog{}'s 0.05 /m washed out a single tree seen from
// 20 m): Fog{}'s, with its extinction scaled so that the light from the camera's target
// keeps exp(-kAddedFogOpticalDepth) of itself (0.78): shafts show, the plant stays.
constexpr double kAddedFogOpticalDepth = 0.25;
Fog fog_for_view(const Camera& camera);

// Where the tests click: screen rectangles of named widgets from the last frame.
struct WidgetRect {
  ImVec2 min{0, 0}, max{0, 0};
  ImVec2 centre() const { return ImVec2((min.x + max.x) * 0.5f, (min.y + max.y) * 0.5f); }
};

// The preset browser's thumbnails, in pixels.
inline constexpr uint32_t kThumbnailWidth = 96, kThumbnailHeight = 72;

class StudioApp {
 public:
  StudioApp(StudioOptions options, Viewport* viewport);
  ~StudioApp();
  StudioApp(const StudioApp&) = delete;
  StudioApp& operator=(const StudioApp&) = delete;

  // Opens a .lsys grammar or a .scene.json scene (its plants grow; the editor shows the
  // first plant's grammar). Returns the error text, changing nothing, when it cannot.
  // An autosave that differs from the file is offered for restoring (document_files.h).
  std::optional<std::string> open(const std::string& path);
  // One frame of widgets at time `now` (seconds, any origin, increasing).
  void frame(double now);
  // Writes an edited document's autosave now, whatever the timer (SIGTERM, SIGHUP: the
  // studio keeps the buffer as vim and nano do). Returns the error text when it cannot.
  std::optional<std::string> autosave_now();

  std::string title() const;  // "sylva studio — elm.lsys*"
  bool dirty() const;         // the text differs from the file's
  // The window asks to close: true if it may close now; otherwise the app asks the user
  // (save / don't save / cancel) and quit_requested() turns true when they answer so.
  bool request_close();
  bool quit_requested() const { return quit_; }
  // Whether the next frame should come at once rather than on the next input event: the
  // worker runs or has a result, a timer (debounce, undo step) is pending, an animation
  // or a camera drag is on.
  bool wants_frames() const;
  std::optional<std::string> save();                        // to the document's path
  std::optional<std::string> save_as(const std::string& path);
  // Writes the scene as the viewport shows it — its plants (the edited ones naming the
  // document's grammar, with the parameter controls' values as their defines), the orbit
  // camera, the sun control's direction, the rest as opened — through the scene writer
  // (write_scene_json: paths relative to the scene's folder), atomically. An empty path:
  // the scene the document came with. A grammar opened alone makes a new scene with its
  // one plant. Returns the error text, writing nothing, when it cannot (an untitled
  // grammar, a folder that is not there).
  std::optional<std::string> save_scene(const std::string& path = "");

  // State, for the window's --screenshot and for tests.
  const std::string& text() const { return text_; }
  const std::string& path() const { return path_; }
  const std::optional<Diagnostic>& error() const { return error_; }
  const std::optional<GrowOutcome>& plant() const { return plant_; }  // the last good plant
  uint64_t plants_applied() const { return plants_applied_; }        // results put on screen
  bool plant_drawn() const { return drawn_version_ == plants_applied_ && plants_applied_ > 0; }
  // The light queries drawn over the picture at the last frame (the Light panel's "colour
  // queries by q"; empty while it is off).
  const std::vector<QueryDot>& query_dots() const { return query_dots_; }
  GrowWorker& worker() { return *worker_; }
  const ConeWorker& cone_worker() const { return *cones_; }
  uint64_t cone_requests() const { return cone_requests_; }  // cone builds asked of the cone worker
  CodeEditor& editor() { return editor_; }
  const UndoHistory& history() const { return history_; }
  const std::map<std::string, double>& overrides() const { return overrides_; }
  const Scene& scene() const { return scene_; }
  const OrbitCamera& camera() const { return orbit_; }
  bool restore_offered() const { return restore_.has_value(); }
  bool close_prompt_open() const { return close_prompt_; }
  bool external_change_prompt_open() const { return external_prompt_; }
  const std::string& status() const { return status_; }
  // Edit-to-picture latencies (submit to the first frame showing the result), seconds.
  const std::vector<double>& latencies() const { return latencies_; }
  std::optional<WidgetRect> rect(const std::string& name) const;
  bool continuous() const { return continuous_; }

  // Actions the menus and shortcuts call (also for tests).
  void undo();
  void redo();
  void write_parameters_to_text();
  // What releasing a define's slider at `value` does: override, undo step, regrow.
  void set_define(const std::string& name, double value);
  void step();     // one more derivation step
  void run();      // to the derivation length
  void rewind();   // back to the axiom
  // A Ctrl chord (`key`: 'Z', 'Y', 'F', 'G', 'S', 'O') from the window's key callback,
  // handled at the next frame. Once one has come this way, chords are taken only from
  // here: a press and release between two frames (a short chord at a low frame rate)
  // never reaches ImGui's polled key state, and was lost (issue 31 §5).
  void queue_chord(int key, bool shift) { chords_.push_back({key, shift}), chords_from_callbacks_ = true; }
  void animate();  // from the axiom, animate_speed() steps a second (as fast as they grow, at most)
  double animate_speed() const { return animate_steps_per_s_; }
  void set_animate_speed(double steps_per_s) { animate_steps_per_s_ = std::clamp(steps_per_s, 0.25, 60.0); }
  // Animate's substeps (issue 31 §3, docs/animation.md): each step shown as K pictures, the
  // plant growing from the last step's into the new one (core/grow/growth_tween.h, what
  // `render --frames all --substeps K` draws), the step still taking 1 / animate_speed()
  // seconds. 1 (the default): steps as they come.
  int animate_substeps() const { return animate_substeps_; }
  bool animating() const { return animating_; }
  void set_animate_substeps(int k) { animate_substeps_ = std::clamp(k, 1, 16); }
  void frame_plant();
  // What the glTF export dialog asks (docs/gltf.md): the mesh, the wind rig and clip (the
  // scene's `animation` key, or the default sway), per-vertex wind data.
  struct GltfChoice {
    bool mesh = true;
    bool rig = false;
    int max_joints = 128;
    bool animation = false;
    bool wind_data = false;
    int lod = 0;  // levels of detail beyond LOD0, the last impostor cards (0: none)
    bool meshopt = false;  // EXT_meshopt_compression (then required)
  };
  std::optional<std::string> export_gltf_file(const std::string& path, const GltfChoice& choice);
  std::optional<std::string> export_skeleton_file(const std::string& path);
  std::optional<std::string> export_png_file(const std::string& path, uint32_t width, uint32_t height);

 private:
  enum class FileDialog { none, open, save_as, export_gltf, export_png, export_skeleton, save_scene_as };

  void load_text(const std::string& path, std::string text, const std::string& scene_path, Scene scene,
                 std::string object_folder = "");
  // The document's define lines, found again in the text; a vlab object's panel sliders give
  // the ranges the text's own range comments do not.
  void rescan_defines();
  // What a scene's plant names for the document: a vlab object's folder, else the grammar file.
  const std::string& plant_grammar() const { return object_folder_.empty() ? path_ : object_folder_; }
  void submit_regrow();
  void apply_outcome(GrowOutcome outcome);
  void set_text(std::string text);  // from undo/reload/write-to-text: editor follows
  DocState doc_state() const;
  void apply_state(const DocState& s);
  void snapshot();
  void poll_worker();
  void handle_shortcuts();
  void autosave(double now);
  void watch_file(double now);
  void draw_menu();
  void draw_editor(ImVec2 size);
  void draw_message_bar();
  void draw_viewport(ImVec2 size);
  void draw_parameters();
  void draw_derivation();
  void handle_chord(int key, bool shift);  // a Ctrl chord: undo, redo, find, go to, save, open
  std::string message_text() const;             // the error's first line, or ""
  float message_bar_height(float width) const;  // the bar below the editor, wrapped to `width`
  void draw_view();
  void draw_fog();
  void draw_light();
  void update_cones();  // the fog's cones for the plants and sun on screen (cone_worker.h)
  void draw_presets();
  void take_thumbnails();
  void draw_modals();
  void draw_file_dialog();
  void keep(const std::string& name);  // records the last item's rect under `name`
  Scene view_scene() const;            // scene_ with the view's bark and skin controls applied
  std::optional<SkinStyle> skin_override() const;  // the skin control's, none for "scene's"
  void plants_changed();               // skin/bark/relief options or new plants → set_plants
  std::string display_name() const;

  StudioOptions options_;
  Viewport* viewport_;
  std::unique_ptr<GrowWorker> worker_;
  std::unique_ptr<ConeWorker> cones_;
  std::vector<double> cone_key_;  // what the last cone request was built for
  uint64_t cone_requests_ = 0;
  CodeEditor editor_;
  UndoHistory history_;

  // The document.
  std::string path_;                 // the grammar file; empty: untitled
  std::string scene_path_;           // the scene it came with, if any
  std::string object_folder_;        // a vlab object's folder when path_ is its model (docs/cpfg.md)
  std::vector<lsys::PanelSlider> panel_;  // that object's panel.l sliders
  std::string text_;
  std::string saved_text_;           // the text as on disk
  FileStamp disk_stamp_;
  std::vector<DefineLine> define_lines_;
  std::map<std::string, double> overrides_;
  std::optional<uint64_t> seed_;
  std::optional<int64_t> steps_;
  std::optional<int64_t> show_step_;
  bool continuous_ = true;

  // The plants.
  Scene scene_;                      // camera, sun, ...; plants with their skeletons
  std::vector<size_t> edited_plants_;  // indices of scene_'s plants grown from the text
  std::optional<GrowOutcome> plant_;
  std::optional<Diagnostic> error_;
  uint64_t plants_applied_ = 0, drawn_version_ = 0;
  std::optional<std::chrono::steady_clock::time_point> latency_start_;
  std::vector<double> latencies_;
  bool animating_ = false;
  struct Chord {
    int key;
    bool shift;
  };
  std::vector<Chord> chords_;          // queue_chord's, not yet handled
  bool chords_from_callbacks_ = false;
  float animate_steps_per_s_ = 4;    // the Animate speed control
  int animate_substeps_ = 1;         // the Animate substeps control
  double animate_stepped_at_ = 0;    // now_ when the animation last took a step (or substep)
  // A step being shown in substeps: the edited plants' skeletons of the step before and
  // of the new one, and how many of the K pictures were put on screen.
  struct Tween {
    std::vector<Skeleton> before, after;
    int shown = 0;
  };
  std::optional<Tween> tween_;
  void show_tween();  // the edited plants at tween_'s current substep, to the viewport
  bool camera_set_ = false;
  OrbitCamera orbit_;
  RenderOptions render_options_;
  bool bark_ = true;
  bool show_queries_ = false;         // the Light panel's "colour queries by q"
  std::vector<QueryDot> query_dots_;  // drawn at the last frame
  // What query_dots_ were projected for: the camera, the image's place and size on the
  // screen, the sensor radius and the plant (plants_applied_; 0: none yet).
  struct QueryDotsKey {
    Camera camera;
    float x = 0, y = 0, width = 0, height = 0;
    double radius = 0;
    uint64_t plants = 0;
    bool operator==(const QueryDotsKey&) const = default;
  };
  QueryDotsKey query_dots_key_;
  int skin_choice_ = 0;              // the view's skin control: 0 the scene's, 1 smooth, 2 paper
  float sun_azimuth_deg_ = 0, sun_elevation_deg_ = 45;
  bool view_half_res_ = false;

  // Time.
  double now_ = 0;
  std::optional<double> edited_at_;    // text changed, regrow not yet submitted
  std::optional<double> unsnapped_at_; // text changed, undo step not yet taken
  double last_autosave_ = 0, last_watch_ = 0;
  std::string autosaved_text_;

  // Prompts and dialogs.
  std::optional<Autosave> restore_;
  bool close_prompt_ = false;
  std::optional<std::string> open_after_prompt_;  // a file to open once the prompt is answered
  bool external_prompt_ = false;
  bool quit_ = false;
  FileDialog dialog_ = FileDialog::none;
  std::string dialog_path_;
  int export_width_ = 1920, export_height_ = 1080;
  GltfChoice export_gltf_;
  bool show_presets_ = false;
  std::optional<std::vector<PresetEntry>> presets_;  // listed when the browser first opens
  std::unique_ptr<ThumbnailWorker> thumbnails_;
  std::map<std::string, ImTextureID> thumbnail_textures_;  // by preset path
  std::map<std::string, std::string> thumbnail_errors_;    // by preset path
  std::string status_;
  std::map<std::string, WidgetRect> rects_;
  std::map<std::string, std::string> field_text_;  // typed fields being edited
};

}  // namespace sylva::studio
