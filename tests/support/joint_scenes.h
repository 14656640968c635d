// joint_scenes.h — close-ups of branch joints and elbows (docs/joints.md) and the
// measure of their surface's defects, shared by the CPU test (tests/cpu/render_joints_
// test.cpp) and the GL one (tests/gl/render_gl_joints_test.cpp).
//
// A rim, a lip or a radius step is a convex crease: a line across which the surface
// turns outward by a large angle (90° at a flat cap's edge), and so is the facet line of
// a mitred elbow (the bend angle, on the outer side). Where two solids join — a branch
// leaving its parent — the crease is concave, as a branch crotch is. So the measure is the
// largest convex turn of the surface between points 4 pixels apart, both on one
// continuous piece of surface seen not too obliquely and away from the outline, with the surface's normals taken
// from the depth field (so the shading normal's smoothing, Bhagvat et al. 2009 eq. 8, cannot hide a
// facet) and, separately, from the normal AOV (what shading sees).
#pragma once

#include "core/geometry/crotch.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry/skin.h"
#include "tests/support/skeleton_builder.h"
#include "tests/support/test_textures.h"
#include "core/scene/render_common.h"
#include "core/scene/render_types.h"
#include "core/scene/scene.h"
#include "core/util/math.h"

namespace sylva::test {

struct JointCloseUp {
  std::string name;
  Scene scene;
};

inline Scene close_up(const Skeleton& sk, glm::dvec3 eye, glm::dvec3 target, double fov_y_deg) {
  Scene s;
  s.width = 200;
  s.height = 150;
  s.camera = Camera{eye, target, {0, 1, 0}, fov_y_deg};
  s.ground.height = -100;
  s.sun.angular_radius_deg = 0;
  ScenePlant plant;
  plant.skeleton = sk;
  s.plants.push_back(plant);
  return s;
}

// The close-ups: an elm-like crown (three limbs from the end of the trunk), an axis that
// goes on thinner past a branch, a lateral at 45° from the side of its parent, the elm's
// first fork (the axis goes on bent, a limb leaves beside it), and a 60° elbow seen from
// its outer side.
inline std::vector<JointCloseUp> joint_close_ups() {
  std::vector<JointCloseUp> out;
  {
    Skeleton sk;
    add_chain(sk, {{0, 0, 0}, {0, 2, 0}}, {0.3, 0.28}, std::nullopt);
    for (int k = 0; k < 3; ++k) {
      const double az = 2 * kPi * k / 3 + 0.3, tilt = 25 * kPi / 180;
      const glm::dvec3 d{std::sin(tilt) * std::cos(az), std::cos(tilt), std::sin(tilt) * std::sin(az)};
      add_chain(sk, {{0, 2, 0}, glm::dvec3(0, 2, 0) + 1.4 * d}, {0.22, 0.18}, ChainParent{0, 1});
    }
    out.push_back({"crown", close_up(sk, {2.2, 2.6, 0.9}, {0, 2.05, 0}, 32)});
  }
  {
    Skeleton sk;
    add_chain(sk, {{0, 0, 0}, {0, 1.5, 0}}, {0.3, 0.3}, std::nullopt);
    add_chain(sk, {{0, 1.5, 0}, {0.1, 3.0, 0}}, {0.2, 0.18}, ChainParent{0, 1});
    add_chain(sk, {{0, 1.5, 0}, {1.0, 2.1, 0}}, {0.15, 0.12}, ChainParent{0, 1});
    out.push_back({"continuation", close_up(sk, {0.6, 2.3, 2.8}, {0.1, 1.6, 0}, 35)});
  }
  {
    Skeleton sk;
    add_chain(sk, {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {0.3, 0.28, 0.25}, std::nullopt);
    add_chain(sk, {{0, 1, 0}, {0.85, 1.85, 0}}, {0.15, 0.12}, ChainParent{0, 1});
    out.push_back({"fork", close_up(sk, {0.5, 1.6, 2.8}, {0.2, 1.2, 0}, 35)});
  }
  {
    // The elm's first fork (presets/elm.lsys): the trunk ends, its axis goes on bent 30°
    // toward -z, and a limb of nearly its radius leaves the same joint 35° the other way.
    Skeleton sk;
    add_chain(sk, {{0, 0, 0}, {0, 1.6, 0}, {0, 3.2, 0}}, {0.336, 0.32, 0.294}, std::nullopt);
    add_chain(sk, {{0, 3.2, 0}, {0.05, 4.32, -0.54}, {0.44, 5.27, -1.11}}, {0.2436, 0.2436, 0.18},
              ChainParent{0, 2});
    add_chain(sk, {{0, 3.2, 0}, {-0.1, 4.2, 0.7}, {-0.3, 5.1, 1.3}}, {0.22, 0.2, 0.16}, ChainParent{0, 2});
    out.push_back({"y_fork", close_up(sk, {1.9, 3.5, 0.4}, {0, 3.3, 0}, 40)});
  }
  {
    Skeleton sk;
    const double a = 60 * kPi / 180;
    add_chain(sk, {{0, 0, 0}, {0, 1, 0}, {std::sin(a), 1 + std::cos(a), 0}}, {0.2, 0.2, 0.2}, std::nullopt);
    const glm::dvec3 outer = glm::normalize(glm::dvec3(-0.866, 0.5, 0.35));
    out.push_back({"elbow", close_up(sk, glm::dvec3(0, 1, 0) + 2.4 * outer, {0, 1, 0}, 30)});
  }
  return out;
}

struct SurfaceDefects {
  double convex_crease_deg = 0;  // from the depth field's normals
  double convex_normal_jump_deg = 0;  // from the normal AOV
  uint64_t pairs = 0;            // pixel pairs measured
  double concave_crease_deg = 0; // the same measure for concave pairs (a crotch's crease)
  uint64_t concave_pairs = 0;
  int concave_x = -1, concave_y = -1;   // where the largest concave crease begins
  int x = -1, y = -1;            // the pixel where the largest crease (depth) begins
  std::string describe() const {
    return "largest convex crease " + std::to_string(convex_crease_deg) + "° (depth, at pixel " +
           std::to_string(x) + ", " + std::to_string(y) + "), " +
           std::to_string(convex_normal_jump_deg) + "° (normal AOV) over " + std::to_string(pairs) + " pairs";
  }
};

// The measure of this header's comment on `image` (depth and normal AOVs) of `scene`.
inline SurfaceDefects surface_defects(const Scene& scene, const RenderImage& image) {
  const render_common::CameraFrame f = render_common::camera_frame(scene);
  const int w = static_cast<int>(image.width), h = static_cast<int>(image.height);
  const auto idx = [&](int x, int y) { return static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x); };
  std::vector<glm::dvec3> p(static_cast<size_t>(w) * static_cast<size_t>(h));
  std::vector<double> footprint(p.size(), 0);
  std::vector<bool> hit(p.size(), false);
  const double pixel_at_1m = 2 * f.half_height / f.height;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double z = image.depth[idx(x, y)];
      if (!std::isfinite(z)) continue;
      const Ray r = render_common::frame_ray(f, x + 0.5, y + 0.5);
      p[idx(x, y)] = r.origin + z * glm::normalize(r.direction);
      footprint[idx(x, y)] = z * pixel_at_1m;
      hit[idx(x, y)] = true;
    }
  }
  // Geometric normal by central differences, toward the eye; none off the surface, across
  // a depth jump, or seen at more than 60° from the view direction.
  std::vector<std::optional<glm::dvec3>> n(p.size());
  const auto near = [&](int ax, int ay, int bx, int by, double spans) {
    return glm::length(p[idx(ax, ay)] - p[idx(bx, by)]) < spans * footprint[idx(ax, ay)];
  };
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      if (!hit[idx(x, y)] || !hit[idx(x - 1, y)] || !hit[idx(x + 1, y)] || !hit[idx(x, y - 1)] ||
          !hit[idx(x, y + 1)])
        continue;
      if (!near(x - 1, y, x + 1, y, 8) || !near(x, y - 1, x, y + 1, 8)) continue;
      glm::dvec3 g = glm::cross(p[idx(x + 1, y)] - p[idx(x - 1, y)], p[idx(x, y + 1)] - p[idx(x, y - 1)]);
      if (!(glm::length(g) > 0)) continue;
      g = glm::normalize(g);
      const glm::dvec3 view = glm::normalize(f.eye - p[idx(x, y)]);
      if (glm::dot(g, view) < 0) g = -g;
      if (glm::dot(g, view) < 0.5) continue;
      n[idx(x, y)] = g;
    }
  }
  // Near the outline (3 pixels from a miss) the stencils straddle surfaces that touch
  // only in the picture: no normal there.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int dy = -3; dy <= 3 && n[idx(x, y)]; ++dy) {
        for (int dx = -3; dx <= 3; ++dx) {
          const int qx = std::clamp(x + dx, 0, w - 1), qy = std::clamp(y + dy, 0, h - 1);
          if (!hit[idx(qx, qy)]) {
            n[idx(x, y)].reset();
            break;
          }
        }
      }
    }
  }
  const auto angle_deg = [](glm::dvec3 a, glm::dvec3 b) {
    return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)) * 180 / kPi;
  };
  SurfaceDefects d;
  const int step = 4;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int dir = 0; dir < 2; ++dir) {
        const int cx = x + (dir == 0 ? step : 0), cy = y + (dir == 1 ? step : 0);
        if (cx >= w || cy >= h || !n[idx(x, y)] || !n[idx(cx, cy)]) continue;
        bool continuous = true;  // every pixel between them on the surface, no jump
        for (int k = 1; k <= step && continuous; ++k) {
          const int bx = x + (dir == 0 ? k : 0), by = y + (dir == 1 ? k : 0);
          const int qx = bx - (dir == 0 ? 1 : 0), qy = by - (dir == 1 ? 1 : 0);
          continuous = hit[idx(bx, by)] && near(qx, qy, bx, by, 4);
        }
        if (!continuous) continue;
        const glm::dvec3 a = p[idx(x, y)], c = p[idx(cx, cy)];
        const glm::dvec3 na = *n[idx(x, y)], nc = *n[idx(cx, cy)];
        const double tiny = 1e-3 * footprint[idx(x, y)];
        if (glm::dot(na, c - a) > tiny && glm::dot(nc, a - c) > tiny) {  // concave
          ++d.concave_pairs;
          if (angle_deg(na, nc) > d.concave_crease_deg) {
            d.concave_crease_deg = angle_deg(na, nc);
            d.concave_x = x, d.concave_y = y;
          }
          continue;
        }
        if (!(glm::dot(na, c - a) < -tiny && glm::dot(nc, a - c) < -tiny)) continue;  // not convex
        ++d.pairs;
        if (angle_deg(na, nc) > d.convex_crease_deg) {
          d.convex_crease_deg = angle_deg(na, nc);
          d.x = x, d.y = y;
        }
        if (!image.normal.empty()) {
          const auto aov = [&](int px, int py) {
            const size_t i = 3 * idx(px, py);
            return glm::dvec3(image.normal[i], image.normal[i + 1], image.normal[i + 2]);
          };
          d.convex_normal_jump_deg = std::max(d.convex_normal_jump_deg, angle_deg(aov(x, y), aov(cx, cy)));
        }
      }
    }
  }
  return d;
}

