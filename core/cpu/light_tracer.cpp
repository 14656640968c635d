// light_tracer.cpp — sun and sky photons through the plants, and the light each sensor
// sphere receives (light_tracer.h).
#include "core/cpu/light_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <utility>

#include <glm/geometric.hpp>

#include "core/cpu/crotch_tracer.h"
#include "core/cpu/frustum_accel.h"
#include "core/cpu/leaf_tracer.h"
#include "core/geometry/closest_point.h"
#include "core/geometry/leaf_mesh.h"
#include "core/geometry/relief.h"
#include "core/geometry/skin.h"
#include "core/light/sky.h"
#include "core/util/clock.h"
#include "core/util/parallel.h"
#include "core/util/random.h"

namespace sylva {

namespace {

using glm::dvec3;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint64_t kChunk = 1u << 14;  // photons per work item
__extension__ using Int128 = __int128;

// ---- Geometry ------------------------------------------------------------------------

// The plants as one set of primitives: frusta 0..F-1, then leaves F + leaf_base[plant] + leaf.
struct LightScene {
  std::vector<Frustum> frusta;
  std::vector<uint32_t> leaf_base;  // per plant
  uint32_t primitives = 0;
  std::vector<Aabb> boxes;  // per primitive
  std::unique_ptr<const CrotchBalls> crotches;  // the blended crotches' fillets (null: none)
  std::optional<FrustumAccel> accel;            // the frusta, the fillets beside them
  std::unique_ptr<LeafTracer> leaves;
  Aabb bounds = empty_box();
};

std::unique_ptr<LightScene> build_light_scene(std::span<const Skeleton> plants, const SkinOptions& skin) {
  auto s = std::make_unique<LightScene>();
  LeafMesh mesh;
  uint64_t leaf_count = 0;
  std::vector<SkinnedSkeleton> skinned(plants.size());
  std::vector<std::vector<Crotch>> crotches(plants.size());
  parallel_for(plants.size(), 0, nullptr, [&](size_t p, unsigned) {
    skinned[p] = skin_skeleton(plants[p], skin);
    if (skin.blend_crotches) crotches[p] = find_crotches(plants[p], skinned[p].frusta);
  });
  std::vector<Crotch> all_crotches;
  for (uint32_t p = 0; p < plants.size(); ++p) {
    const uint32_t first = static_cast<uint32_t>(s->frusta.size());
    for (Crotch& c : crotches[p]) {  // by the scene's frustum index
      for (uint32_t& i : c.parent_frusta) i += first;
      for (uint32_t& i : c.lateral_frusta) i += first;
      all_crotches.push_back(std::move(c));
    }
    s->frusta.insert(s->frusta.end(), skinned[p].frusta.begin(), skinned[p].frusta.end());
    skinned[p] = {};
    append_leaves(mesh, plants[p], p);
    s->leaf_base.push_back(static_cast<uint32_t>(leaf_count));
    leaf_count += plants[p].leaves.size();
  }
  for (uint32_t& b : s->leaf_base) b += static_cast<uint32_t>(s->frusta.size());
  s->primitives = static_cast<uint32_t>(s->frusta.size() + leaf_count);
  s->boxes.resize(s->frusta.size());
  parallel_for((s->frusta.size() + 4095) / 4096, 0, nullptr, [&](size_t c, unsigned) {
    for (size_t i = c * 4096; i < std::min(s->frusta.size(), (c + 1) * 4096); ++i)
      s->boxes[i] = frustum_bounds(s->frusta[i].shape);
  });
  s->boxes.reserve(s->primitives);
  for (const Skeleton& plant : plants)
    for (const Leaf& leaf : plant.leaves) {
      Aabb box = empty_box();
      for (const auto& v : leaf.vertices_m) grow(box, dvec3(v[0], v[1], v[2]));
      s->boxes.push_back(box);
    }
  for (const Aabb& b : s->boxes) grow(s->bounds, b);
  if (!mesh.empty()) {
    s->leaves = std::make_unique<LeafTracer>(std::move(mesh), nullptr);
  }
  if (!all_crotches.empty()) {
    s->crotches = std::make_unique<CrotchBalls>(std::move(all_crotches), s->frusta);
    grow(s->bounds, s->crotches->all_bounds());
  }
  if (!s->frusta.empty()) s->accel.emplace(s->frusta, CustomFrusta{}, s->crotches.get());
  return s;
}

struct PrimitiveHit {
  double t = kInf;
  uint32_t primitive = 0;
  double t_after = kInf;  // where tracing resumes past it
};

// The nearest primitive along `ray` beyond t_min (stops at t_max).
PrimitiveHit nearest_primitive(const LightScene& s, const Ray& ray, double t_min, double t_max) {
  PrimitiveHit h;
  if (s.accel) {
    // A fillet in front of the frusta is named by its heavier group's frustum (a sensor
    // ignores it as it ignores that frustum); past it the photon resumes where the ray
    // leaves that frustum's solid, or just past the fillet.
    const BvhHit b = nearest_wood(*s.accel, s.crotches.get(), ray, t_min, t_max);
    if (b.hit_any()) {
      h.t = b.hit.t;
      h.primitive = b.frustum;
    }
  }
  if (s.leaves) {
    const SurfaceHit leaf = s.leaves->nearest_leaf(ray, t_min, std::min(h.t, t_max));
    if (leaf.hit()) {
      h.t = leaf.t;
      h.primitive = s.leaf_base[leaf.plant] + leaf.leaf;
      h.t_after = leaf.t + 1e-9 * (1 + std::abs(leaf.t));
      return h;
    }
  }
  if (h.t < kInf) {
    const SolidInterval solid = frustum_solid_interval(ray, s.frusta[h.primitive].shape, h.t, kInf);
    const double exit = solid.hit ? std::max(solid.t_exit, h.t) : h.t;
    h.t_after = exit + 1e-9 * (1 + std::abs(exit));
  }
  return h;
}

// ---- Sensors -------------------------------------------------------------------------

// A uniform grid over the sensors' spheres; each sensor listed in every cell its sphere's
// box overlaps. Cells are cubes of side h ≥ 2r, about one sensor per cell.
struct SensorGrid {
  dvec3 lo{0, 0, 0};
  double h = 1;
  int n[3] = {1, 1, 1};
  std::vector<uint32_t> start;  // per cell, into items (size cells + 1)
  std::vector<uint32_t> items;

