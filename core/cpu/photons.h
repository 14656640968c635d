// photons.h — sun photons and the shadow cones made from them (Hougs and Day 2001 sec. 3.1–3.2,
// 6.1): the viewpoint-independent half of the fog (docs/spec/fog.md, "Photons and
// cones"), built once per (plants, sun) and reused by every camera, frame and fog mode.
//
// Photons leave a disc perpendicular to the sun that covers the plants' bounding sphere
// for every direction of the sun's disc: centred on the sphere's sunward tangent plane,
// radius R·(1 + 2·tan α)/cos α for a sphere of radius R and a sun of angular radius α.
// Positions: the R2 low-discrepancy sequence (Roberts 2018, the plastic number's
// additive recurrence) rotated by the seed (Cranley–Patterson) and mapped to the disc by
// the concentric map (Shirley & Chiu 1997), so shadow vectors come out evenly spread
// instead of Poisson-clumped: the sector test of the clustering sees the occluder's
// edges, not the emitter's noise. Directions: uniform over the sun's disc (cos θ uniform
// in [cos α, 1], 1 − cos θ drawn as u·2·sin²(α/2): 1 − cos α in double would keep only
// ~11 of its 16 digits at the sun's 4.7 mrad). Photon i's numbers depend only on
// (seed, i), so the result is the same for every thread count.
//
// Each photon is traced through the plants' exact frusta (Embree, frustum_accel.h; no
// relief: the shadow of a bark relief a centimetre deep is below the cones' resolution).
// At the first frustum it hits it leaves a shadow vector where it exits that frustum's
// solid (frustum_solid_interval; Fig. 2b: on the occluder's far side), with its
// direction and the frustum's index. Photons that hit nothing leave nothing.
// Leaves (docs/leaves.md) stop photons too: a photon whose first hit is a leaf leaves its
// vector at the hit point (a leaf has no thickness, so its far side is where the photon
// meets it), naming the first frustum of the leaf's plant.
// Blended crotches (SceneGeometry::crotches, crotch_tracer.h) stop photons as the frusta
// do: their balls are extra primitives of the same Embree scene, and a fillet in front of
// the frusta's hit is the photon's first hit, named by the fillet's heavier group's
// frustum, the vector where the photon leaves that frustum's solid (at the fillet's hit
// where it misses it). The occupancy mask and the emitter cover the balls.
//
// Instances (SceneGeometry::instances, build_instanced_geometry): the photons go through
// the same InstanceTracer construction the renderer uses (instance_tracer.h), over
// prototypes of exact frusta and leaves in each skeleton's frame (the double ray taken to
// the frame, the hit back), with the plants skinned in the world one more prototype at the
// identity. The exit point is found on the frustum placed in the world (its shape through
// the plant's transform), and the emitter, the mask and the vectors are what the
// non-instanced path makes of the same plants, up to the rounding of the transforms.
// A vector's frustum then indexes the tracer's frustum space (plant_of_frustum()): first
// SceneGeometry::frusta (the plants skinned in the world, same indices), then each
// instance's block of its prototype's frusta, in SceneGeometry::instances order — instance
// i's frustum f is first_frustum(i) + f. The clustering keeps plants apart by that index's
// plant; no frustum is copied per plant (4 bytes of plant index per placed frustum).
//
// Units and frames: world space, metres, Y up; the vectors' float positions are
// relative to the bounding sphere's centre (ShadowVectors::origin).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/cpu/render_cpu.h"  // SceneGeometry
#include "core/scene/fog_integrator.h"  // FogConeSource
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "core/light/shadow_cones.h"
#include "core/geometry/skin.h"
#include "core/geometry/surface.h"