// How continuous u and v are across the boundary between a chain and the child that
// carries its axis on (continuation_children, docs/joints.md "Continuations"), from the uv
// and id AOVs: for each pair of neighbouring pixels that see the parent and that child, the
// jump in v (metres) and in u (turns, the shorter way round) against the local step — the
// largest change between either pixel and a 4-neighbour on its own chain. Seamless
// bark has jumps of about one step; a ring has jumps of many.
struct UvContinuity {
  uint64_t pairs = 0;      // boundary pairs with a local step on at least one side
  double worst_v = 0;      // largest jump / local step in v
  double worst_u = 0;      // ... in u
  int x = -1, y = -1;      // where the worst (v or u) is
  std::string describe() const {
    return std::to_string(pairs) + " boundary pairs, worst jump " + std::to_string(worst_v) + " steps in v, " +
           std::to_string(worst_u) + " in u (at pixel " + std::to_string(x) + ", " + std::to_string(y) + ")";
  }
};

inline UvContinuity uv_continuity(const Scene& scene, const RenderImage& image) {
  const int w = static_cast<int>(image.width), h = static_cast<int>(image.height);
  std::vector<std::vector<int64_t>> continuation;  // per plant
  for (const ScenePlant& plant : scene.plants) {
    continuation.push_back(plant.skeleton ? continuation_children(*plant.skeleton) : std::vector<int64_t>{});
  }
  const auto at = [&](int x, int y) { return static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x); };
  const auto plant_of = [&](int x, int y) { return image.id[3 * at(x, y)]; };
  const auto chain_of = [&](int x, int y) { return image.id[3 * at(x, y) + 1]; };
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h; };
  const auto same_chain = [&](int ax, int ay, int bx, int by) {
    return inside(ax, ay) && inside(bx, by) && plant_of(ax, ay) == plant_of(bx, by) && chain_of(ax, ay) == chain_of(bx, by);
  };
  const auto u_diff = [](double a, double b) {
    const double d = std::abs(a - b);
    return std::min(d, 1 - d);
  };
  const auto is_continuation = [&](float plant, float parent, float child) {
    if (plant < 0 || parent < 0 || child < 0 || static_cast<size_t>(plant) >= continuation.size()) return false;
    const std::vector<int64_t>& c = continuation[static_cast<size_t>(plant)];
    return static_cast<size_t>(parent) < c.size() && c[static_cast<size_t>(parent)] == static_cast<int64_t>(child);
  };
  UvContinuity out;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int dir = 0; dir < 2; ++dir) {
        const int dx = dir == 0 ? 1 : 0, dy = dir == 1 ? 1 : 0;
        const int qx = x + dx, qy = y + dy;
        if (!inside(qx, qy) || plant_of(x, y) < 0 || plant_of(x, y) != plant_of(qx, qy)) continue;
        const float a = chain_of(x, y), b = chain_of(qx, qy);
        if (!is_continuation(plant_of(x, y), a, b) && !is_continuation(plant_of(x, y), b, a)) continue;
        const auto u = [&](int px, int py) { return double(image.uv[2 * at(px, py)]); };
        const auto v = [&](int px, int py) { return double(image.uv[2 * at(px, py) + 1]); };
        // The local step: the largest change to a 4-neighbour of the same chain, around
        // either pixel of the pair (its gradient's size, not just along the pair).
        double step_u = 0, step_v = 0;
        bool stepped = false;
        for (const auto& [px, py] : {std::pair{x, y}, std::pair{qx, qy}}) {
          for (const auto& [ox, oy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
            if (!same_chain(px, py, px + ox, py + oy)) continue;
            step_u = std::max(step_u, u_diff(u(px, py), u(px + ox, py + oy)));
            step_v = std::max(step_v, std::abs(v(px, py) - v(px + ox, py + oy)));
            stepped = true;
          }
        }
        if (!stepped) continue;
        ++out.pairs;
        // Floors: a step of 1e-4 (turns, metres) is flat bark at any scale these close-ups use.
        const double jv = std::abs(v(x, y) - v(qx, qy)) / std::max(step_v, 1e-4);
        const double ju = u_diff(u(x, y), u(qx, qy)) / std::max(step_u, 1e-4);
        if (jv > out.worst_v || ju > out.worst_u) out.x = x, out.y = y;
        out.worst_v = std::max(out.worst_v, jv);
        out.worst_u = std::max(out.worst_u, ju);
      }
    }
  }
  return out;
}

