// scene.h — the scene of docs/spec/scene.md: camera, image size, sun, sky, ground,
// fog and plants, read from a `.scene.json` file or made around one skeleton.
//
// Units: metres, Y up, angles in degrees where the name says _deg. Colours are linear RGB.
// Every key but `plants` is optional (the defaults below are those of docs/spec/scene.md's
// example); a key the reader does not know is an error naming the key, the file and the
// key's line and column, so a typo never silently changes a picture.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/geometry/skeleton.h"
#include "core/geometry/skeleton_bounds.h"  // skeleton_bounds, which framing_camera's callers take
#include "core/geometry/skin.h"
#include "core/util/bounds.h"
#include "core/util/diagnostic.h"
#include "core/util/progress.h"

namespace sylva {

// Pinhole camera; pixel (i, j), j downward, is sampled through (i + 0.5, j + 0.5).
struct Camera {
  glm::dvec3 eye{6, 3, 6};
  glm::dvec3 target{0, 2, 0};
  glm::dvec3 up{0, 1, 0};
  double fov_y_deg = 40;  // full vertical field of view, (0, 180)
  bool operator==(const Camera&) const = default;
};

// Why `camera` cannot be rendered, or nullopt: the one check of every camera, a scene's
// and the command line's (docs/limits.md): eye and target within ±kMaxCoordinateM and
// distinct, up not zero and not along the view, fov_y_deg strictly between 0 and 180. The
// message starts with the camera key it names ("eye", "target", "up" or "fov_y_deg"),
// e.g. "eye coordinates must be within ±1e12 m (docs/limits.md)"; `up` is compared as a
// direction, whatever its length.
std::optional<std::string> camera_problem(const Camera& camera);

// The sun: a disc light. angular_radius_deg 0 is a point sun (hard shadows).
struct Sun {
  glm::dvec3 direction{0.4, 1.0, 0.2};  // toward the sun, need not be unit (stored unit)
  double angular_radius_deg = 0.27;
  // Despite its name (kept: it is the scene file's key, docs/spec/scene.md), the sun's irradiance at
  // normal incidence, W/m² per linear RGB channel — not a radiance: a surface whose normal
  // makes an angle θ with the sun receives radiance·cos θ whatever the disc's size
  // (core/light/shading.h E_sun).
  glm::dvec3 radiance{3, 3, 2.8};
  bool operator==(const Sun&) const = default;
};

struct Ground {
  double height = 0;                    // the plane y = height
  glm::dvec3 albedo{0.35, 0.3, 0.25};
  bool operator==(const Ground&) const = default;
};

// The light that answers a grammar's `?E` queries while it grows (docs/spec/light.md): the
// scene's sun, a sky, or both, traced with `photons` photons after every `every`-th step.
enum class LightSky : uint8_t {
  sun,           // the scene's sun alone
  uniform,       // a uniform overcast sky (UOC)
  overcast,      // the CIE standard overcast sky: radiance ∝ (1 + 2 cos θ)/3 (Moon and Spencer 1942)
  sun_uniform,   // "sun+uniform": sun_fraction of the horizontal irradiance from the sun
  sun_overcast,  // "sun+overcast"
};
const char* light_sky_name(LightSky sky);                            // "sun", "sun+uniform", ...
std::optional<LightSky> light_sky_from_name(std::string_view name);  // nullopt: not a sky

struct LightEnvironment {
  LightSky sky = LightSky::sun;
  double sun_fraction = 1.0;        // [0, 1]; read by the sun+ skies only
  uint64_t photons = 1'000'000;     // per answer, 1..kLightMaxPhotons
  double sensor_radius_m = 0.1;     // (0, kLightMaxSensorRadiusM]
  uint32_t every = 1;               // answer after every n-th step, 1..kLightMaxEvery
  uint64_t seed = 1;                // the photons' stream, with the step
  bool operator==(const LightEnvironment&) const = default;
};
constexpr uint64_t kLightMaxPhotons = 1'000'000'000;
constexpr double kLightMaxSensorRadiusM = 1000;
constexpr uint32_t kLightMaxEvery = 1'000'000;

// How the fog's single scattering is computed (docs/spec/fog.md, "How the integral is computed";
// core/scene/fog_integrator.h implements each).
enum class FogMode : uint8_t {
  automatic,  // "auto": refined on the CPU
  brute,      // stratified samples, a shadow ray at each
  medium,     // the same samples, shadow rays only inside the shadow cones
  fast,       // no sunlight inside the cones, closed form outside
  refined,    // the cones' intervals refined to the exact transitions, closed form
  reference,  // converged: every visibility change bisected, many sun-disc samples
  map,        // the cones' intervals walked through sun-space depth maps, closed form
};
const char* fog_mode_name(FogMode mode);                          // "auto", "brute", ...
std::optional<FogMode> fog_mode_from_name(std::string_view name);  // nullopt: not a mode

// The participating medium and how it is rendered (docs/spec/fog.md): density
// ρ(y) = exp(−height_falloff·(y − ground.height)) up to `top`, 0 above it; σ = coefficient·ρ.
struct Fog {
  double sigma_s = 0.05;         // scattering coefficient at the ground, 1/m, >= 0
  double sigma_a = 0.005;        // absorption coefficient at the ground, 1/m, >= 0
  double g = 0.6;                // Henyey–Greenstein asymmetry that Schlick's phase approximates,
                                 // |g| < kFogMaxAbsG (fog.h: where Schlick's |k| reaches 1)
  double height_falloff = 0.0;   // 1/m, >= 0 (0: homogeneous)
  double top = std::numeric_limits<double>::infinity();  // world y of the fog's ceiling, above
                                 // ground.height; +inf (no `top` key): none
  FogMode mode = FogMode::automatic;
  uint32_t steps = 64;           // samples along a ray (brute, medium; probes of refined), >= 1
  uint64_t photons = 1'000'000;  // sun photons for the shadow cones, >= 1
  uint32_t map_resolution = 2048;  // mode map: texels a side of a sun map, a multiple of 32 in
                                   // [32, 65536] (core/cpu/sun_maps.h; docs/fog-map.md)
  uint32_t map_directions = 4;     // mode map: maps over the sun's disc, 1 to 64 (a point sun: 1)
  bool operator==(const Fog&) const = default;
};

// The most samples along one camera ray (`steps`, --fog-steps) and the most photons
// (`photons`, --photons) a scene or the command line may ask for.
constexpr uint32_t kFogMaxSteps = 65536;
constexpr uint64_t kFogMaxPhotons = 1'000'000'000;
// The range of a sun map's texels a side (a multiple of 32) and of its disc directions.
constexpr uint32_t kFogMinMapResolution = 32, kFogMaxMapResolution = 65536;
constexpr uint32_t kFogMaxMapDirections = 64;

// The `animation` key (docs/animation.md): how the plants move over time, for
// `sylva render --frames` and the studio. Frame k is at time k / fps seconds; the motion
// is core/scene/animate.h's sway (bend away from the wind, lateral chains fluttering), with
// `dance`'s defaults those of the paper's dancing cacti (Bhagvat et al. 2009, fig. 8): a stronger,
// faster bend. Keys a scene leaves out keep the motion's defaults (animation_defaults).
enum class AnimationMotion { sway, dance };
struct SceneAnimation {
  AnimationMotion motion = AnimationMotion::sway;
  double fps = 24;                   // frames per second, (0, 1000]
  double duration_s = 4;             // `--frames all` renders frames 0 .. ceil(duration·fps) − 1
  glm::dvec3 wind{1, 0, 0};          // where the wind blows to (its horizontal part counts)
  double amplitude_deg = 4;          // the top's bend at the sway's extreme, [0, 90]
  double frequency_hz = 0.4;         // [0, 100]
  double branch_amplitude_deg = 3;   // each lateral chain's swing, [0, 90]
  double branch_frequency_hz = 1.1;  // [0, 100]
  uint64_t seed = 0;                 // the chains' flutter frequencies, the plants' phases
  bool operator==(const SceneAnimation&) const = default;
};
// The defaults of a motion: sway's are SceneAnimation's; dance bends 12° at 1.2 Hz with the
// chains swinging 8° at 2.5 Hz.
SceneAnimation animation_defaults(AnimationMotion motion);
const char* animation_motion_name(AnimationMotion motion);  // "sway", "dance"
// The frames `--frames all` renders: ceil(duration_s · fps), at least 1.
uint64_t animation_frame_count(const SceneAnimation& animation);
// The most frames one command renders (docs/limits.md).
inline constexpr uint64_t kMaxAnimationFrames = 100'000;

// The bark of a plant. albedo is a texture path or a constant colour. Texture paths are
// checked when the scene is read: a file that does not exist or that OpenImageIO cannot
// open is an error at its key. Textures: texture.h; relief: relief.h.
struct Bark {
  std::optional<std::string> albedo_texture;  // resolved against the scene file's folder
  std::optional<glm::dvec3> albedo_rgb;       // constant albedo of material 0 (wood)
  std::optional<std::string> height_texture;  // relief height map (resolved path)
  double relief_depth_m = 0.02;
  double u_repeat = 1;           // texture repeats around the stem
  double v_per_metre = 1;        // texture repeats per metre of arc length
  bool operator==(const Bark&) const = default;
};

// How an image repeats over a segment: u_repeat times around, v_per_metre times per metre
// along (SceneMaterial::segment_repeat). Outside SceneMaterial: clang cannot default-construct
// a nested class with member initialisers inside the optional of its enclosing class.
struct SegmentRepeat {
  double u_repeat = 1, v_per_metre = 1;
  bool operator==(const SegmentRepeat&) const = default;
};

// One entry of the scene's `materials` table (docs/materials.md): how material index k
// (the grammar's `'`, a joint's material) looks on every plant of the scene. Material 0
// is the wood, which a plant's bark refines (materials.h).
struct SceneMaterial {
  std::optional<glm::dvec3> albedo_rgb;  // linear albedo; none: default_material_albedo(k)
  double specular = 1;                   // weight of the Blinn–Phong lobe (shading.h), [0, 1]
  std::optional<std::string> albedo_image{};  // resolved path: the leaves' albedo (leaf_images.h)
  std::optional<std::string> alpha_image{};   // resolved path: the leaves' cut-out (leaf_images.h)
  bool two_sided = true;                 // false: a leaf of it exists on its front side only
  // Given (the entry names `u_repeat` or `v_per_metre`): the albedo image also covers the
  // material's segments, laid as a bark's albedo texture is (texture.h: s = u·u_repeat,
  // t = v_m·v_per_metre, periodic, MIP-mapped). None: its segments take the image's mean
  // (leaf_images.h segment_look). Only with an albedo image.
  using Repeat = SegmentRepeat;
  std::optional<Repeat> segment_repeat{};
  bool operator==(const SceneMaterial&) const = default;
};

// The albedo texture that covers the segments (not the leaves) of `material` on a plant
// with `bark` (docs/materials.md, first match wins): material 0 with a bark albedo texture:
// that texture, with the bark's repeats; material 0 with a bark albedo colour: none (the
// colour); else the table entry's albedo image where it gives a segment_repeat; else none.
// `bark` may be null (then only the table counts).
struct SegmentTexture {
  std::string path;
  double u_repeat = 1, v_per_metre = 1;
  bool from_bark = false;  // the bark's albedo texture (else the table entry's image)
};
std::optional<SegmentTexture> segment_texture(const std::map<uint32_t, SceneMaterial>& table, const Bark* bark,
                                              uint32_t material);

// The highest material index the `materials` table may name (the GL shade pass's table
// holds kMaterialSlots entries; higher indices look like the default table's last).
constexpr uint32_t kMaterialSlots = 256;

// What material `material` looks like (but for bark textures, which the renderers look up
// themselves on material 0): albedo = `bark`'s colour for material 0 where it has one,
// else the table's entry, else default_material_albedo(material); specular = the table
// entry's, else 1. `bark` may be null (the scene-wide table alone).
struct MaterialLook {
  glm::dvec3 albedo;
  double specular;
};
MaterialLook material_look(const std::map<uint32_t, SceneMaterial>& table, const Bark* bark,
                           uint32_t material);

// One plant: a grammar grown with seed/steps/defines, or a ready skeleton, placed by
// p_world = position + R_y(rotate_y_deg) · (scale · p).
struct ScenePlant {
  std::string grammar;                     // resolved path (empty if `skeleton` is given)
  std::optional<uint64_t> seed;            // overrides the grammar's seed
  std::optional<int64_t> steps;            // overrides the derivation length
  std::map<std::string, double> defines;   // -D overrides
  std::optional<Skeleton> skeleton;        // set by default_scene_for (no grammar to grow)
  glm::dvec3 position{0, 0, 0};
  double rotate_y_deg = 0;
  double scale = 1;
  Bark bark;
  SourceLoc grammar_loc = {};              // where the scene file names the grammar ({0,0}:
                                           //   not read from a file); grow_scene_plants' note
  uint32_t scatter = 0;                    // k + 1: placed by scatter[k] (written as that
                                           //   entry, not as a plant); 0: one of `plants`
  SkinStyle skin = SkinStyle::smooth;      // its own `skin` key, else its scatter entry's,
                                           //   else the scene's (docs/spec/scene.md "Skin")
  bool operator==(const ScenePlant&) const = default;
};

// A `scatter` entry (docs/scatter.md): many plants of one grammar placed at once over an
// area of the ground — `count` of them (or `density` per m²), at least `min_spacing` apart
// (Poisson-disc dart throwing), each turned and scaled at random within its ranges and
// grown with its own grammar seed. The reader places them (core/scene/scatter.h) and appends
// them to Scene::plants after the scene's own, so everything downstream sees plants;
// instances with equal grammar, seed, steps and defines are derived once
// (grow_scene_plants). Deterministic: the same entry places the same plants everywhere.
struct SceneScatter {
  std::string grammar;                     // resolved path
  std::optional<int64_t> steps;
  std::map<std::string, double> defines;
  Bark bark;
  uint64_t count = 0;                      // plants placed (from `density` when that is given)
  std::optional<double> density;           // plants per m², as the file says
  std::optional<glm::dvec2> disc_centre;   // the area: a disc (x, z) with disc_radius ...
  double disc_radius = 0;
  double disc_fade = 0;                    // metres inside the disc's rim over which the
                                           //   density falls linearly to 0 (0: a hard edge)
  std::vector<glm::dvec2> polygon;         // ... or a simple polygon (x, z), >= 3 corners
  uint64_t seed = 0;                       // the placement's random stream
  std::optional<std::pair<uint64_t, uint64_t>> plant_seeds;  // each instance's grammar seed
                                           //   drawn from [first, last]; none: its own
  double rotate_min_deg = 0, rotate_max_deg = 360;
  double scale_min = 1, scale_max = 1;
  double min_spacing = 0;                  // metres between any two plants' positions
  std::optional<SkinStyle> skin;           // its `skin` key; none: the scene's
  SourceLoc grammar_loc = {};
  bool operator==(const SceneScatter&) const = default;
};
// The most plants one scatter entry places (docs/limits.md).
inline constexpr uint64_t kMaxScatterPlants = 1'000'000;

struct Scene {
  Camera camera;
  uint32_t width = 1024;
  uint32_t height = 768;
  Sun sun;
  glm::dvec3 sky{0.25, 0.3, 0.4};  // uniform sky radiance, linear RGB
  Ground ground;
  std::optional<Fog> fog;          // none: no fog pass
  std::optional<LightEnvironment> environment;  // none: the defaults (light.md), for ?E only
  std::optional<SceneAnimation> animation;  // none: the plants stand still
  std::map<uint32_t, SceneMaterial> materials;  // by material index (< kMaterialSlots)
  std::vector<ScenePlant> plants;  // the scene's own, then every scatter entry's, in order
  std::vector<SceneScatter> scatter;
  SkinStyle skin = SkinStyle::smooth;  // the `skin` key: every plant's that names none
  std::string file = {};           // the file it was read from, for messages ("" if made
                                   //   in code); like ScenePlant::grammar_loc, a place, not
                                   //   part of what the scene describes (not written)
  std::shared_ptr<const void> files_held = {};  // keeps alive files the paths above name
                                   //   that exist only while the scene does (a glTF's
                                   //   images written out for the renderers); not written
  bool operator==(const Scene&) const = default;  // field by field, places included
};

// The unit sun direction a scene file's `sun.direction` reads as: `toward_sun` normalised
// as the reader does it. Normalising is not idempotent in floating point, so a direction
// set in code (the studio's sun control) should go through this for the scene to write
// and read back exactly (write_scene_json). Precondition: toward_sun is not zero.
glm::dvec3 unit_sun_direction(const glm::dvec3& toward_sun);

// `--skin` (render, export, studio): every plant, scatter entry and the scene itself
// skinned by `style`, whatever their keys say.
void override_skin(Scene& scene, SkinStyle style);

// The skeleton of `plant` placed in the world: p' = position + R_y(rotate_y_deg)·(scale·p),
// radii scaled. Precondition: plant.skeleton is set.
Skeleton place_plant(const ScenePlant& plant);
// One point of the plant's frame placed the same way.
glm::dvec3 place_point(const ScenePlant& plant, const glm::dvec3& p);

// Camera framing a box for an image of width × height: a 3/4 view from the front right,
// 12° above the box centre's horizon (azimuth 35° from +Z toward +X), fov_y 35°, far
// enough that the box's bounding sphere fits the narrower field of view with 8% margin.
Camera framing_camera(const glm::dvec3& lo, const glm::dvec3& hi, uint32_t width,
                      uint32_t height);

// The scene a bare grammar or skeleton is rendered in (docs/spec/scene.md): the plant at the
// origin, the sun from (0.5, 1, 0.3), no fog, the ground at the skeleton's lowest point
// (or 0 if higher), and framing_camera around the skeleton's bounds.
Scene default_scene_for(const Skeleton& skeleton, uint32_t width = 1024, uint32_t height = 768);

// Why `skeleton`, placed at `position` and scaled by `scale` (rotated about y), reaches
// beyond kMaxCoordinateM (core/util/limits.h, docs/limits.md) — which neither renderer
// nor a glTF float accessor can represent — or nullopt. grow_scene_plants checks every
// plant, export_gltf every plant, the render front ends a lone skeleton.
std::optional<std::string> plant_extent_problem(const Skeleton& skeleton, const glm::dvec3& position = {0, 0, 0},
                                                double scale = 1);

}  // namespace sylva
