// studio_app.cpp — see studio_app.h.
#include "app/studio/studio_app.h"

#include "app/front/impostor.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>

#include <glm/geometric.hpp>
#include <imgui_stdlib.h>

#include "core/grow/grow.h"
#include "core/grow/growth_tween.h"
#include "core/gl/render_gl.h"
#include "core/io/gltf.h"
#include "core/geometry/skeleton.h"
#include "core/scene/scene_json.h"
#include "core/util/file_io.h"
#include "core/util/math.h"
#include "app/front/light.h"

namespace sylva::studio {

namespace {

// A one-line Diagnostic (a file's error: no source line, no notes) as the status bar and
// the message box show it, without format()'s final newline.
std::string one_line(const Diagnostic& d) {
  std::string text = d.format();
  if (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

using Clock = std::chrono::steady_clock;

// The node name of a plant in glTF: the grammar's file name without its extension.
std::string stem(const std::string& path) {
  std::string name = base_name(path);
  if (name.ends_with(".lsys")) name.resize(name.size() - 5);
  return name.empty() ? "plant" : name;
}

// Bytes of the token at `column` (1-based) of `line` in `text`: a name or number, else 1.
uint32_t token_length(const std::string& text, uint32_t line, uint32_t column) {
  if (column == 0) return 0;
  size_t at = offset_of(text, line, column);
  size_t end = at;
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; };
  while (end < text.size() && word(text[end])) ++end;
  return static_cast<uint32_t>(std::max<size_t>(1, end - at));
}

}  // namespace

Fog fog_for_view(const Camera& camera) {
  Fog f;
  const double d = std::max(glm::length(camera.eye - camera.target), 0.1);
  const double sigma_t = kAddedFogOpticalDepth / d;
  f.sigma_s = std::clamp(sigma_t * 10 / 11, 1e-4, 0.5);  // the defaults' ratio: sigma_a = sigma_s / 10
  f.sigma_a = f.sigma_s / 10;
  return f;
}

namespace {

bool key_pressed(char key) { return ImGui::IsKeyPressed(static_cast<int>(key), false); }

std::optional<uint64_t> parse_u64_exact(const std::string& s) {
  uint64_t v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

}  // namespace

StudioApp::StudioApp(StudioOptions options, Viewport* viewport)
    : options_(std::move(options)),
      viewport_(viewport),
      worker_(std::make_unique<GrowWorker>()),
      cones_(std::make_unique<ConeWorker>()) {
  if (options_.skin) skin_choice_ = *options_.skin == SkinStyle::paper ? 2 : 1;
  show_presets_ = true;  // until a document is opened
  scene_ = Scene{};
  scene_.plants.assign(1, ScenePlant{});  // an untitled grammar: typing grows it
  edited_plants_.push_back(0);
  const glm::dvec3 d = glm::normalize(scene_.sun.direction);
  sun_azimuth_deg_ = static_cast<float>(std::atan2(d.x, d.z) / kRadPerDeg);
  sun_elevation_deg_ = static_cast<float>(std::asin(d.y) / kRadPerDeg);
}

StudioApp::~StudioApp() {
  thumbnails_.reset();
  if (viewport_)
    for (const auto& [path, texture] : thumbnail_textures_) viewport_->free_texture(texture);
}

std::string StudioApp::display_name() const { return path_.empty() ? "untitled" : base_name(path_); }

std::string StudioApp::title() const {
  return "sylva studio \xE2\x80\x94 " + display_name() + (dirty() ? "*" : "");
}

bool StudioApp::dirty() const { return text_ != saved_text_; }

bool StudioApp::wants_frames() const {
  return worker_->busy() || worker_->result_waiting() || cones_->busy() || edited_at_ || unsnapped_at_ || animating_ || tween_ ||
         view_half_res_ || latency_start_ || (viewport_ && viewport_->busy()) ||
         (show_presets_ && thumbnails_ && !thumbnails_->idle());
}

std::optional<WidgetRect> StudioApp::rect(const std::string& name) const {
  auto it = rects_.find(name);
  if (it == rects_.end()) return std::nullopt;
  return it->second;
}

void StudioApp::keep(const std::string& name) { rects_[name] = WidgetRect{ImGui::GetItemRectMin(), ImGui::GetItemRectMax()}; }

// ---- documents --------------------------------------------------------------------

namespace {
// The file the editor shows for a grammar path, and its text: the file itself, or for a vlab
// object folder the model its specifications name (its view file, functions, environment,
// colours and panel come with it when it grows: docs/cpfg.md).
Expected<std::pair<std::string, std::string>> grammar_document(const std::string& grammar) {
  Expected<std::string> file =
      std::filesystem::is_directory(grammar) ? lsys::vlab_model_file(grammar) : Expected<std::string>(grammar);
  if (!file) return std::move(file.error());
  Expected<std::string> text = read_text_file(*file);
  if (!text) return std::move(text.error());
  return std::pair<std::string, std::string>{*file, std::move(*text)};
}
}  // namespace

std::optional<std::string> StudioApp::open(const std::string& path) {
  if (path.ends_with(".scene.json")) {
    Expected<Scene> read = read_scene_file(path);
    if (!read) return one_line(read.error());
    Scene scene = std::move(*read);
    // The editor shows the first plant's grammar; plants from other grammars (or ready
    // skeletons) grow once, here.
    std::string grammar;
    for (const ScenePlant& p : scene.plants)
      if (!p.grammar.empty() && !p.skeleton) {
        grammar = p.grammar;
        break;
      }
    if (grammar.empty()) return path + ": error: the scene has no plant grown from a grammar to edit";
    const bool object = std::filesystem::is_directory(grammar);
    Scene others = scene;
    for (ScenePlant& p : others.plants)
      if (p.grammar == grammar) p.skeleton = Skeleton{};  // not grown here
    // A plant's grammar error: the grammar's place, and a note at the scene key naming it.
    if (Status grown = grow_scene_plants(others, options_.max_modules, {}, &cpu_light_oracle()); !grown) return grown.error().format();
    for (size_t i = 0; i < scene.plants.size(); ++i)
      if (scene.plants[i].grammar != grammar) scene.plants[i].skeleton = std::move(others.plants[i].skeleton);
    auto document = grammar_document(grammar);
    if (!document) return one_line(document.error());
    load_text(document->first, std::move(document->second), path, std::move(scene), object ? grammar : "");
    return std::nullopt;
  }
  auto document = grammar_document(path);
  if (!document) return one_line(document.error());
  load_text(document->first, std::move(document->second), "", Scene{},
            std::filesystem::is_directory(path) ? path : "");
  return std::nullopt;
}

void StudioApp::rescan_defines() {
  define_lines_ = scan_defines(text_);
  for (DefineLine& d : define_lines_) {
    if (d.has_range()) continue;
    for (const lsys::PanelSlider& p : panel_)
      if (p.define == d.name) {
        d.min = p.min;
        d.max = p.max;
        d.step = p.step;
      }
  }
}

void StudioApp::load_text(const std::string& path, std::string text, const std::string& scene_path, Scene scene,
                          std::string object_folder) {
  worker_->cancel();
  path_ = path;
  scene_path_ = scene_path;
  object_folder_ = std::move(object_folder);
  panel_.clear();
  if (!object_folder_.empty()) {
    // vlab's panel manager reads panel.l beside the model; without one, no sliders from it.
    if (Expected<std::string> panel = read_text_file((std::filesystem::path(object_folder_) / "panel.l").string());
        panel)
      panel_ = lsys::read_panel_sliders(*panel);
  }
  saved_text_ = text;
  text_ = std::move(text);
  editor_.replace(text_);
  disk_stamp_ = stamp_of(path_);
  autosaved_text_ = text_;
  rescan_defines();
  overrides_.clear();
  seed_.reset();
  steps_.reset();
  show_step_.reset();
  animating_ = false;
  edited_at_.reset();
  unsnapped_at_.reset();
  error_.reset();
  plant_.reset();
  camera_set_ = false;
  scene_ = std::move(scene);
  edited_plants_.clear();
  if (scene_path_.empty()) {
    scene_.plants.assign(1, ScenePlant{});
    scene_.plants[0].grammar = plant_grammar();
    edited_plants_.push_back(0);
  } else {
    for (size_t i = 0; i < scene_.plants.size(); ++i)
      if (scene_.plants[i].grammar == plant_grammar()) edited_plants_.push_back(i);
  }
  history_.reset(doc_state());
  restore_ = path_.empty() ? std::nullopt : restorable_autosave(path_, saved_text_);
  show_presets_ = false;
  status_ = "opened " + base_name(scene_path_.empty() ? path_ : scene_path_);
  submit_regrow();
}

std::optional<std::string> StudioApp::save() {
  if (path_.empty()) {
    dialog_ = FileDialog::save_as;
    dialog_path_ = "untitled.lsys";
    return std::nullopt;
  }
  // Through a symbolic link to the real document (the link stays a link).
  if (Status written = write_file_atomically(save_target(path_), text_); !written) {
    status_ = one_line(written.error());
    return status_;
  }
  saved_text_ = text_;
  disk_stamp_ = stamp_of(path_);
  remove_autosave(path_);
  autosaved_text_ = text_;
  status_ = "saved " + path_;
  return std::nullopt;
}

std::optional<std::string> StudioApp::save_as(const std::string& path) {
  if (path.empty()) return std::string("no file name");
  const std::string old = path_;
  path_ = path;
  if (auto err = save()) {
    path_ = old;
    return err;
  }
  if (!old.empty() && old != path_) remove_autosave(old);
  // Saved elsewhere, a vlab object's model is a cpfg file of its own: its object's
  // specifications still name the old file, so its view file no longer applies.
  if (old != path_ && !object_folder_.empty()) {
    object_folder_.clear();
    panel_.clear();
    rescan_defines();
    submit_regrow();
  }
  for (size_t i : edited_plants_) scene_.plants[i].grammar = path_;
  return std::nullopt;
}

std::optional<std::string> StudioApp::save_scene(const std::string& path) {
  const std::string target = path.empty() ? scene_path_ : path;
  if (target.empty()) return std::string("no scene file name");
  if (path_.empty()) return std::string("save the grammar first: a scene names its grammar's file");
  Scene s = scene_;
  s.camera = orbit_.camera();
  s.sun.direction = unit_sun_direction(scene_.sun.direction);
  for (ScenePlant& p : s.plants) p.skeleton.reset();  // plants are named, never embedded
  for (size_t i : edited_plants_) {
    s.plants[i].grammar = plant_grammar();
    for (const auto& [name, value] : overrides_) s.plants[i].defines[name] = value;
    if (seed_) s.plants[i].seed = *seed_;
    if (steps_) s.plants[i].steps = *steps_;
  }
  const std::string folder = std::filesystem::path(target).parent_path().string();
  Expected<std::string> json = write_scene_json(s, folder);
  if (!json) return one_line(json.error());
  if (Status written = write_file_atomically(target, *json); !written) return one_line(written.error());
  scene_path_ = target;
  status_ = "saved " + target;
  return std::nullopt;
}

bool StudioApp::request_close() {
  if (!dirty()) {
    quit_ = true;
    return true;
  }
  close_prompt_ = true;
  return false;
}

// ---- regrowing --------------------------------------------------------------------

DocState StudioApp::doc_state() const { return DocState{text_, overrides_, seed_, steps_}; }

void StudioApp::snapshot() {
  history_.record(doc_state());
  unsnapped_at_.reset();
}

void StudioApp::apply_state(const DocState& s) {
  // The cursor goes to the edit undone or redone (issue 31 §5: it went to the file's end).
  if (s.text != text_) {
    uint32_t line = 1, column = 1;
    line_column(s.text.data(), s.text.size(), changed_until(text_, s.text), &line, &column);
    editor_.jump_to(line, column);
  }
  set_text(s.text);
  overrides_ = s.defines;
  seed_ = s.seed;
  steps_ = s.steps;
  field_text_.clear();
  submit_regrow();
}

void StudioApp::undo() {
  if (doc_state() != history_.current()) snapshot();  // what was typed since is a step too
  if (history_.can_undo()) apply_state(history_.undo());
}

void StudioApp::redo() {
  if (doc_state() != history_.current()) snapshot();
  if (history_.can_redo()) apply_state(history_.redo());
}

void StudioApp::set_text(std::string text) {
  if (text == text_) return;
  text_ = std::move(text);
  editor_.replace(text_);
  rescan_defines();
  edited_at_.reset();
}

void StudioApp::submit_regrow() {
  edited_at_.reset();
  // Overrides of defines the text no longer has would fail the parse: drop them.
  for (auto it = overrides_.begin(); it != overrides_.end();) {
    const bool known = std::any_of(define_lines_.begin(), define_lines_.end(),
                                   [&](const DefineLine& d) { return d.name == it->first; });
    it = known ? std::next(it) : overrides_.erase(it);
  }
  GrowRequest r;
  r.text = text_;
  r.file = path_.empty() ? "untitled.lsys" : path_;
  r.object_folder = object_folder_;
  r.max_modules = options_.max_modules;
  r.show_step = show_step_;
  for (size_t i : edited_plants_) {
    const ScenePlant& p = scene_.plants[i];
    PlantVariant v;
    v.defines = p.defines;
    for (const auto& [k, x] : overrides_) v.defines[k] = x;
    v.seed = seed_ ? seed_ : p.seed;
    v.steps = steps_ ? steps_ : p.steps;
    r.plants.push_back(std::move(v));
  }
  if (r.plants.empty()) return;
  // The light ?E queries are answered in: the scene's sun, ground and environment.
  r.light.sun = scene_.sun;
  r.light.ground = scene_.ground;
  r.light.environment = scene_.environment;
  latency_start_ = Clock::now();
  worker_->submit(std::move(r));
}

Scene StudioApp::view_scene() const {
  Scene s = scene_;
  if (!bark_)
    for (ScenePlant& p : s.plants) p.bark = Bark{};
  if (auto style = skin_override()) override_skin(s, *style);
  return s;
}

std::optional<SkinStyle> StudioApp::skin_override() const {
  if (skin_choice_ == 0) return std::nullopt;
  return skin_choice_ == 2 ? SkinStyle::paper : SkinStyle::smooth;
}

void StudioApp::plants_changed() {
  if (!viewport_ || !plant_) return;
  viewport_->set_plants(view_scene(), render_options_);
}

void StudioApp::apply_outcome(GrowOutcome outcome) {
  if (outcome.error) {
    error_ = std::move(outcome.error);
    animating_ = false;
    return;
  }
  error_.reset();
  // Animate with substeps: the next step grows out of the one on screen.
  tween_.reset();
  if (animating_ && animate_substeps_ > 1 && plant_ && outcome.shown_step == plant_->shown_step + 1 &&
      outcome.skeletons.size() == edited_plants_.size()) {
    Tween t;
    for (size_t k = 0; k < edited_plants_.size(); ++k) {
      const std::optional<Skeleton>& old = scene_.plants[edited_plants_[k]].skeleton;
      if (!old) break;
      t.before.push_back(*old);
    }
    if (t.before.size() == edited_plants_.size()) {
      t.after = outcome.skeletons;
      tween_ = std::move(t);
    }
  }
  for (size_t k = 0; k < edited_plants_.size() && k < outcome.skeletons.size(); ++k)
    scene_.plants[edited_plants_[k]].skeleton = std::move(outcome.skeletons[k]);
  outcome.skeletons.clear();
  if (!camera_set_) {
    // A grammar's first plant: the default scene's framing (docs/spec/scene.md); a scene: its camera.
    if (scene_path_.empty()) {
      const Skeleton& sk = *scene_.plants[0].skeleton;
      Scene d = default_scene_for(sk, scene_.width, scene_.height);
      add_grammar_colours(outcome.colours, d.materials);  // a vlab object's colour map
      d.plants = std::move(scene_.plants);
      scene_ = std::move(d);
      const glm::dvec3 dir = glm::normalize(scene_.sun.direction);
      sun_azimuth_deg_ = static_cast<float>(std::atan2(dir.x, dir.z) / kRadPerDeg);
      sun_elevation_deg_ = static_cast<float>(std::asin(dir.y) / kRadPerDeg);
    }
    orbit_ = OrbitCamera::from(scene_.camera);
    camera_set_ = true;
  }
  plant_ = std::move(outcome);
  ++plants_applied_;
  if (tween_) {
    tween_->shown = 1;  // the first substep at once
    animate_stepped_at_ = now_;
    show_tween();
  } else {
    plants_changed();
  }
}

void StudioApp::show_tween() {
  const double alpha = static_cast<double>(tween_->shown) / animate_substeps_;
  for (size_t k = 0; k < edited_plants_.size(); ++k) {
    scene_.plants[edited_plants_[k]].skeleton =
        tween_->shown >= animate_substeps_ ? tween_->after[k] : tween_growth(tween_->before[k], tween_->after[k], alpha);
  }
  plants_changed();
}

void StudioApp::poll_worker() {
  if (auto outcome = worker_->poll()) {
    const auto submitted = outcome->submitted;
    const bool ok = !outcome->error;
    apply_outcome(std::move(*outcome));
    if (ok) latency_start_ = submitted;
    else latency_start_.reset();
  }
  // Substeps: each 1 / (speed · K) seconds the plant grows a K-th further into the step;
  // stopped (Stop, Step, an edit...) mid-step, it shows the whole step.
  if (tween_ && (!animating_ || now_ - animate_stepped_at_ >= 1.0 / (animate_steps_per_s_ * animate_substeps_))) {
    tween_->shown = animating_ ? tween_->shown + 1 : animate_substeps_;
    animate_stepped_at_ = now_;
    show_tween();
    if (tween_->shown >= animate_substeps_) tween_.reset();
  }
  const double step_s = 1.0 / (animate_steps_per_s_ * (animate_substeps_ > 1 ? animate_substeps_ : 1));
  if (animating_ && !tween_ && !worker_->busy() && plant_ && !error_) {
    if (plant_->shown_step >= plant_->steps) {
      animating_ = false;
    } else if (now_ - animate_stepped_at_ >= step_s) {
      animate_stepped_at_ = now_;
      show_step_ = plant_->shown_step + 1;
      submit_regrow();
    }
  }
}

void StudioApp::step() {
  animating_ = false;
  const int64_t at = plant_ ? plant_->shown_step : 0;
  const int64_t steps = plant_ ? plant_->steps : 0;
  if (at + 1 > steps) steps_ = at + 1;  // past the derivation length: derive further
  show_step_ = at + 1;
  submit_regrow();
}

void StudioApp::run() {
  animating_ = false;
  show_step_.reset();
  submit_regrow();
}

void StudioApp::rewind() {
  animating_ = false;
  show_step_ = 0;
  submit_regrow();
}

void StudioApp::animate() {
  show_step_ = 0;
  animating_ = true;
  animate_stepped_at_ = now_;
  submit_regrow();
}

void StudioApp::frame_plant() {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  bool any = false;
  for (const ScenePlant& p : scene_.plants) {
    if (!p.skeleton || p.skeleton->joints.empty()) continue;
    const SkeletonBounds b = skeleton_bounds(place_plant(p));
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
    any = true;
  }
  if (any) orbit_.frame(lo, hi, scene_.width, scene_.height);
}

void StudioApp::set_define(const std::string& name, double value) {
  overrides_[name] = value;
  field_text_.erase(name);
  snapshot();
  submit_regrow();
}

void StudioApp::write_parameters_to_text() {
  if (overrides_.empty()) return;
  std::string t = text_;
  // Replace from the last line up so earlier offsets stay valid.
  std::vector<DefineLine> lines = scan_defines(t);
  std::sort(lines.begin(), lines.end(), [](const DefineLine& a, const DefineLine& b) { return a.value_begin > b.value_begin; });
  for (const DefineLine& d : lines) {
    auto it = overrides_.find(d.name);
    if (it != overrides_.end()) t = with_define_value(t, d, it->second);
  }
  overrides_.clear();
  field_text_.clear();
  set_text(std::move(t));
  snapshot();
  submit_regrow();
}

// ---- files ------------------------------------------------------------------------

void StudioApp::autosave(double now) {
  if (now - last_autosave_ < options_.autosave_s) return;
  last_autosave_ = now;
  if (auto error = autosave_now()) status_ = "autosave: " + *error;
}

std::optional<std::string> StudioApp::autosave_now() {
  if (!dirty() || text_ == autosaved_text_) return std::nullopt;
  const std::string target = autosave_path(path_.empty() ? "untitled.lsys" : path_);
  if (Status written = write_file_atomically(target, text_); !written) return one_line(written.error());
  autosaved_text_ = text_;
  return std::nullopt;
}

void StudioApp::watch_file(double now) {
  if (path_.empty() || now - last_watch_ < options_.watch_s) return;
  last_watch_ = now;
  const FileStamp s = stamp_of(path_);
  if (s == disk_stamp_) return;
  disk_stamp_ = s;
  Expected<std::string> r = read_text_file(path_);
  if (!r || *r == saved_text_) return;
  if (!dirty()) {
    saved_text_ = *r;
    set_text(*r);
    autosaved_text_ = text_;
    snapshot();
    submit_regrow();
    status_ = "reloaded " + path_ + " (changed on disk)";
  } else {
    external_prompt_ = true;
  }
}

std::optional<std::string> StudioApp::export_gltf_file(const std::string& path, const GltfChoice& choice) {
  if (!plant_) return std::string("no plant to export yet");
  std::vector<GltfPlant> plants;
  const std::optional<SkinStyle> skin = skin_override();
  for (const ScenePlant& sp : scene_.plants) {  // the bark whatever the view shows; its skin
    if (!sp.skeleton) continue;
    GltfPlant p;
    p.name = stem(sp.grammar.empty() ? path_ : sp.grammar);
    p.skeleton = *sp.skeleton;
    for (int k = 0; k < 3; ++k) p.position_m[k] = sp.position[k];
    p.rotate_y_deg = sp.rotate_y_deg;
    p.scale = sp.scale;
    p.bark = sp.bark;
    p.skin = skin.value_or(sp.skin);
    plants.push_back(std::move(p));
  }
  GltfExportOptions o;
  o.mesh = choice.mesh;
  o.rig = choice.rig;
  o.max_joints = static_cast<uint32_t>(std::clamp(choice.max_joints, 1, static_cast<int>(kMaxRigJoints)));
  o.wind_data = choice.wind_data;
  o.lod = static_cast<uint32_t>(std::clamp(choice.lod, 0, static_cast<int>(kMaxLodLevels)));
  if (o.lod > 0) o.card_renderer = cpu_card_renderer(scene_.materials);
  if (choice.meshopt) o.compress = GltfCompression::meshopt;
  const SceneAnimation animation = scene_.animation.value_or(SceneAnimation{});
  o.wind_seed = animation.seed;
  if (choice.animation)
    o.animation = GltfWindClip{.sway = sway_parameters_of(animation), .duration_s = animation.duration_s, .fps = animation.fps};
  if (Status exported = export_gltf(plants, path, o); !exported) return one_line(exported.error());
  return std::nullopt;
}

std::optional<std::string> StudioApp::export_skeleton_file(const std::string& path) {
  if (!plant_) return std::string("no plant to export yet");
  const Skeleton& sk = *scene_.plants[edited_plants_.front()].skeleton;
  if (Status written = write_file_atomically(path, write_skeleton_json(sk)); !written) return one_line(written.error());
  return std::nullopt;
}

std::optional<std::string> StudioApp::export_png_file(const std::string& path, uint32_t width, uint32_t height) {
  if (!plant_) return std::string("no plant to export yet");
  if (!viewport_) return std::string("no renderer in this session");
  Scene s = view_scene();
  s.camera = orbit_.camera();
  s.width = width;
  s.height = height;
  // The viewport draws one sample a frame to stay interactive; the file gets `sylva
  // render`'s default, where needles and twigs stop breaking up (docs/benchmarks.md).
  RenderOptions options = render_options_;
  options.spp = std::max(options.spp, kDefaultRenderSpp);
  return viewport_->write_image(s, options, path);
}

// ---- the frame --------------------------------------------------------------------

void StudioApp::handle_chord(int key, bool shift) {
  switch (key) {
    case 'Z': shift ? redo() : undo(); break;
    case 'Y': redo(); break;
    case 'F': editor_.open_find(); break;
    case 'G': editor_.open_goto(); break;
    case 'S':
      if (shift) dialog_ = FileDialog::save_as, dialog_path_ = path_.empty() ? "untitled.lsys" : path_;
      else save();
      break;
    case 'O': dialog_ = FileDialog::open, dialog_path_ = path_; break;
    default: break;
  }
}

void StudioApp::handle_shortcuts() {
  if (chords_from_callbacks_) {
    std::vector<Chord> chords;
    chords.swap(chords_);
    for (const Chord& c : chords) handle_chord(c.key, c.shift);
    return;
  }
  // No key callback (the headless tests): ImGui's polled keys.
  const ImGuiIO& io = ImGui::GetIO();
  if (!io.KeyCtrl) return;
  for (char key : {'Z', 'Y', 'F', 'G', 'S', 'O'})
    if (key_pressed(key)) handle_chord(key, io.KeyShift);
}

void StudioApp::frame(double now) {
  now_ = now;
  rects_.clear();
  poll_worker();
  update_cones();
  handle_shortcuts();

  // A pause in typing: grow the new text; a longer one: an undo step.
  if (edited_at_ && now - *edited_at_ >= options_.debounce_s) submit_regrow();
  if (unsnapped_at_ && now - *unsnapped_at_ >= options_.snapshot_s) snapshot();
  autosave(now);
  watch_file(now);

  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(vp->WorkPos);
  ImGui::SetNextWindowSize(vp->WorkSize);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowRounding, 0);
  ImGui::Begin("studio", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_MenuBar | ImGuiWindowFlags_NoBringToFrontOnFocus);
  ImGui::PopStyleVar();
  draw_menu();
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const float left = std::floor(avail.x * 0.42f);
  const float status_h = ImGui::GetFrameHeightWithSpacing();