// Calls seen(x, y, p) for every hit pixel of `image` (its depth AOV) with the point p the
// pixel's centre ray sees.
template <class Seen>
void for_each_seen_point(const Scene& scene, const RenderImage& image, Seen&& seen) {
  const render_common::CameraFrame f = render_common::camera_frame(scene);
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) {
      const double z = image.depth[static_cast<size_t>(y) * image.width + x];
      if (!std::isfinite(z)) continue;
      const Ray r = render_common::frame_ray(f, x + 0.5, y + 0.5);
      seen(x, y, r.origin + z * glm::normalize(r.direction));
    }
  }
}

// How deep the surface a pixel sees lies inside a solid it should not show: for every hit
// pixel (depth AOV), the point seen and, over every frustum of every plant (skinned with
// `skin`), the most negative frustum_bound (crotch.h) other than those of the frusta whose
// surface it is on — i.e. the largest depth inside another solid. A union of solids drawn by
// nearest hit, with or without fillets (which lie outside the exact union), shows none.
struct InsideView {
  double deepest_m = 0;  // the deepest a seen point lies inside a solid, metres (0: none)
  uint64_t pixels = 0;   // hit pixels measured
  int x = -1, y = -1;
};
inline InsideView deepest_inside_view(const Scene& scene, const RenderImage& image, const SkinOptions& skin) {
  std::vector<Frustum> frusta;
  for (const ScenePlant& plant : scene.plants) {
    const SkinnedSkeleton s = skin_skeleton(place_plant(plant), skin.styled(plant.skin));
    frusta.insert(frusta.end(), s.frusta.begin(), s.frusta.end());
  }
  InsideView v;
  for_each_seen_point(scene, image, [&](uint32_t x, uint32_t y, const glm::dvec3& p) {
    ++v.pixels;
    // The point is on (or, by rounding, just inside) the solids it bounds: its own
    // frusta's bounds are ~0; another solid's interior is what is measured.
    double deepest = 0;
    for (const Frustum& fr : frusta) deepest = std::min(deepest, frustum_bound(fr.shape, p));
    if (-deepest > v.deepest_m) v.deepest_m = -deepest, v.x = static_cast<int>(x), v.y = static_cast<int>(y);
  });
  return v;
}