namespace sylva {

class LeafTracer;   // leaf_tracer.h
class CrotchBalls;  // crotch_tracer.h

struct SunPhotonOptions {
  uint64_t photons = 1'000'000;             // photons emitted, >= 0
  uint64_t seed = 0;                        // the sequence's rotation and the directions' stream
  unsigned threads = 0;                     // 0: every core
  const std::atomic<bool>* cancel = nullptr;  // set to stop early (the result says so)
  bool occupancy_mask = true;  // skip photons the sun-frame mask proves to miss (false:
                               // trace every photon; the vectors are the same, tested)
};

// The emitter of a set of frusta under a sun.
struct SunEmitter {
  glm::dvec3 centre{0, 0, 0};     // the plants' bounding sphere
  double sphere_radius_m = 0;
  glm::dvec3 to_sun{0, 1, 0};     // unit, toward the sun's centre
  double sun_radius_rad = 0;      // α
  glm::dvec3 disc_centre{0, 0, 0};
  double disc_radius_m = 0;
};

// The emitter for `frusta` (empty: a zero sphere) and, with frusta, the box `leaves` of
// their plants' leaves (empty_box(): none) under `sun`.
SunEmitter sun_emitter(std::span<const Frustum> frusta, const Sun& sun, const Aabb& leaves = empty_box());

struct SunPhotons {
  ShadowVectors vectors;  // in photon order; origin = the emitter's sphere centre
  SunEmitter emitter;
  uint64_t traced = 0;    // photons traced (== options.photons unless cancelled)
  double seconds = 0;     // wall time of the tracing (not the accelerator's build)
  double cpu_seconds = 0; // CPU time of the tracing summed over its threads (core-seconds:
                          // photons per second per core = traced / cpu_seconds, a rate
                          // that other processes on the machine disturb less than wall time)
  double build_seconds = 0;  // the accelerator's and the mask's build
  bool cancelled = false;
};

// The plants as the sun's photons see them, built once per (plants, sun) and reused by
// every trace (seeds, photon counts): Embree over the exact frusta (frustum_accel.h) and
// the sun-frame occupancy mask (photons.cpp), built on `threads` threads (0: every
// core). `frusta` must outlive it, unchanged. Thread-safe (const).
class SunPhotonTracer {
 public:
  // `leaves` (optional, outliving the tracer): the scene's leaves, which stop photons too
  // (see the header comment); `plant_of_frustum` names each frustum's plant (a leaf's
  // vectors carry the first frustum of its plant; a plant without frusta leaves none).
  // `crotches` (optional, over `frusta`, outliving the tracer): the blended crotches'
  // fillets, which stop photons as the frusta do (a vector where the photon leaves the
  // solid of the frustum the fillet hit names, crotch_tracer.h, or at the hit where the
  // photon misses that solid).
  SunPhotonTracer(std::span<const Frustum> frusta, const Sun& sun, unsigned threads = 0,
                  const LeafTracer* leaves = nullptr, std::span<const uint32_t> plant_of_frustum = {},
                  const CrotchBalls* crotches = nullptr);
  // Over everything `geometry` holds (outliving the tracer, unchanged): its frusta and
  // leaves, and its instances when build_instanced_geometry made it (see the header
  // comment). Throws std::runtime_error when Embree fails.
  SunPhotonTracer(const SceneGeometry& geometry, const Sun& sun, unsigned threads = 0);
  ~SunPhotonTracer();
  SunPhotonTracer(const SunPhotonTracer&) = delete;
  SunPhotonTracer& operator=(const SunPhotonTracer&) = delete;