  ImGui::BeginChild("left", ImVec2(left, avail.y - status_h), false);
  {
    const float message_h = message_bar_height(ImGui::GetContentRegionAvail().x);
    draw_editor(ImVec2(ImGui::GetContentRegionAvail().x, ImGui::GetContentRegionAvail().y - message_h));
    draw_message_bar();
  }
  ImGui::EndChild();
  ImGui::SameLine();
  ImGui::BeginChild("right", ImVec2(0, avail.y - status_h), false);
  {
    const ImVec2 r = ImGui::GetContentRegionAvail();
    draw_viewport(ImVec2(r.x, std::floor(r.y * 0.6f)));
    ImGui::BeginChild("panels", ImVec2(0, 0), true);
    draw_parameters();
    draw_derivation();
    draw_view();
    draw_fog();
    draw_light();
    ImGui::EndChild();
    keep("panels");
  }
  ImGui::EndChild();

  // Status line: what was last done, and the cursor.
  ImGui::Separator();
  ImGui::Text("Ln %u, Col %u", editor_.cursor_line(), editor_.cursor_column());
  ImGui::SameLine(160);
  ImGui::TextUnformatted(status_.c_str());
  ImGui::End();

  if (show_presets_) draw_presets();
  draw_file_dialog();
  draw_modals();
}

void StudioApp::draw_menu() {
  if (!ImGui::BeginMenuBar()) return;
  if (ImGui::BeginMenu("File")) {
    if (ImGui::MenuItem("Open...", "Ctrl+O")) dialog_ = FileDialog::open, dialog_path_ = path_;
    if (ImGui::MenuItem("Presets...")) show_presets_ = true;
    if (ImGui::MenuItem("Save", "Ctrl+S")) save();
    if (ImGui::MenuItem("Save as...", "Ctrl+Shift+S"))
      dialog_ = FileDialog::save_as, dialog_path_ = path_.empty() ? "untitled.lsys" : path_;
    if (ImGui::MenuItem("Save scene", nullptr, false, !scene_path_.empty())) {
      if (auto err = save_scene()) status_ = *err;
    }
    if (ImGui::MenuItem("Save scene as...")) {
      dialog_ = FileDialog::save_scene_as;
      dialog_path_ = !scene_path_.empty() ? scene_path_
                     : path_.empty()      ? std::string("untitled.scene.json")
                                          : (std::filesystem::path(path_).replace_extension("").string() + ".scene.json");
    }
    if (ImGui::MenuItem("Reload from disk", nullptr, false, !path_.empty())) {
      Expected<std::string> r = read_text_file(path_);
      if (r) {
        saved_text_ = *r;
        set_text(*r);
        snapshot();
        submit_regrow();
      }
    }
    ImGui::Separator();
    if (ImGui::MenuItem("Quit")) request_close();
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Edit")) {
    if (ImGui::MenuItem("Undo", "Ctrl+Z", false, history_.can_undo() || doc_state() != history_.current())) undo();
    if (ImGui::MenuItem("Redo", "Ctrl+Shift+Z", false, history_.can_redo())) redo();
    if (ImGui::MenuItem("Find", "Ctrl+F")) editor_.open_find();
    if (ImGui::MenuItem("Go to line", "Ctrl+G")) editor_.open_goto();
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Export")) {
    const std::string base = path_.empty() ? "untitled" : (std::filesystem::path(path_).parent_path() / stem(path_)).string();
    if (ImGui::MenuItem("glTF...", nullptr, false, plant_.has_value()))
      dialog_ = FileDialog::export_gltf, dialog_path_ = base + ".glb";
    if (ImGui::MenuItem("PNG...", nullptr, false, plant_.has_value()))
      dialog_ = FileDialog::export_png, dialog_path_ = base + ".png";
    if (ImGui::MenuItem("Skeleton...", nullptr, false, plant_.has_value()))
      dialog_ = FileDialog::export_skeleton, dialog_path_ = base + ".skel.json";
    ImGui::EndMenu();
  }
  ImGui::EndMenuBar();
}

void StudioApp::draw_editor(ImVec2 size) {
  std::optional<EditorMark> mark;
  if (error_ && error_->loc.line > 0)
    mark = EditorMark{error_->loc.line, error_->loc.column, token_length(text_, error_->loc.line, error_->loc.column),
                      error_->message};
  if (editor_.draw("editor", text_, mark, size)) {
    rescan_defines();
    edited_at_ = now_;
    unsnapped_at_ = now_;  // the undo step comes after a pause in typing
    animating_ = false;
  }
  keep("editor");
  if (editor_.deactivated() && doc_state() != history_.current()) snapshot();
}

std::string StudioApp::message_text() const {
  if (!error_) return "";
  const std::string text = error_->format();
  return text.substr(0, text.find('\n'));
}

float StudioApp::message_bar_height(float width) const {
  const float line = ImGui::GetTextLineHeightWithSpacing();
  if (!error_) return line * 2 + 4;
  // The whole message, wrapped to the pane (issue 31 §5: it was cut at the pane's edge),
  // but never more than a third of the pane's height.
  const float wrapped = ImGui::CalcTextSize(message_text().c_str(), nullptr, false, width).y;
  return std::min(wrapped + ImGui::GetStyle().ItemSpacing.y, ImGui::GetContentRegionAvail().y / 3) + line + 4;
}

void StudioApp::draw_message_bar() {
  if (error_) {
    const std::string first = message_text();
    // A selectable as tall as the wrapped message, the message drawn over it.
    const ImVec2 at = ImGui::GetCursorPos();
    const float width = ImGui::GetContentRegionAvail().x;
    const float height = ImGui::CalcTextSize(first.c_str(), nullptr, false, width).y;
    const bool clicked = ImGui::Selectable("##message", false, 0, ImVec2(width, height));
    keep("message");
    const ImVec2 after = ImGui::GetCursorPos();
    ImGui::SetCursorPos(at);
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.5f, 0.45f, 1));
    ImGui::PushTextWrapPos(at.x + width);
    ImGui::TextUnformatted(first.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
    ImGui::SetCursorPos(after);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("click to go to the error\n%s", error_->format().c_str());
    if (clicked && error_->loc.line > 0) editor_.jump_to(error_->loc.line, std::max(1u, error_->loc.column));
    ImGui::TextDisabled("the viewport keeps the last good plant");
  } else if (plant_) {
    ImGui::TextDisabled("%s", plant_->warning.empty() ? "no errors" : plant_->warning.c_str());
    keep("message");
  } else {
    ImGui::TextDisabled("%s", worker_->busy() ? "growing..." : "");
  }
}

void StudioApp::draw_viewport(ImVec2 size) {
  ImGui::BeginChild("viewport", size, true, ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse);
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const ImGuiIO& io = ImGui::GetIO();
  const float line = ImGui::GetTextLineHeightWithSpacing();
  const ImVec2 image_size(std::max(1.0f, avail.x), std::max(1.0f, avail.y - line));
  // The scene's size follows the panel; while the camera is dragged, half the pixels.
  const uint32_t scale = view_half_res_ ? 2 : 1;
  scene_.width = std::max<uint32_t>(1, static_cast<uint32_t>(image_size.x) / scale);
  scene_.height = std::max<uint32_t>(1, static_cast<uint32_t>(image_size.y) / scale);
  if (camera_set_) scene_.camera = orbit_.camera();  // before the first plant: the file's camera
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("##view", image_size,
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonMiddle);
  keep("viewport");
  const bool hovered = ImGui::IsItemHovered(), active = ImGui::IsItemActive();
  if (active && (io.MouseDelta.x != 0 || io.MouseDelta.y != 0)) {
    if (ImGui::IsMouseDown(ImGuiMouseButton_Middle) || (io.KeyShift && ImGui::IsMouseDown(ImGuiMouseButton_Left)))
      orbit_.pan(io.MouseDelta.x, io.MouseDelta.y, image_size.y);
    else if (ImGui::IsMouseDown(ImGuiMouseButton_Left))
      orbit_.orbit(io.MouseDelta.x, io.MouseDelta.y);
  }
  view_half_res_ = active;
  if (hovered && io.MouseWheel != 0) orbit_.zoom(io.MouseWheel);
  if (hovered && !io.WantTextInput && key_pressed('F') && !io.KeyCtrl) frame_plant();
  if (camera_set_) scene_.camera = orbit_.camera();  // before the first plant: the file's camera

  ImDrawList* dl = ImGui::GetWindowDrawList();
  ViewImage img;
  if (viewport_ && plant_) img = viewport_->image(view_scene());
  if (img.texture) {
    dl->AddImage(img.texture, origin, ImVec2(origin.x + image_size.x, origin.y + image_size.y),
                 img.flip_v ? ImVec2(0, 1) : ImVec2(0, 0), img.flip_v ? ImVec2(1, 0) : ImVec2(1, 1));
    if (img.current) {
      drawn_version_ = plants_applied_;
      if (latency_start_) {
        latencies_.push_back(std::chrono::duration<double>(Clock::now() - *latency_start_).count());
        latency_start_.reset();
      }
    }
  } else {
    dl->AddRectFilled(origin, ImVec2(origin.x + image_size.x, origin.y + image_size.y), IM_COL32(40, 44, 52, 255));
    const char* why = !plant_ ? (worker_->busy() ? "growing..." : "no plant yet")
                               : (viewport_ && !viewport_->stats().error.empty() ? viewport_->stats().error.c_str()
                                                                                 : "no renderer");
    dl->AddText(ImVec2(origin.x + 10, origin.y + 10), IM_COL32(200, 200, 200, 255), why);
    if (plant_ && (!viewport_ || !viewport_->busy())) {
      drawn_version_ = plants_applied_;  // nothing more to wait for
      if (latency_start_) {
        latencies_.push_back(std::chrono::duration<double>(Clock::now() - *latency_start_).count());
        latency_start_.reset();
      }
    }
  }
  if (show_queries_ && plant_) {
    // Projected and sorted again only when the view, the panel or the plant changed.
    const double radius = scene_.environment.value_or(LightEnvironment{}).sensor_radius_m;
    const QueryDotsKey key{scene_.camera, origin.x, origin.y, image_size.x, image_size.y, radius, plants_applied_};
    if (!(key == query_dots_key_)) {
      std::vector<PlantQueries> plants;
      for (size_t k = 0; k < edited_plants_.size() && k < plant_->queries.size(); ++k)
        plants.push_back({&scene_.plants[edited_plants_[k]], &plant_->queries[k]});
      query_dots_ = studio::query_dots(scene_.camera, origin, image_size, radius, plants);
      query_dots_key_ = key;
    }
    draw_query_dots(dl, query_dots_, origin, image_size);
  } else {
    query_dots_.clear();
    query_dots_key_ = {};
  }
  if (worker_->busy()) {
    int64_t step = 0, steps = 0;
    worker_->progress(&step, &steps);
    char text[96];
    std::snprintf(text, sizeof text, "regrowing... step %lld/%lld", static_cast<long long>(step),
                  static_cast<long long>(steps));
    dl->AddText(ImVec2(origin.x + 10, origin.y + image_size.y - line - 4), IM_COL32(255, 230, 150, 255), text);
  }
  // Under the picture: what it is and what it cost.
  if (plant_) {
    // GL pictures say their GPU time; the CPU viewport's (no GPU passes) its render time.
    double gpu_ms = 0;
    bool gpu = false;
    if (viewport_)
      for (const RenderPass& p : viewport_->stats().passes)
        if (p.name.find("(GPU)") != std::string::npos) gpu_ms += p.seconds * 1e3, gpu = true;
    if (viewport_ && !gpu) gpu_ms = viewport_->stats().render_ms;
    char leaves[32] = "";
    if (plant_->leaves > 0)
      std::snprintf(leaves, sizeof leaves, "  %llu leaves", static_cast<unsigned long long>(plant_->leaves));
    ImGui::Text("%llu segments%s  step %lld/%lld  %llu modules  %s %.1f ms  frame %.1f ms",
                static_cast<unsigned long long>(plant_->segments), leaves, static_cast<long long>(plant_->shown_step),
                static_cast<long long>(plant_->steps), static_cast<unsigned long long>(plant_->modules),
                gpu ? "GPU" : "CPU", gpu_ms, io.DeltaTime * 1e3);
  }
  ImGui::EndChild();
}

void StudioApp::draw_parameters() {
  if (!ImGui::CollapsingHeader("Parameters", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::Checkbox("continuous", &continuous_);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("regrow while dragging (off: when the slider is released)");
  ImGui::SameLine();
  if (ImGui::Button("Write to text")) write_parameters_to_text();
  keep("write_to_text");
  ImGui::SameLine();
  if (ImGui::Button("Reset") && !overrides_.empty()) {
    overrides_.clear();
    field_text_.clear();
    snapshot();
    submit_regrow();
  }
  const float field_w = 90;
  for (const DefineLine& d : define_lines_) {
    ImGui::PushID(d.name.c_str());
    double value = 0;
    bool known = false;
    if (auto it = overrides_.find(d.name); it != overrides_.end()) value = it->second, known = true;
    if (!known && plant_)
      for (const lsys::Define& gd : plant_->defines)
        if (gd.name == d.name) value = gd.value, known = true;
    if (!known) value = parse_exact(d.value_text).value_or(0);
    bool changed = false, released = false;
    if (d.has_range()) {
      const float slider_w = std::max(80.0f, ImGui::GetContentRegionAvail().x - field_w - 130);
      ImGui::SetNextItemWidth(slider_w);
      double v = value;
      if (ImGui::SliderScalar("##slider", ImGuiDataType_Double, &v, &*d.min, &*d.max, "%.4g",
                              ImGuiSliderFlags_NoRoundToFormat)) {
        if (d.step) v = *d.min + std::round((v - *d.min) / *d.step) * *d.step;
        // What the slider can tell apart: its step, or its range over its pixels.
        v = slider_value(v, d.step ? *d.step : (*d.max - *d.min) / static_cast<double>(slider_w));
        v = std::clamp(v, *d.min, *d.max);
        if (v != value) value = v, changed = true;
      }
      keep("slider:" + d.name);
      released = ImGui::IsItemDeactivatedAfterEdit();
      ImGui::SameLine();
    }
    // The typed field: exact (parsed whole, shortest round-trip shown).
    std::string& field = field_text_[d.name];
    if (!ImGui::IsAnyItemActive() || field.empty()) {
      // refreshed below unless this field is being typed in
    }
    ImGui::SetNextItemWidth(field_w);
    const std::string shown = shortest(value);
    std::string buffer = field.empty() ? shown : field;
    const bool typed_enter = ImGui::InputText("##field", &buffer, ImGuiInputTextFlags_EnterReturnsTrue);
    keep("field:" + d.name);
    const bool field_active = ImGui::IsItemActive();
    if (field_active) field = buffer;
    if (typed_enter || ImGui::IsItemDeactivatedAfterEdit()) {
      if (auto v = parse_exact(buffer)) {
        value = *v;
        changed = released = true;
      }
      field.clear();
    } else if (!field_active) {
      field.clear();
    }
    ImGui::SameLine();
    const bool overridden = overrides_.count(d.name) > 0;
    if (overridden) ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.85f, 0.4f, 1));
    ImGui::TextUnformatted(d.name.c_str());
    if (overridden) ImGui::PopStyleColor();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("#define %s %s (line %u)%s", d.name.c_str(), d.value_text.c_str(), d.line,
                        overridden ? "\noverridden: not in the text until 'Write to text'" : "");
    if (changed) overrides_[d.name] = value;
    if ((changed && continuous_) || released) submit_regrow();
    if (released) snapshot();
    ImGui::PopID();
  }
  // Seed and steps: exact integers.
  {
    const uint64_t grammar_seed = plant_ ? plant_->grammar_seed : 1;
    std::string seed_text = std::to_string(seed_.value_or(grammar_seed));
    ImGui::SetNextItemWidth(160);
    if (ImGui::InputText("seed", &seed_text, ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_CharsDecimal))
      if (auto v = parse_u64_exact(seed_text)) seed_ = *v, snapshot(), submit_regrow();
    ImGui::SameLine();
    if (ImGui::Button("+1")) seed_ = seed_.value_or(grammar_seed) + 1, snapshot(), submit_regrow();
    keep("seed+1");
    ImGui::SameLine();
    int64_t steps = steps_.value_or(plant_ ? plant_->grammar_steps : 1);
    const int64_t one = 1;
    ImGui::SetNextItemWidth(120);
    if (ImGui::InputScalar("steps", ImGuiDataType_S64, &steps, &one, nullptr, "%lld",
                           ImGuiInputTextFlags_EnterReturnsTrue)) {
      steps_ = std::max<int64_t>(0, steps);
      show_step_.reset();
      snapshot();
      submit_regrow();
    }
  }
}

void StudioApp::draw_derivation() {
  if (!ImGui::CollapsingHeader("Derivation", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (ImGui::Button("Rewind")) rewind();
  keep("button:Rewind");
  ImGui::SameLine();
  if (ImGui::Button("Step")) step();
  keep("button:Step");
  ImGui::SameLine();
  if (ImGui::Button("Run")) run();
  keep("button:Run");
  ImGui::SameLine();
  if (ImGui::Button(animating_ ? "Stop" : "Animate")) animating_ ? (void)(animating_ = false) : animate();
  keep("button:Animate");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  ImGui::SliderFloat("##speed", &animate_steps_per_s_, 0.25f, 60, "%.2g steps/s", ImGuiSliderFlags_Logarithmic);
  keep("slider:animate_speed");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(70);
  ImGui::SliderInt("##substeps", &animate_substeps_, 1, 16, animate_substeps_ == 1 ? "whole steps" : "%d substeps");
  keep("slider:animate_substeps");
  ImGui::SameLine();
  if (worker_->busy()) {
    if (ImGui::Button("Cancel")) worker_->cancel(), animating_ = false;
  } else if (plant_) {
    ImGui::Text("step %lld of %lld%s", static_cast<long long>(plant_->shown_step), static_cast<long long>(plant_->steps),
                plant_->from_cache ? " (cached)" : "");
  }
}

// The fog's cone modes (medium, fast, auto) need the shadow cones of the plants on screen
// under the sun, mode map their sun maps: asked of the cone worker when the plants, how they
// are skinned, the sun, the photons, the cones' kind or the maps' resolution or directions
// changed — never for the camera or the medium, which the same cones (maps) serve. The
// viewport draws with the last ones until the new ones arrive.
void StudioApp::update_cones() {
  if (std::optional<ConeResult> done = cones_->poll(); done && viewport_) {
    if (done->maps) viewport_->set_fog_maps(std::move(done->maps));
    else viewport_->set_fog_cones(std::move(done->cones));
  }
  if (!viewport_ || !plant_ || !scene_.fog || scene_.fog->mode == FogMode::brute) return;
  const FogMode kind = gl_fog_walks_maps(scene_.fog->mode)        ? FogMode::map
                       : scene_.fog->mode == FogMode::medium       ? FogMode::medium
                                                                   : FogMode::fast;
  const glm::dvec3 sun = unit_sun_direction(scene_.sun.direction);
  std::vector<double> key = {static_cast<double>(plants_applied_),
                             sun.x,
                             sun.y,
                             sun.z,
                             scene_.sun.angular_radius_deg,
                             scene_.ground.height,
                             static_cast<double>(scene_.fog->photons),
                             static_cast<double>(kind),
                             static_cast<double>(render_options_.skin.knuckle_frusta),
                             render_options_.geometry.relief ? 1.0 : 0.0,
                             static_cast<double>(scene_.fog->map_resolution),
                             static_cast<double>(scene_.fog->map_directions)};
  if (key == cone_key_) return;
  cone_key_ = std::move(key);
  ++cone_requests_;
  cones_->submit(ConeRequest{view_scene(), render_options_.skin, kind, scene_.fog->photons});
}

// docs/spec/fog.md's medium, live: every control changes scene_.fog, which the viewport's next
// picture draws (a new picture, never a re-skin; new cones only for new photons or mode
// kind) and save_scene writes.
void StudioApp::draw_fog() {
  if (!ImGui::CollapsingHeader("Fog", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (!scene_.fog) {
    if (ImGui::Button("add fog")) scene_.fog = fog_for_view(scene_.camera);
    keep("fog:add");
    return;
  }
  Fog& f = *scene_.fog;
  auto slider = [&](const char* label, double* value, float lo, float hi, const char* format, bool logarithmic) {
    float v = static_cast<float>(*value);
    ImGui::SetNextItemWidth(150);
    if (ImGui::SliderFloat(label, &v, lo, hi, format, logarithmic ? ImGuiSliderFlags_Logarithmic : 0)) *value = v;
    keep(std::string("fog:") + label);
  };
  slider("sigma_s", &f.sigma_s, 0, 0.5f, "%.4f /m", true);
  ImGui::SameLine();
  slider("sigma_a", &f.sigma_a, 0, 0.5f, "%.4f /m", true);
  slider("g", &f.g, -0.9f, 0.9f, "%.2f", false);
  ImGui::SameLine();
  slider("height falloff", &f.height_falloff, 0, 1, "%.3f /m", true);
  bool ceiling = std::isfinite(f.top);
  if (ImGui::Checkbox("top", &ceiling)) f.top = ceiling ? scene_.ground.height + 30 : std::numeric_limits<double>::infinity();
  keep("fog:top on");
  if (ceiling) {
    ImGui::SameLine();
    float top = static_cast<float>(f.top - scene_.ground.height);
    ImGui::SetNextItemWidth(150);
    if (ImGui::SliderFloat("above ground", &top, 0.5f, 500, "%.1f m", ImGuiSliderFlags_Logarithmic))
      f.top = scene_.ground.height + top;
    keep("fog:top");
  }
  // The GL backend's modes (docs/gl-fog.md); refined and reference are the CPU's.
  const FogMode modes[] = {FogMode::automatic, FogMode::brute, FogMode::medium, FogMode::fast, FogMode::map};
  ImGui::SetNextItemWidth(100);
  if (ImGui::BeginCombo("mode", fog_mode_name(f.mode))) {
    for (FogMode m : modes)
      if (ImGui::Selectable(fog_mode_name(m), m == f.mode)) f.mode = m;
    ImGui::EndCombo();
  }
  keep("fog:mode");
  ImGui::SameLine();
  int steps = static_cast<int>(f.steps);
  ImGui::SetNextItemWidth(120);
  if (ImGui::SliderInt("steps", &steps, 1, 512, "%d", ImGuiSliderFlags_Logarithmic))
    f.steps = static_cast<uint32_t>(std::clamp(steps, 1, 512));
  keep("fog:steps");
  ImGui::SameLine();
  // Each new count is a new cone build (the latest wins: the one running is cancelled).
  static_assert(sizeof(unsigned long long) == sizeof(uint64_t));
  uint64_t photons = f.photons;
  const uint64_t photons_min = 1000, photons_max = 10'000'000;
  ImGui::SetNextItemWidth(150);
  ImGui::SliderScalar("photons", ImGuiDataType_U64, &photons, &photons_min, &photons_max, "%llu",
                      ImGuiSliderFlags_Logarithmic);
  if (photons != f.photons) f.photons = std::max<uint64_t>(1, photons);
  keep("fog:photons");
  if (ImGui::Button("remove fog")) scene_.fog.reset();
  keep("fog:remove");
}

// docs/spec/light.md's environment, live: a grammar with ?E queries grows in the scene's sun
// and this light; every change regrows it (a grammar without queries traces nothing, and
// its plant is not regrown for the light).
void StudioApp::draw_light() {
  const bool open = ImGui::CollapsingHeader("Light (?E)");
  keep("header:light");
  if (!open) return;
  LightEnvironment e = scene_.environment.value_or(LightEnvironment{});
  const LightEnvironment before = e;
  ImGui::SetNextItemWidth(130);
  if (ImGui::BeginCombo("sky", light_sky_name(e.sky))) {
    for (LightSky sky : {LightSky::sun, LightSky::uniform, LightSky::overcast, LightSky::sun_uniform,
                         LightSky::sun_overcast})
      if (ImGui::Selectable(light_sky_name(sky), sky == e.sky)) e.sky = sky;
    ImGui::EndCombo();
  }
  keep("light:sky");
  if (e.sky == LightSky::sun_uniform || e.sky == LightSky::sun_overcast) {
    ImGui::SameLine();
    float f = static_cast<float>(e.sun_fraction);
    ImGui::SetNextItemWidth(120);
    if (ImGui::SliderFloat("sun fraction", &f, 0, 1, "%.2f")) e.sun_fraction = f;
    keep("light:sun_fraction");
  }
  uint64_t photons = e.photons;
  const uint64_t photons_min = 1000, photons_max = 10'000'000;
  ImGui::SetNextItemWidth(150);
  ImGui::SliderScalar("photons##light", ImGuiDataType_U64, &photons, &photons_min, &photons_max, "%llu",
                      ImGuiSliderFlags_Logarithmic);
  e.photons = std::max<uint64_t>(1, photons);
  keep("light:photons");
  ImGui::SameLine();
  float radius = static_cast<float>(e.sensor_radius_m);
  ImGui::SetNextItemWidth(120);
  if (ImGui::SliderFloat("sensor", &radius, 0.01f, 1, "%.2f m", ImGuiSliderFlags_Logarithmic))
    e.sensor_radius_m = std::max(radius, 1e-3f);
  keep("light:sensor_radius");
  int every = static_cast<int>(e.every);
  ImGui::SetNextItemWidth(90);
  if (ImGui::SliderInt("every", &every, 1, 10, "%d steps")) e.every = static_cast<uint32_t>(std::clamp(every, 1, 10));
  keep("light:every");
  if (!(e == before)) {
    scene_.environment = e;
    submit_regrow();
  }
  ImGui::Checkbox("colour queries by q", &show_queries_);
  keep("light:show_queries");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("draw every ?E over the picture, coloured by its last answer q (dark: shaded, yellow: open sky)");
  if (plant_ && plant_->light.answers > 0)
    ImGui::Text("%llu answers, %llu queries, %.2f s (%.2f s CPU tracing), noise %.1f%%",
                static_cast<unsigned long long>(plant_->light.answers),
                static_cast<unsigned long long>(plant_->light.queries), plant_->light.seconds,
                plant_->light.cpu_seconds, 100 * plant_->light.mean_relative_error);
  else
    ImGui::TextDisabled("the grammar asks no ?E: no light is traced while it grows");
}

void StudioApp::draw_view() {
  if (!ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) return;
  bool sun = false;
  ImGui::SetNextItemWidth(150);
  sun |= ImGui::SliderFloat("sun azimuth", &sun_azimuth_deg_, -180, 180, "%.0f deg");
  keep("sun azimuth");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(150);
  sun |= ImGui::SliderFloat("elevation", &sun_elevation_deg_, 1, 90, "%.0f deg");
  if (sun) {
    const double az = sun_azimuth_deg_ * kRadPerDeg, el = sun_elevation_deg_ * kRadPerDeg;
    scene_.sun.direction = {std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
  }
  bool skin = false;
  skin |= ImGui::Checkbox("bark", &bark_);
  ImGui::SameLine();
  skin |= ImGui::Checkbox("relief", &render_options_.geometry.relief);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(110);
  skin |= ImGui::Combo("skin", &skin_choice_, "scene's\0smooth\0paper\0");
  keep("skin");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(100);
  int knuckles = render_options_.skin.knuckle_frusta;
  if (ImGui::SliderInt("knuckle frusta", &knuckles, 2, 16)) render_options_.skin.knuckle_frusta = knuckles;
  skin |= ImGui::IsItemDeactivatedAfterEdit();
  ImGui::SameLine();
  if (ImGui::Button("Frame (F)")) frame_plant();
  if (skin) plants_changed();
  if (viewport_) {
    const ViewStats& st = viewport_->stats();
    // The GPU passes of a GL picture; every pass of a CPU one (none says "(GPU)").
    bool gpu = false;
    for (const RenderPass& p : st.passes) gpu |= p.name.find("(GPU)") != std::string::npos;
    std::string passes;
    for (const RenderPass& p : st.passes)
      if (!gpu || p.name.find("(GPU)") != std::string::npos) {
        char b[96];
        std::snprintf(b, sizeof b, "%s%s %.2f ms", passes.empty() ? "" : ", ", p.name.substr(0, p.name.find(" (")).c_str(),
                      p.seconds * 1e3);
        passes += b;
      }
    ImGui::TextDisabled("%s: %s", gpu || passes.empty() ? "GPU" : "CPU", passes.empty() ? "-" : passes.c_str());
    ImGui::TextDisabled("%llu frusta, render %.1f ms, skin+upload %.1f ms%s%s",
                        static_cast<unsigned long long>(st.frusta), st.render_ms, st.upload_ms,
                        st.renderer.empty() ? "" : ", ", st.renderer.c_str());
  }
  if (!latencies_.empty()) ImGui::TextDisabled("last regrow: %.0f ms edit to picture", latencies_.back() * 1e3);
}

// Thumbnails the worker finished, made into textures (the viewport's GL, on this thread).
void StudioApp::take_thumbnails() {
  if (!thumbnails_) return;
  for (auto& [path, t] : thumbnails_->take_finished()) {
    if (!t.error.empty()) {
      thumbnail_errors_[path] = t.error;
      continue;
    }
    if (ImTextureID texture = viewport_ ? viewport_->make_texture(t.width, t.height, t.rgba) : nullptr)
      thumbnail_textures_[path] = texture;
  }
}

void StudioApp::draw_presets() {
  ImGui::SetNextWindowSize(ImVec2(520, 560), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowPos(ImVec2(60, 60), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Presets", &show_presets_, ImGuiWindowFlags_NoSavedSettings)) {
    ImGui::End();
    return;
  }
  if (!presets_) {  // listed once, not every frame; thumbnails asked for in list order
    presets_ = list_presets(options_.presets_dir);
    if (!options_.thumbnail_cache.empty() && !presets_->empty()) {
      thumbnails_ = std::make_unique<ThumbnailWorker>(options_.thumbnail_cache, kThumbnailWidth, kThumbnailHeight);
      for (const PresetEntry& e : *presets_) thumbnails_->request(e.path);
    }
  }
  take_thumbnails();
  if (presets_->empty()) ImGui::TextDisabled("no presets in %s", options_.presets_dir.c_str());
  const ImVec2 thumb(static_cast<float>(kThumbnailWidth), static_cast<float>(kThumbnailHeight));
  for (const PresetEntry& e : *presets_) {
    ImGui::PushID(e.path.c_str());
    if (thumbnails_) {
      auto texture = thumbnail_textures_.find(e.path);
      if (texture != thumbnail_textures_.end()) {
        ImGui::Image(texture->second, thumb);
      } else {
        auto error = thumbnail_errors_.find(e.path);
        ImGui::BeginChild("##thumb", thumb, true, ImGuiWindowFlags_NoScrollbar);
        ImGui::TextDisabled("%s", error != thumbnail_errors_.end() ? "no picture" : "drawing...");
        ImGui::EndChild();
      }
      keep("thumbnail:" + e.label);
      ImGui::SameLine();
    }
    ImGui::BeginGroup();
    const bool chosen = ImGui::Selectable(e.label.c_str(), e.path == path_ || e.path == scene_path_, 0,
                                          ImVec2(ImGui::CalcTextSize(e.label.c_str()).x, 0));
    keep("preset:" + e.label);
    if (!e.description.empty() && ImGui::IsItemHovered()) {
      ImGui::BeginTooltip();
      ImGui::PushTextWrapPos(ImGui::GetFontSize() * 32);
      ImGui::TextUnformatted(e.description.c_str());
      ImGui::PopTextWrapPos();
      ImGui::EndTooltip();
    }
    if (!e.title.empty()) {
      if (thumbnails_) {  // under the label, wrapped beside the thumbnail
        ImGui::PushTextWrapPos(0);
        ImGui::TextDisabled("%s", e.title.c_str());
        ImGui::PopTextWrapPos();
      } else {  // one line a preset
        ImGui::SameLine();
        ImGui::TextDisabled("%s", e.title.c_str());
      }
      keep("preset title:" + e.label);
    }
    ImGui::EndGroup();
    ImGui::PopID();
    if (chosen) {
      if (dirty()) {
        open_after_prompt_ = e.path;
        close_prompt_ = true;
      } else if (auto err = open(e.path)) {
        status_ = *err;
      }
    }
  }
  ImGui::End();
}

void StudioApp::draw_file_dialog() {
  if (dialog_ == FileDialog::none) return;
  const char* titles[] = {"", "Open", "Save as", "Export glTF", "Export PNG", "Export skeleton", "Save scene as"};
  const char* title = titles[static_cast<int>(dialog_)];
  if (!ImGui::IsPopupOpen(title)) ImGui::OpenPopup(title);
  if (!ImGui::BeginPopupModal(title, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  ImGui::TextUnformatted(dialog_ == FileDialog::open ? "a .lsys grammar or .scene.json scene" : "file");
  ImGui::SetNextItemWidth(480);
  if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
  bool go = ImGui::InputText("##path", &dialog_path_, ImGuiInputTextFlags_EnterReturnsTrue);
  if (dialog_ == FileDialog::export_png) {
    ImGui::SetNextItemWidth(120);
    ImGui::InputInt("width", &export_width_);
    ImGui::SameLine();
    ImGui::SetNextItemWidth(120);
    ImGui::InputInt("height", &export_height_);
    export_width_ = std::clamp(export_width_, 1, 16384);
    export_height_ = std::clamp(export_height_, 1, 16384);
  }
  if (dialog_ == FileDialog::export_gltf) {
    GltfChoice& c = export_gltf_;
    ImGui::Checkbox("mesh (the skinned frusta as triangles)", &c.mesh);
    ImGui::BeginDisabled(!c.mesh);
    ImGui::Checkbox("wind rig (a glTF skin)", &c.rig);
    ImGui::SameLine();
    ImGui::SetNextItemWidth(100);
    ImGui::BeginDisabled(!c.rig);
    ImGui::InputInt("joints at most", &c.max_joints);
    c.max_joints = std::clamp(c.max_joints, 1, static_cast<int>(kMaxRigJoints));
    ImGui::Checkbox(scene_.animation ? "wind clip (the scene's animation, looping)" : "wind clip (the default sway, looping)",
                    &c.animation);
    ImGui::EndDisabled();
    ImGui::Checkbox("wind data for shaders (TEXCOORD_2/3)", &c.wind_data);
    ImGui::SetNextItemWidth(100);
    ImGui::InputInt("levels of detail (0: none; the last are impostor cards)", &c.lod);
    c.lod = std::clamp(c.lod, 0, static_cast<int>(kMaxLodLevels));
    ImGui::EndDisabled();
    ImGui::Checkbox("compress (EXT_meshopt_compression: three.js, Babylon, Unity; not Blender 3.4, Godot)",
                    &c.meshopt);
    if (!c.mesh) c.rig = c.wind_data = false, c.lod = 0;
    if (!c.rig) c.animation = false;
  }
  go |= ImGui::Button("OK");
  ImGui::SameLine();
  const bool cancel = ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape));
  if (go) {
    std::optional<std::string> err;
    switch (dialog_) {
      case FileDialog::open:
        if (dirty()) open_after_prompt_ = dialog_path_, close_prompt_ = true;
        else err = open(dialog_path_);
        break;
      case FileDialog::save_as: err = save_as(dialog_path_); break;
      case FileDialog::export_gltf: err = export_gltf_file(dialog_path_, export_gltf_); break;
      case FileDialog::export_png:
        err = export_png_file(dialog_path_, static_cast<uint32_t>(export_width_), static_cast<uint32_t>(export_height_));
        break;
      case FileDialog::export_skeleton: err = export_skeleton_file(dialog_path_); break;
      case FileDialog::save_scene_as: err = save_scene(dialog_path_); break;
      case FileDialog::none: break;
    }
    if (err) status_ = *err;
    else if (dialog_ != FileDialog::open && dialog_ != FileDialog::save_as && dialog_ != FileDialog::save_scene_as)
      status_ = "wrote " + dialog_path_;
  }
  if (go || cancel) {
    dialog_ = FileDialog::none;
    ImGui::CloseCurrentPopup();
  }
  ImGui::EndPopup();
}

void StudioApp::draw_modals() {
  if (restore_) {
    if (!ImGui::IsPopupOpen("Restore unsaved edits?")) ImGui::OpenPopup("Restore unsaved edits?");
    if (ImGui::BeginPopupModal("Restore unsaved edits?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
      ImGui::Text("%s has edits that were never saved (%s).", display_name().c_str(), autosave_path(path_).c_str());
      if (restore_->older_than_file)
        ImGui::Text("They are older than the file, which changed since they were written.");
      if (ImGui::Button("Restore")) {
        set_text(restore_->text);
        snapshot();
        submit_regrow();
        restore_.reset();
        ImGui::CloseCurrentPopup();
      }
      keep("button:Restore");
      ImGui::SameLine();
      if (ImGui::Button("Discard")) {
        remove_autosave(path_);
        restore_.reset();
        ImGui::CloseCurrentPopup();
      }
      keep("button:Discard");
      ImGui::EndPopup();
    }
  }
  if (close_prompt_) {
    if (!ImGui::IsPopupOpen("Unsaved edits")) ImGui::OpenPopup("Unsaved edits");
    if (ImGui::BeginPopupModal("Unsaved edits", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
      ImGui::Text("Save the changes to %s?", display_name().c_str());
      auto proceed = [&] {
        close_prompt_ = false;
        ImGui::CloseCurrentPopup();
        if (open_after_prompt_) {
          const std::string next = *open_after_prompt_;
          open_after_prompt_.reset();
          if (auto err = open(next)) status_ = *err;
        } else {
          quit_ = true;
        }
      };
      if (ImGui::Button("Save")) {
        if (path_.empty()) {
          close_prompt_ = false;
          dialog_ = FileDialog::save_as;
          dialog_path_ = "untitled.lsys";
          ImGui::CloseCurrentPopup();
        } else if (!save()) {
          proceed();
        }
      }
      keep("button:Save");
      ImGui::SameLine();
      if (ImGui::Button("Don't save")) {
        remove_autosave(path_.empty() ? "untitled.lsys" : path_);
        saved_text_ = text_;  // nothing left to lose: the user said so
        proceed();
      }
      keep("button:DontSave");
      ImGui::SameLine();
      if (ImGui::Button("Cancel")) {
        close_prompt_ = false;
        open_after_prompt_.reset();
        ImGui::CloseCurrentPopup();
      }
      keep("button:Cancel");
      ImGui::EndPopup();
    }
  }
  if (external_prompt_) {
    if (!ImGui::IsPopupOpen("Changed on disk")) ImGui::OpenPopup("Changed on disk");
    if (ImGui::BeginPopupModal("Changed on disk", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
      ImGui::Text("%s was changed by another program, and has unsaved edits here.", display_name().c_str());
      if (ImGui::Button("Reload (lose my edits)")) {
        Expected<std::string> r = read_text_file(path_);
        if (r) {
          saved_text_ = *r;
          set_text(*r);
          snapshot();
          submit_regrow();
        }
        external_prompt_ = false;
        ImGui::CloseCurrentPopup();
      }
      keep("button:Reload");
      ImGui::SameLine();
      if (ImGui::Button("Keep mine")) {
        Expected<std::string> r = read_text_file(path_);
        if (r) saved_text_ = *r;  // the disk's text is what "saved" means now
        external_prompt_ = false;
        ImGui::CloseCurrentPopup();
      }
      keep("button:KeepMine");
      ImGui::EndPopup();
    }
  }
}

}  // namespace sylva::studio