  size_t cell(int x, int y, int z) const { return (static_cast<size_t>(z) * n[1] + y) * n[0] + x; }
  template <class F>
  void for_cells_in(const dvec3& a, const dvec3& b, F&& f) const {
    int l[3], u[3];
    for (int k = 0; k < 3; ++k) {
      l[k] = std::clamp(static_cast<int>(std::floor((a[k] - lo[k]) / h)), 0, n[k] - 1);
      u[k] = std::clamp(static_cast<int>(std::floor((b[k] - lo[k]) / h)), 0, n[k] - 1);
    }
    for (int z = l[2]; z <= u[2]; ++z)
      for (int y = l[1]; y <= u[1]; ++y)
        for (int x = l[0]; x <= u[0]; ++x) f(cell(x, y, z));
  }
};

constexpr double kCellScale = 0.5;  // cell side per sensor spacing (the grid only finds crossings now)

SensorGrid build_sensor_grid(std::span<const dvec3> sensors, double r) {
  SensorGrid g;
  Aabb box = empty_box();
  for (const dvec3& p : sensors) grow(box, p);
  box.lo -= dvec3(r), box.hi += dvec3(r);
  const dvec3 extent = box.hi - box.lo;
  const double volume = std::max(extent.x * extent.y * extent.z, 1e-30);
  g.h = std::max(2 * r, kCellScale * std::cbrt(volume / static_cast<double>(sensors.size())));
  for (int k = 0; k < 3; ++k) g.n[k] = std::clamp(static_cast<int>(std::ceil(extent[k] / g.h)), 1, 512);
  g.h = std::max({g.h, extent.x / g.n[0], extent.y / g.n[1], extent.z / g.n[2]});
  g.lo = box.lo;
  const size_t cells = static_cast<size_t>(g.n[0]) * g.n[1] * g.n[2];
  std::vector<uint32_t> count(cells + 1, 0);
  for (const dvec3& p : sensors) g.for_cells_in(p - dvec3(r), p + dvec3(r), [&](size_t c) { ++count[c + 1]; });
  for (size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
  g.start = count;
  g.items.resize(count[cells]);
  for (uint32_t s = 0; s < sensors.size(); ++s)
    g.for_cells_in(sensors[s] - dvec3(r), sensors[s] + dvec3(r), [&](size_t c) { g.items[count[c]++] = s; });
  return g;
}

// The sensors as one batch's parallel photons see them: their centres projected on the
// plane perpendicular to the batch's direction (coordinates along the frame's e0, e1
// about the emitter's centre), in a uniform 2D grid of about one sensor per cell, each
// sensor listed in every cell its disc of radius r overlaps. A photon's cell then holds
// every sensor it can cross. Rebuilt in place for each batch (its buffers kept).
struct DirectionMap {
  double lo[2] = {0, 0};
  double h = 1;
  int n[2] = {1, 1};
  std::vector<uint32_t> start, items;
  std::vector<glm::dvec2> uv;

  std::span<const uint32_t> at(double u, double v) const {
    const double x = std::floor((u - lo[0]) / h), y = std::floor((v - lo[1]) / h);
    if (!(x >= 0 && y >= 0 && x < n[0] && y < n[1])) return {};
    const size_t c = static_cast<size_t>(y) * static_cast<size_t>(n[0]) + static_cast<size_t>(x);
    return std::span<const uint32_t>(items).subspan(start[c], start[c + 1] - start[c]);
  }

  void build(std::span<const dvec3> sensors, const dvec3& centre, const AxisFrame& frame, double reach) {
    uv.resize(sensors.size());
    double a[2] = {kInf, kInf}, b[2] = {-kInf, -kInf};
    for (size_t s = 0; s < sensors.size(); ++s) {
      const dvec3 o = sensors[s] - centre;
      uv[s] = {glm::dot(o, frame.e0), glm::dot(o, frame.e1)};
      for (int k = 0; k < 2; ++k) a[k] = std::min(a[k], uv[s][k] - reach), b[k] = std::max(b[k], uv[s][k] + reach);
    }
    const double area = std::max((b[0] - a[0]) * (b[1] - a[1]), 1e-30);
    h = std::max(reach, std::sqrt(area / static_cast<double>(sensors.size())));
    for (int k = 0; k < 2; ++k) {
      lo[k] = a[k];
      n[k] = std::clamp(static_cast<int>(std::ceil((b[k] - a[k]) / h)), 1, 4096);
    }
    h = std::max({h, (b[0] - a[0]) / n[0], (b[1] - a[1]) / n[1]});
    const size_t cells = static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]);
    start.assign(cells + 1, 0);
    auto for_cells = [&](const glm::dvec2& p, auto&& f) {
      const int x0 = std::clamp(static_cast<int>(std::floor((p.x - reach - lo[0]) / h)), 0, n[0] - 1);
      const int x1 = std::clamp(static_cast<int>(std::floor((p.x + reach - lo[0]) / h)), 0, n[0] - 1);
      const int y0 = std::clamp(static_cast<int>(std::floor((p.y - reach - lo[1]) / h)), 0, n[1] - 1);
      const int y1 = std::clamp(static_cast<int>(std::floor((p.y + reach - lo[1]) / h)), 0, n[1] - 1);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) f(static_cast<size_t>(y) * static_cast<size_t>(n[0]) + static_cast<size_t>(x));
    };
    for (const glm::dvec2& p : uv) for_cells(p, [&](size_t c) { ++start[c + 1]; });
    for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    items.resize(start[cells]);
    std::vector<uint32_t>& fill = scratch;
    fill.assign(start.begin(), start.end() - 1);
    for (uint32_t s = 0; s < uv.size(); ++s) for_cells(uv[s], [&](size_t c) { items[fill[c]++] = s; });
  }