// The fork close-up with ribbed bark `depth_m` deep (vertical ribs, 8 around, from a
// 32 × 8 height map written to `height_path`): the saguaro's arm in small.
inline Scene ribbed_fork(const std::string& height_path, double depth_m) {
  write_gray_float(height_path, 32, 8, [](uint32_t x, uint32_t) {
    return static_cast<float>(0.5 + 0.5 * std::sin(2 * kPi * (x + 0.5) / 32));
  });
  for (JointCloseUp& c : joint_close_ups()) {
    if (c.name != "fork") continue;
    ScenePlant& plant = c.scene.plants[0];
    plant.bark.height_texture = height_path;
    plant.bark.relief_depth_m = depth_m;
    plant.bark.u_repeat = 8;
    return c.scene;
  }
  return {};
}

// The relief on a blended crotch (crotch.h crotch_relief_fade): for every hit pixel
// inside a crotch's ball, the seen point's field sample; where the blend adds material
// (fade 0) the seen surface must be the smooth blended one (F ~ 0), and every seen point
// must lie on the blended surface or no higher above the exact union (min(P, C)) than
// depth·fade allows (the fillet itself stands up to k/4 off the union, relief-free).
struct ReliefAtCrotches {
  uint64_t faded_pixels = 0;       // pixels whose point has fade 0 (the fillet's region)
  double faded_height_m = 0;       // the largest F there: the height above the blended solid
  double faded_median_m = 0;       // the median F there
  double excess_m = 0;             // the largest min(F, min(P, C) − depth·fade), any pixel in a ball
  uint64_t ribbed_pixels = 0;      // pixels in no ball, or with fade 1
  double ribbed_height_m = 0;      // the largest min(P, C) there: the ribs, undimmed
  int x = -1, y = -1;              // where excess_m was found
  std::string describe() const {
    char text[256];
    std::snprintf(text, sizeof text,
                  "%llu pixels in the fillet's region, at most %.2e m above the blend (median %.2e); excess over the fade %.2e m "
                  "(pixel %d, %d); ribs %.4f m high in %llu pixels",
                  static_cast<unsigned long long>(faded_pixels), faded_height_m, faded_median_m, excess_m, x, y,
                  ribbed_height_m,
                  static_cast<unsigned long long>(ribbed_pixels));
    return text;
  }
};
inline ReliefAtCrotches relief_at_crotches(const Scene& scene, const RenderImage& image, const SkinOptions& skin,
                                          double depth_m) {
  const ScenePlant& plant = scene.plants.at(0);
  const Skeleton placed = place_plant(plant);
  const SkinnedSkeleton skinned = skin_skeleton(placed, skin.styled(plant.skin));
  const std::vector<Crotch> crotches = find_crotches(placed, skinned.frusta);
  ReliefAtCrotches out;
  std::vector<double> faded;
  for_each_seen_point(scene, image, [&](uint32_t x, uint32_t y, const glm::dvec3& p) {
    double fade = 1, union_bound = std::numeric_limits<double>::infinity(), blended = union_bound;
    for (const Crotch& c : crotches) {
      if (glm::length(p - c.centre) >= c.radius) continue;
      const CrotchSample sample = crotch_field(c, skinned.frusta, p);
      fade = std::min(fade, crotch_relief_fade(sample));
      union_bound = std::min(union_bound, std::min(sample.parent, sample.lateral));
      blended = std::min(blended, sample.value);
    }
    if (!std::isfinite(union_bound)) {  // in no ball: the frusta's own relief
      for (const Frustum& fr : skinned.frusta) union_bound = std::min(union_bound, frustum_bound(fr.shape, p));
    } else if (const double excess = std::min(blended, union_bound - depth_m * fade); excess > out.excess_m) {
      out.excess_m = excess, out.x = static_cast<int>(x), out.y = static_cast<int>(y);
    }
    if (fade == 0) ++out.faded_pixels, out.faded_height_m = std::max(out.faded_height_m, blended), faded.push_back(blended);
    if (fade == 1) ++out.ribbed_pixels, out.ribbed_height_m = std::max(out.ribbed_height_m, union_bound);
  });
  if (!faded.empty()) {
    std::nth_element(faded.begin(), faded.begin() + faded.size() / 2, faded.end());
    out.faded_median_m = faded[faded.size() / 2];
  }
  return out;
}

}  // namespace sylva::test