  // options.photons sun photons (see the header comment); build_seconds is left 0.
  SunPhotons trace(const SunPhotonOptions& options) const;
  // Whether a frustum blocks the sun's centre from `point` (an exact shadow ray).
  bool toward_sun_blocked(const glm::dvec3& point) const;
  // The distance along `ray` (direction unit, pointing away from the sun within its disc,
  // origin on the sunward side of the emitter's sphere) to the first plant surface a
  // photon would stop at — frustum or leaf, as trace() sees them — or +inf when it meets
  // none (the occupancy mask answers most misses without a traversal).
  double first_hit(const Ray& ray) const;
  const SunEmitter& emitter() const;
  double build_seconds() const;  // the accelerator's and the mask's
  std::span<const Frustum> frusta() const;  // the frusta skinned in the world
  // The plant of each index a shadow vector may name (the constructor's plant_of_frustum,
  // or with instances the frustum space of the header comment).
  std::span<const uint32_t> plant_of_frustum() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// SunPhotonTracer(frusta, sun).trace(options), with build_seconds set.
SunPhotons trace_sun_photons(std::span<const Frustum> frusta, const Sun& sun, const SunPhotonOptions& options);

// ---- Automatic cone parameters (sec. 6.1) ----------------------------------------------
//
// The paper chose p1..p4 by hand and left their automatic choice as future work. Here
// they are chosen by measurement at the photons' own density: on a square window of the
// emitter plane around the vectors' median, holding about 8000 of them (the density is
// the full one, so the choice holds for all), candidates are clustered and each is
// measured on random points of the window's shadow region (ConeCoverage); a coordinate
// descent over a grid (p3 ∈ {6..32} vectors per ring, p2 ∈ {4..16} sectors, threshold
// ∈ {1.25..6}, p4 ∈ {p3/2, p3, 2·p3}, p1 = 5·p3 + 1) starting from (16, 8, 2.5, p3)
// moves to the best neighbour while it gains more than the measurement's noise. Every
// candidate's K is a prefix of the largest, so neighbours are found once.

// How well a cone set matches the exact shadow, measured on random points of the
// plants' shadow region (uniform in the bounding sphere's sweep along the sun, from its
// sunward tangent plane to 2R beyond its far side or the ground), each classified by an
// exact shadow ray toward the sun's centre.
struct ConeCoverage {
  uint64_t points = 0;             // sample points
  uint64_t shadowed = 0;           // of them in the exact shadow
  double missed_shadow = 0;        // shadowed points outside every cone / shadowed points
  double covered_lit = 0;          // lit points inside a cone / shadowed points
  // What the automatic choice minimises: the symmetric difference of the cones and the
  // shadow over the shadow's volume, the miss counted miss_weight times.
  double error(double miss_weight = 1) const { return miss_weight * missed_shadow + covered_lit; }
};

// One candidate of the automatic choice and what it measured.
struct ConeCandidate {
  ConeParams params;
  ConeCoverage coverage;
  uint64_t cones = 0;
};

// What the automatic choice did (--verbose prints it).
struct AutoConeReport {
  double density_per_m2 = 0;   // shadow vectors per m² of the emitter disc that hit
  double spacing_m = 0;        // their mean spacing, 1/sqrt(density)
  uint64_t window_vectors = 0; // vectors in the trial window the candidates were tried on
  double miss_weight = 1;      // the error's weight of missed shadow (SunConeOptions)
  std::vector<ConeCandidate> candidates;  // in the order tried
  size_t chosen = 0;           // index into candidates
  double seconds = 0;
  std::string describe() const;  // a few lines: density, each candidate, the choice
};

// ---- Photons and cones, once per (plants, sun) -----------------------------------------

struct SunConeOptions {
  SunPhotonOptions photons;
  std::optional<ConeParams> params;  // nullopt: automatic (sec. 6.1)
  double miss_weight = 1;            // automatic: the weight of missed shadow against covered
                                     // lit space (> 1 favours covering: medium and refined
                                     // modes pay a miss in bias but a cover only in time)
  uint64_t coverage_points = 20000;  // points of the final coverage measurement (0: none)
};

// Everything the fog integrator reads (through `cones`) and what it cost.
struct SunCones {
  ShadowVectors vectors;
  ConeSet cones;
  ConeParams params;                   // the parameters used
  ConeLimits limits;                   // where the cones end
  ClusterReport cluster;
  std::optional<AutoConeReport> automatic;  // set when the parameters were chosen
  std::optional<ConeCoverage> coverage;     // of the final set (coverage_points > 0)
  SunEmitter emitter;
  uint64_t photons = 0;
  double photon_seconds = 0;  // tracing (and the accelerator's build), wall
  double cone_seconds = 0;    // clustering, the choice, the hierarchy, the coverage, wall
  double coverage_seconds = 0;  // of cone_seconds: the final coverage measurement (a
                                // report, which rendering does not need), wall
  // The same in CPU time of the process (core-seconds, every thread).
  double photon_cpu_seconds = 0, cone_cpu_seconds = 0, coverage_cpu_seconds = 0;
  bool cancelled = false;
  std::vector<RenderPass> passes;  // "photons", "cone params", "cones", "cone coverage"
};

// Traces the photons of `scene`'s sun through `geometry`'s frusta and clusters their
// shadow vectors into cones ending at scene.ground (the length limit: the bounding
// sphere's sweep, 2R beyond its far side or to the ground). A sun at or below the
// horizon (no sunlight reaches the fog) traces nothing and gives no cones. `tracer`, when
// given, must be built over `geometry` (SunPhotonTracer(geometry, sun)) and scene.sun
// (several photon counts or seeds then share its build); null: one is built here (its
// build counted in photon_seconds). Instanced geometry's plants cast their photons
// through their instances (see the header comment).
std::unique_ptr<const SunCones> build_sun_cones(const SceneGeometry& geometry, const Scene& scene,
                                                const SunConeOptions& options,
                                                const SunPhotonTracer* tracer = nullptr);

// What the fog needs of photons and cones for a render (docs/spec/fog.md's modes): whether
// `mode` reads shadow cones (medium, fast, refined; resolve auto first: cpu_fog_mode, or the
// GL backend's) and the
// options of build_sun_cones for it — `photons` sun photons (seeded by `seed`), the
// clustering parameters p1..p4 given, or automatic (nullopt), the automatic choice
// weighing a missed shadow 4× a covered lit point for medium and refined (a miss costs them
// bias, a cover only shadow rays) and 1× for fast (both cost it bias).
bool fog_mode_needs_cones(FogMode mode);
SunConeOptions sun_cone_options_for(FogMode mode, uint64_t photons, const std::optional<std::array<uint32_t, 4>>& params,
                                    unsigned threads, const std::atomic<bool>* cancel, uint64_t seed = 0);

}  // namespace sylva