 private:
  std::vector<uint32_t> scratch;
};

// Per sensor, the primitives that cross its sphere (sorted), as CSR.
struct Ignored {
  std::vector<uint32_t> start;
  std::vector<uint32_t> items;
  bool contains(uint32_t sensor, uint32_t primitive) const {
    return std::binary_search(items.begin() + start[sensor], items.begin() + start[sensor + 1], primitive);
  }
};

Ignored crossing_primitives(const LightScene& s, std::span<const Skeleton> plants, std::span<const dvec3> sensors,
                            const SensorGrid& grid, double r) {
  std::vector<std::vector<uint32_t>> per(sensors.size());
  // The frusta in chunks on every core, each chunk's (sensor, frustum) pairs kept apart and
  // appended in chunk order: the lists come out the same for any thread count.
  constexpr size_t kFrustumChunk = 8192;
  const size_t chunks = (s.frusta.size() + kFrustumChunk - 1) / kFrustumChunk;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> pairs(chunks);
  const unsigned workers = worker_count(0);
  std::vector<std::vector<uint32_t>> stamps(workers);
  parallel_for(chunks, workers, nullptr, [&](size_t chunk, unsigned worker) {
    std::vector<uint32_t>& stamp = stamps[worker];
    if (stamp.empty()) stamp.assign(sensors.size(), UINT32_MAX);
    for (uint32_t f = static_cast<uint32_t>(chunk * kFrustumChunk);
         f < std::min(s.frusta.size(), (chunk + 1) * kFrustumChunk); ++f) {
      const FrustumShape& sh = s.frusta[f].shape;
      const dvec3 a = sh.base, b = sh.base + sh.length * sh.axis;
      const double reach = r + std::max(sh.radius0, sh.radius1);
      grid.for_cells_in(glm::min(a, b) - dvec3(reach), glm::max(a, b) + dvec3(reach), [&](size_t c) {
        for (uint32_t k = grid.start[c]; k < grid.start[c + 1]; ++k) {
          const uint32_t sensor = grid.items[k];
          if (stamp[sensor] == f) continue;
          stamp[sensor] = f;
          if (point_segment_distance(sensors[sensor], a, b) <= reach) pairs[chunk].push_back({sensor, f});
        }
      });
    }
  });
  for (const auto& chunk : pairs)
    for (const auto& [sensor, f] : chunk) per[sensor].push_back(f);
  std::vector<uint32_t> stamp(sensors.size(), UINT32_MAX);
  for (uint32_t p = 0; p < plants.size(); ++p)
    for (uint32_t l = 0; l < plants[p].leaves.size(); ++l) {
      const auto& v = plants[p].leaves[l].vertices_m;
      if (v.size() < 3) continue;
      const uint32_t id = s.leaf_base[p] + l;
      Aabb box = empty_box();
      for (const auto& q : v) grow(box, dvec3(q[0], q[1], q[2]));
      grid.for_cells_in(box.lo - dvec3(r), box.hi + dvec3(r), [&](size_t c) {
        for (uint32_t k = grid.start[c]; k < grid.start[c + 1]; ++k) {
          const uint32_t sensor = grid.items[k];
          if (stamp[sensor] == id) continue;
          stamp[sensor] = id;
          // The polygon as a fan from its first vertex: a leaf is planar (the turtle
          // checks), so the fan covers it when it is convex, and its outline otherwise.
          const dvec3 v0(v[0][0], v[0][1], v[0][2]);
          for (size_t i = 1; i + 1 < v.size(); ++i) {
            const dvec3 v1(v[i][0], v[i][1], v[i][2]), v2(v[i + 1][0], v[i + 1][1], v[i + 1][2]);
            if (point_triangle_distance(sensors[sensor], v0, v1, v2) <= r) {
              per[sensor].push_back(id);
              break;
            }
          }
        }
      });
    }
  Ignored out;
  out.start.assign(sensors.size() + 1, 0);
  for (size_t i = 0; i < sensors.size(); ++i) {
    std::sort(per[i].begin(), per[i].end());
    out.start[i + 1] = out.start[i] + static_cast<uint32_t>(per[i].size());
  }
  out.items.reserve(out.start.back());
  for (const auto& p : per) out.items.insert(out.items.end(), p.begin(), p.end());
  return out;
}

// The chord of `ray` (unit direction) through the sphere (c, r): [a, b], or a > b when
// it misses. Re-centred: h is the offset of the ray's nearest point from c.
bool sphere_chord(const Ray& ray, const dvec3& c, double r, double* a, double* b) {
  const dvec3 oc = ray.origin - c;
  const double tc = -glm::dot(oc, ray.direction);
  const dvec3 h = oc + tc * ray.direction;
  const double disc = r * r - glm::dot(h, h);
  if (disc <= 0) return false;
  const double half = std::sqrt(disc);
  *a = tc - half;
  *b = tc + half;
  return true;
}

// ---- Photons -------------------------------------------------------------------------

// Where a photon's light comes from: the sun's share and the sky's shape (sky.h).
struct LightSource {
  double sun_share = 1;  // probability that a photon comes from the sun
  SkyShape shape = SkyShape::uniform;
  dvec3 to_sun{0, 1, 0};
  AxisFrame sun_frame;
  double one_minus_cos_alpha = 0;
};

LightSource light_source(const Scene& scene) {
  const LightEnvironment env = scene.environment.value_or(LightEnvironment{});
  LightSource s;
  s.to_sun = glm::normalize(scene.sun.direction);
  s.sun_frame = axis_frame(s.to_sun);
  s.one_minus_cos_alpha = 2 * std::pow(std::sin(0.5 * scene.sun.angular_radius_deg * std::numbers::pi / 180), 2);
  s.shape = env.sky == LightSky::overcast || env.sky == LightSky::sun_overcast ? SkyShape::overcast : SkyShape::uniform;
  switch (env.sky) {
    case LightSky::sun: s.sun_share = s.to_sun.y > 0 ? 1 : 0; break;
    case LightSky::uniform:
    case LightSky::overcast: s.sun_share = 0; break;
    case LightSky::sun_uniform:
    case LightSky::sun_overcast: s.sun_share = sun_scalar_share(env.sun_fraction, s.to_sun.y, s.shape); break;
  }
  return s;
}

// The unit direction toward the light of one photon, from its stream.
dvec3 photon_toward(const LightSource& src, Rng& rng) {
  if (rng.next_double() < src.sun_share) {
    // Uniform over the sun's disc: 1 − cos θ uniform in [0, 1 − cos α].
    const double one_minus_cos = rng.next_double() * src.one_minus_cos_alpha;
    const double cos_t = 1 - one_minus_cos;
    const double sin_t = std::sqrt(std::max(0.0, one_minus_cos * (2 - one_minus_cos)));
    const double phi = 2 * std::numbers::pi * rng.next_double();
    return glm::normalize(cos_t * src.to_sun +
                          sin_t * (std::cos(phi) * src.sun_frame.e0 + std::sin(phi) * src.sun_frame.e1));
  }
  const double u = rng.next_double(), v = rng.next_double();
  return sky_sample_direction(src.shape, u, v);
}

// Fixed-point units of track length: 2^24 per sensor diameter.
struct Accumulator {
  std::vector<int64_t> track;   // Σ ℓ
  std::vector<Int128> square;   // Σ ℓ²
  std::vector<int64_t> dir;     // Σ ℓ·ω, 3 per sensor
  std::vector<uint64_t> stamp;  // the last photon that visited the sensor (+1)
  explicit Accumulator(size_t n) : track(n, 0), square(n, 0), dir(3 * n, 0), stamp(n, 0) {}
};

}  // namespace

Expected<std::vector<LightAnswer>> PhotonLightOracle::answer(std::span<const Skeleton> plants,
                                                              std::span<const dvec3> sensors, const Scene& scene,
                                                              int64_t step, LightAnswerStats* stats) const {
  const Clock::time_point wall0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  const LightEnvironment env = scene.environment.value_or(LightEnvironment{});
  std::vector<LightAnswer> out(sensors.size());
  if (sensors.empty()) return out;
  const double r = env.sensor_radius_m;
  const LightSource src = light_source(scene);
  const std::unique_ptr<LightScene> geometry = build_light_scene(plants, skin_.styled(scene.skin));
  Aabb box = geometry->bounds;
  for (const dvec3& p : sensors) grow(box, p);
  box.lo -= dvec3(r), box.hi += dvec3(r);
  const dvec3 centre = 0.5 * (box.lo + box.hi);
  const double big_r = 0.5 * glm::length(box.hi - box.lo) * (1 + 1e-9) + 1e-9;
  const SensorGrid grid = build_sensor_grid(sensors, r);
  const Ignored ignored = crossing_primitives(*geometry, plants, sensors, grid, r);
  const double build_seconds = seconds_since(wall0);
  const double ground = scene.ground.height;
  const double unit = static_cast<double>(1 << 24) / (2 * r);  // fixed-point units per metre
  const unsigned workers = worker_count(threads_);
  std::vector<Accumulator> acc;
  acc.reserve(workers);
  for (unsigned w = 0; w < workers; ++w) acc.emplace_back(sensors.size());
  const uint64_t n = src.sun_share > 0 || env.sky != LightSky::sun ? env.photons : 0;
  const uint64_t stream = mix_pair(mix_pair(env.seed, 0x6c69676874ULL), static_cast<uint64_t>(step));
  // The directions: K batches of parallel photons (see the header comment), K_sun of them
  // from the sun's disc (K·s rounded by a uniform draw: unbiased), the rest from the sky;
  // each set spread by the R2 sequence from a random start.
  const uint64_t batches = n == 0 ? 0 : std::clamp<uint64_t>(std::llround(std::sqrt(static_cast<double>(n)) / 4), 1, 4096);
  Rng split(mix_pair(stream, 0x73706c6974ULL));
  const uint64_t sun_batches = std::min<uint64_t>(
      batches, static_cast<uint64_t>(std::floor(static_cast<double>(batches) * src.sun_share + split.next_double())));
  const uint64_t r2_offset0 = split.next_u64(), r2_offset1 = split.next_u64();
  auto batch_toward = [&](uint64_t b) {
    const bool sun = b < sun_batches;
    const uint64_t k = sun ? b : b - sun_batches;
    const double u = unit_from_fixed(r2_offset0 + k * kR2Step0), v = unit_from_fixed(r2_offset1 + k * kR2Step1);
    if (!sun) return sky_sample_direction(src.shape, u, v);
    const double one_minus_cos = u * src.one_minus_cos_alpha;
    const double sin_t = std::sqrt(std::max(0.0, one_minus_cos * (2 - one_minus_cos)));
    const double phi = 2 * std::numbers::pi * v;
    return glm::normalize((1 - one_minus_cos) * src.to_sun +
                          sin_t * (std::cos(phi) * src.sun_frame.e0 + std::sin(phi) * src.sun_frame.e1));
  };
  std::vector<DirectionMap> maps(workers);
  parallel_for(batches, workers, nullptr, [&](size_t b, unsigned worker) {
    Accumulator& a = acc[worker];
    DirectionMap& map = maps[worker];
    const dvec3 toward = batch_toward(b);
    const AxisFrame f = axis_frame(toward);
    map.build(sensors, centre, f, r);
    std::vector<PrimitiveHit> hits;
    const uint64_t first = b * (n / batches) + std::min<uint64_t>(b, n % batches);
    const uint64_t count = n / batches + (b < n % batches ? 1 : 0);
    for (uint64_t i = first; i < first + count; ++i) {
      Rng rng(mix_pair(stream, i));
      // A uniform point of the disc of radius R perpendicular to the batch's direction.
      const double rad = big_r * std::sqrt(rng.next_double()), phi = 2 * std::numbers::pi * rng.next_double();
      const double pu = rad * std::cos(phi), pv = rad * std::sin(phi);
      const std::span<const uint32_t> near = map.at(pu, pv);
      if (near.empty()) continue;
      Ray ray;
      ray.origin = centre + big_r * toward + pu * f.e0 + pv * f.e1;
      ray.direction = -toward;
      // The track ends at the ground (light from below the horizon never arrives).
      double t_end = 2 * big_r;
      if (ray.direction.y < 0) t_end = std::min(t_end, (ground - ray.origin.y) / ray.direction.y);
      if (!(t_end > 0)) continue;
      hits.clear();
      auto hit = [&](size_t k) -> const PrimitiveHit& {
        while (hits.size() <= k) {
          const double from = hits.empty() ? 0.0 : hits.back().t_after;
          if (!hits.empty() && hits.back().t == kInf) return hits.back();
          hits.push_back(from < t_end ? nearest_primitive(*geometry, ray, from, t_end) : PrimitiveHit{});
        }
        return hits[k];
      };
      for (const uint32_t s : near) {
        // The track in sensor s: from where the photon enters the sphere to where it leaves
        // it or meets the first surface s does not ignore.
        double lo_t, hi_t;
        if (!sphere_chord(ray, sensors[s], r, &lo_t, &hi_t)) continue;
        lo_t = std::max(lo_t, 0.0), hi_t = std::min(hi_t, t_end);
        if (!(hi_t > lo_t)) continue;
        double stop = hi_t;
        for (size_t j = 0; j < static_cast<size_t>(kMaxLightHitsPerPhoton); ++j) {
          const PrimitiveHit& h = hit(j);
          if (h.t >= hi_t) break;
          if (!ignored.contains(s, h.primitive)) {
            stop = h.t;
            break;
          }
          if (j + 1 == static_cast<size_t>(kMaxLightHitsPerPhoton)) stop = h.t;  // give up: treat as blocked
        }
        if (!(stop > lo_t)) continue;
        const int64_t q = std::llround((stop - lo_t) * unit);
        a.track[s] += q;
        a.square[s] += static_cast<Int128>(q) * q;
        for (int d = 0; d < 3; ++d) a.dir[3 * s + d] += std::llround(static_cast<double>(q) * toward[d]);
      }
    }
  });
  // The expected track per photon with no obstacle: (4/3)πr³ / (πR²), in fixed point.
  const double expected = (4.0 / 3.0) * r * r * r / (big_r * big_r) * unit;
  double rel_sum = 0;
  uint64_t rel_count = 0;
  for (size_t s = 0; s < sensors.size(); ++s) {
    Int128 track = 0, square = 0, dir[3] = {0, 0, 0};
    for (const Accumulator& a : acc) {
      track += a.track[s], square += a.square[s];
      for (int d = 0; d < 3; ++d) dir[d] += a.dir[3 * s + d];
    }
    LightAnswer& ans = out[s];
    if (n == 0) continue;
    const double nn = static_cast<double>(n);
    const double mean = static_cast<double>(track) / nn;  // per photon, fixed point
    ans.q = mean / expected;
    const double var = n > 1 ? std::max(0.0, (static_cast<double>(square) / nn - mean * mean) / (nn - 1)) : 0.0;
    ans.std_error = std::sqrt(var) / expected;
    const dvec3 v(static_cast<double>(dir[0]), static_cast<double>(dir[1]), static_cast<double>(dir[2]));
    const double len = glm::length(v);
    if (track > 0 && len > 0) ans.toward = v / len;
    if (ans.q > 0) rel_sum += ans.std_error / ans.q, ++rel_count;
  }
  if (stats) {
    stats->photons = n;
    stats->sensors = sensors.size();
    stats->seconds = seconds_since(wall0);
    stats->build_seconds = build_seconds;
    stats->cpu_seconds = process_cpu_seconds() - cpu0;
    stats->mean_relative_error = rel_count ? rel_sum / static_cast<double>(rel_count) : 0;
  }
  return out;
}

Expected<std::vector<LightAnswer>> gather_light(std::span<const Skeleton> plants, std::span<const dvec3> sensors,
                                                const Scene& scene, int64_t step, uint64_t rays,
                                                const SkinOptions& skin) {
  const LightEnvironment env = scene.environment.value_or(LightEnvironment{});
  std::vector<LightAnswer> out(sensors.size());
  if (sensors.empty() || rays == 0) return out;
  const double r = env.sensor_radius_m;
  const LightSource src = light_source(scene);
  const std::unique_ptr<LightScene> geometry = build_light_scene(plants, skin.styled(scene.skin));
  const SensorGrid grid = build_sensor_grid(sensors, r);
  const Ignored ignored = crossing_primitives(*geometry, plants, sensors, grid, r);
  const bool any_light = src.sun_share > 0 || env.sky != LightSky::sun;
  const uint64_t stream = mix_pair(mix_pair(env.seed, 0x676174686572ULL), static_cast<uint64_t>(step));
  parallel_for(sensors.size(), 0, nullptr, [&](size_t s, unsigned) {
    uint64_t open = 0;
    dvec3 dir(0);
    for (uint64_t k = 0; any_light && k < rays; ++k) {
      Rng rng(mix_pair(mix_pair(stream, s), k));
      const dvec3 toward = photon_toward(src, rng);
      if (toward.y <= 0) continue;  // the ground
      const Ray ray{sensors[s], toward};
      double from = 0;
      bool blocked = false;
      for (int j = 0; j < kMaxLightHitsPerPhoton; ++j) {
        const PrimitiveHit h = nearest_primitive(*geometry, ray, from, kInf);
        if (h.t == kInf) break;
        if (!ignored.contains(static_cast<uint32_t>(s), h.primitive) || j + 1 == kMaxLightHitsPerPhoton) {
          blocked = true;
          break;
        }
        from = h.t_after;
      }
      if (!blocked) ++open, dir += toward;
    }
    LightAnswer& a = out[s];
    const double p = static_cast<double>(open) / static_cast<double>(rays);
    a.q = p;
    a.std_error = std::sqrt(p * (1 - p) / static_cast<double>(rays));
    if (open) a.toward = glm::normalize(dir);
  });
  return out;
}

}  // namespace sylva
