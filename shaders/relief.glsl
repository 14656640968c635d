// relief.glsl — the GLSL twin of core/geometry/relief.cpp (Bhagvat et al. 2009, sec. 3, eq. 11–12): the shell
// of a frustum, a ray's interval in a solid frustum, and the march through the shell
// (uniform steps, then bisection) against the plant's height field. Same structs and
// functions, same names and order as relief.cpp; what each step does and why is said once,
// in relief.h and relief.cpp. Only GLSL-specific points are noted here.
//
// Differences that GLSL forces or float allows: float instead of double, relative to the
// record's origin_hi like ray_frustum.glsl; no compensated arithmetic (the ray is
// re-centred on the point nearest the frustum's midpoint exactly as intersect_frustum_f
// does, which keeps float's relative precision at the relief's millimetres); no member
// functions (Bounds::at_least is bounds_at_least, Marcher::point is marcher_point, ...);
// the height field is the plant's height map read by bark.glsl's height_field (the
// finest level, bilinear, as texture.cpp's HeightTexture::height) and
// height_field_filtered (the MIP-mapped texture, for the normal's footprint). The
// description of a hit (u, v_m, normals) is only compiled where the pass uses it
// (GBUFFER_PASS); the shadow map needs t alone.

uniform int u_relief_linear_steps;         // ReliefOptions::linear_steps (>= 1)
uniform int u_relief_bisection_steps;      // ReliefOptions::bisection_steps (>= 0)
uniform bool u_relief_exact_v;             // ReliefOptions::exact_v
uniform float u_relief_max_depth_per_radius;  // ReliefOptions::max_depth_per_radius
uniform float u_relief_pixel_spread_rad;   // ReliefOptions::pixel_spread_rad (render_cpu.h)

const float kMaxNormalFootprint = 0.5;  // texture units: beyond, the normal is the base one

// SolidBoundary
const uint kBoundaryRange = 0u;
const uint kBoundarySide = 1u;
const uint kBoundaryLower = 2u;
const uint kBoundaryUpper = 3u;

struct ShellDepths {
  float lower_m;
  float upper_m;
};

ShellDepths relief_shell_depths(FrustumShapeF inner, float depth_m, float max_depth_per_radius) {
  float f = max(0.0, max_depth_per_radius);
  float radius1 = inner.radius0 + inner.slope * inner.length_m;
  return ShellDepths(min(depth_m, f * inner.radius0), min(depth_m, f * radius1));
}

// The shape stores radius0 and slope (not radius1): the shell's slope takes the change of
// thickness along the frustum.
FrustumShapeF relief_shell(FrustumShapeF inner, float depth_m, float max_depth_per_radius) {
  ShellDepths d = relief_shell_depths(inner, depth_m, max_depth_per_radius);
  FrustumShapeF s = inner;
  s.radius0 = inner.radius0 + d.lower_m;
  s.slope = inner.slope + (d.upper_m - d.lower_m) / inner.length_m;
  return s;
}

struct SolidInterval {
  bool hit;
  float t_enter;
  float t_exit;
  uint enter;  // a kBoundary* value
  uint exit;
};

// The ray in the frustum's frame: origin relative to the base, moved along the ray to the
// point nearest the midpoint; t = shift + t_local (intersect_frustum_f's re-centring).
struct LocalRay {
  vec3 origin;
  vec3 dir;
  float shift;
};

LocalRay local_ray(RayF ray, FrustumShapeF shape) {
  vec3 d = ray.direction;
  float dir_sq = dot(d, d);
  vec3 relative = ray.origin - shape.base;
  vec3 midpoint = (0.5 * shape.length_m) * shape.axis;
  float shift = dot(midpoint - relative, d) / dir_sq;
  return LocalRay(relative + shift * d, d, shift);
}

struct Bounds {
  float lo;
  float hi;
  uint lo_by;
  uint hi_by;
};
void bounds_at_least(inout Bounds b, float t, uint by) {
  if (t > b.lo) {
    b.lo = t;
    b.lo_by = by;
  }
}
void bounds_at_most(inout Bounds b, float t, uint by) {
  if (t < b.hi) {
    b.hi = t;
    b.hi_by = by;
  }
}
bool bounds_empty(Bounds b) { return !(b.lo <= b.hi); }

bool linear_at_least(inout Bounds b, float a, float c, uint by) {
  if (a > 0.0)
    bounds_at_least(b, c / a, by);
  else if (a < 0.0)
    bounds_at_most(b, c / a, by);
  else if (!(0.0 >= c))
    return false;
  return !bounds_empty(b);
}

bool inside_quadric(inout Bounds b, float A, float r0, float r1) {
  if (A > 0.0) {
    bounds_at_least(b, r0, kBoundarySide);
    bounds_at_most(b, r1, kBoundarySide);
    return !bounds_empty(b);
  }
  Bounds first = b, second = b;
  bounds_at_most(first, r0, kBoundarySide);
  bounds_at_least(second, r1, kBoundarySide);
  bool first_ok = !bounds_empty(first), second_ok = !bounds_empty(second);
  if (!first_ok && !second_ok) return false;
  if (first_ok && second_ok)
    b = (first.hi - first.lo >= second.hi - second.lo) ? first : second;
  else
    b = first_ok ? first : second;
  return true;
}

// The other root is C/q in float (no SecondRoot: the error bounds are the double's).
bool inside_cone(inout Bounds b, vec3 origin_perp, vec3 dir_perp, float rho, float slope_dir_y) {
  ConeQuadric f = cone_quadric(origin_perp, dir_perp, rho, slope_dir_y);
  if (f.A == 0.0) return linear_at_least(b, -2.0 * f.half_b, f.C, kBoundarySide);
  // C++: A > 0 || isnan(discriminant); a NaN fails both comparisons.
  if (!(f.discriminant >= 0.0)) return !(f.A > 0.0 || !(f.discriminant < 0.0));
  float sign_b = f.half_b >= 0.0 ? 1.0 : -1.0;
  float q = -(f.half_b + sign_b * sqrt(f.discriminant));
  float r0 = q / f.A, r1 = q != 0.0 ? f.C / q : r0;
  if (r1 < r0) {
    float swap_value = r0;
    r0 = r1;
    r1 = swap_value;
  }
  return inside_quadric(b, f.A, r0, r1);
}

struct LocalInterval {
  bool hit;
  float lo;
  float hi;
  uint lo_by;
  uint hi_by;
};

LocalInterval local_solid_interval(FrustumShapeF s, LocalRay r, float lower_offset, float upper_offset) {
  LocalInterval none = LocalInterval(false, 0.0, 0.0, kBoundaryRange, kBoundaryRange);
  vec3 o = r.origin;
  vec3 d = r.dir;
  Bounds b = Bounds(-kInfinity, kInfinity, kBoundaryRange, kBoundaryRange);
  if (!linear_at_least(b, dot(s.lower_normal, d), lower_offset - dot(s.lower_normal, o), kBoundaryLower))
    return none;
  if (!linear_at_least(b, -dot(s.upper_normal, d), dot(s.upper_normal, o) - upper_offset, kBoundaryUpper))
    return none;
  float origin_y = dot(o, s.axis);
  float dir_y = dot(d, s.axis);
  float rho = s.radius0 + s.slope * origin_y;
  float slope_dir_y = s.slope * dir_y;
  if (!linear_at_least(b, slope_dir_y, -rho, kBoundarySide)) return none;
  vec3 origin_perp = o - origin_y * s.axis;
  vec3 dir_perp = d - dir_y * s.axis;
  if (!inside_cone(b, origin_perp, dir_perp, rho, slope_dir_y)) return none;
  if (!(abs(b.lo) < kInfinity) || !(abs(b.hi) < kInfinity)) return none;
  return LocalInterval(true, b.lo, b.hi, b.lo_by, b.hi_by);
}

SolidInterval clamp_interval(LocalInterval l, float shift, float t_min, float t_max) {
  SolidInterval clamped = SolidInterval(false, 0.0, 0.0, kBoundaryRange, kBoundaryRange);
  if (!l.hit) return clamped;
  clamped.t_enter = shift + l.lo;
  clamped.t_exit = shift + l.hi;
  clamped.enter = l.lo_by;
  clamped.exit = l.hi_by;
  if (!(clamped.t_enter > t_min)) {
    clamped.t_enter = t_min;
    clamped.enter = kBoundaryRange;
  }
  if (!(clamped.t_exit < t_max)) {
    clamped.t_exit = t_max;
    clamped.exit = kBoundaryRange;
  }
  clamped.hit = clamped.t_enter <= clamped.t_exit && abs(clamped.t_enter) < kInfinity && abs(clamped.t_exit) < kInfinity;
  return clamped;
}

// Plane offsets relative to the base, as ray_frustum.glsl's LocalShape.
SolidInterval frustum_solid_interval(RayF ray, FrustumShapeF shape, float t_min, float t_max) {
  SolidInterval none = SolidInterval(false, 0.0, 0.0, kBoundaryRange, kBoundaryRange);
  if (!(shape.length_m > 0.0) || !(shape.radius0 >= 0.0) || !(dot(ray.direction, ray.direction) > 0.0))
    return none;
  LocalRay r = local_ray(ray, shape);
  LocalInterval l = local_solid_interval(shape, r, shape.lower_offset - dot(shape.lower_normal, shape.base),
                                         shape.upper_offset - dot(shape.upper_normal, shape.base));
  return clamp_interval(l, r.shift, t_min, t_max);
}

// What the relief of one frustum needs besides its shape (relief.h's ReliefMap): the
// plant's maps (bark.glsl) and its relief depth.
struct ReliefMapF {
  PlantMaps maps;
  float depth_m;
  uint record;  // the frustum's record (CROTCH_FADE: its crotches' fade, crotch.glsl)
};

// Everything the marcher needs about one frustum, in its local frame.
struct Marcher {
  FrustumF frustum;  // the inner frustum (its shape relative to origin_hi)
  ReliefMapF map;
  LocalRay ray;
  vec3 axis;
  vec3 e0;
  vec3 e1;
  float slope;
  float radius0;
  float length_m;
  float depth0;        // shell thickness d(y) = depth0 + depth_slope·y
  float depth_slope;
  float lower_offset;  // the shell's planes, relative to the base
  float upper_offset;
  float t_enter;       // local t of the interval's ends, and v_m there (linear v)
  float t_exit;
  float v_enter;
  float v_exit;
};

// Marcher::Point: the sample at local t.
struct ReliefPoint {
  vec3 p;
  vec3 perp;
  float y;
  float rho;
  float r_inner;
  float depth;
};

// Eq. 11–12: the relief height of the point (its constant-w cone).
float point_w(ReliefPoint q) {
  return q.depth > 0.0 ? (q.rho - q.r_inner) / q.depth : (q.rho <= q.r_inner ? 0.0 : 2.0);
}

ReliefPoint marcher_point(Marcher m, float t_local) {
  ReliefPoint q;
  q.p = m.ray.origin + t_local * m.ray.dir;
  q.y = dot(q.p, m.axis);
  q.perp = q.p - q.y * m.axis;
  q.rho = sqrt(dot(q.perp, q.perp));
  q.r_inner = m.radius0 + m.slope * q.y;
  q.depth = m.depth0 + m.depth_slope * q.y;
  return q;
}

vec3 marcher_radial(Marcher m, ReliefPoint q) { return q.rho > 0.0 ? q.perp / q.rho : m.e0; }

// Eq. 7 on the concentric cone through q: the cone of constant w, radius r(y) + w·d(y).
float exact_v_m(Marcher m, ReliefPoint q) {
  vec3 e = marcher_radial(m, q);
  float w = point_w(q);
  float r0 = m.radius0 + w * m.depth0, k = m.slope + w * m.depth_slope;
  FrustumShapeF s = m.frustum.shape;
  float nd_lower = dot(s.lower_normal, e), nd_upper = dot(s.upper_normal, e);
  float y_lower = (m.lower_offset - r0 * nd_lower) / (dot(s.lower_normal, m.axis) + k * nd_lower);
  float y_upper = (m.upper_offset - r0 * nd_upper) / (dot(s.upper_normal, m.axis) + k * nd_upper);
  float v = (q.y - y_lower) / (y_upper - y_lower);
  return m.frustum.v_lower_m + v * s.length_m;  // v_upper_m − v_lower_m = length
}

float v_m_at(Marcher m, ReliefPoint q, float t_local) {
  if (u_relief_exact_v) return exact_v_m(m, q);
  if (!(m.t_exit > m.t_enter)) return m.v_enter;
  return m.v_enter + (t_local - m.t_enter) / (m.t_exit - m.t_enter) * (m.v_exit - m.v_enter);
}

float u_at(Marcher m, ReliefPoint q, float v_m) {
  float raw = atan(dot(q.perp, m.e1), dot(q.perp, m.e0)) / (2.0 * kPi);
  return wrap_turns(raw - m.frustum.u_offset + u_twist_rad_per_m * v_m / (2.0 * kPi));
}

float marcher_height(Marcher m, float u, float v_m) {
  return clamp(height_field(m.map.maps, u * m.map.maps.u_repeat, v_m * m.map.maps.v_per_metre), 0.0, 1.0);
}

// Whether the sample at local t is inside the relief solid; on_shell: an interval end on
// the outer shell, where w = 1 exactly.
bool marcher_inside(Marcher m, float t_local, bool on_shell) {
  ReliefPoint q = marcher_point(m, t_local);
  float w = on_shell ? 1.0 : point_w(q);
  if (w < 0.0) return true;
  if (w > 1.0) return false;
  float v_m = v_m_at(m, q, t_local);
#ifdef CROTCH_FADE
  // relief.h ReliefFade: the height scaled by the crotches' fade at the sample.
  float scale = clamp(relief_fade(m.map.record, m.frustum.shape.base + q.p), 0.0, 1.0);
  if (w > scale) return false;
  return w <= scale * marcher_height(m, u_at(m, q, v_m), v_m);
#else
  return w <= marcher_height(m, u_at(m, q, v_m), v_m);
#endif
}

// A hit on the relief of a frustum (relief.h's ReliefHit).
struct ReliefHitF {
  FrustumHitF hit;       // kind, t; described: y, radial, geometric normal
  float u;               // turns
  float v_m;             // metres
  vec3 shading_normal;   // unit, outward
  bool from_inside;
};

#ifdef GBUFFER_PASS
// The described part of intersect_relief: u, v_m and the perturbed normals of a hit at
// local t `hit_local` (world t `t`) on boundary `boundary`.
void describe_relief_hit_f(Marcher m, RayF ray, float t, float hit_local, uint boundary, bool on_cap,
                           FrustumShapeF shell, inout ReliefHitF result) {
  ReliefPoint q = marcher_point(m, hit_local);
  vec3 e = marcher_radial(m, q);
  result.hit.y = q.y;
  result.hit.radial = e;
  result.v_m = v_m_at(m, q, hit_local);
  result.u = u_at(m, q, result.v_m);
  if (on_cap) {
    result.hit.normal = boundary == kBoundaryLower ? -shell.lower_normal : shell.upper_normal;
    result.shading_normal = result.hit.normal;
    return;
  }
  PlantMaps maps = m.map.maps;
  float footprint_m = u_relief_pixel_spread_rad * max(t, 0.0) * length(ray.direction);
  float around_per_metre = q.rho > 0.0 ? maps.u_repeat / (2.0 * kPi * q.rho) : 0.0;
  float step_s = 1.0 / float(maps.height_width), step_t = 1.0 / float(maps.height_height);
  float ws = max(2.0 * step_s, footprint_m * around_per_metre);
  float wt = max(2.0 * step_t, footprint_m * maps.v_per_metre);
  float s0 = result.u * maps.u_repeat, t0 = result.v_m * maps.v_per_metre;
  bool filtered = ws > 2.0 * step_s || wt > 2.0 * step_t;
  bool resolved = ws < kMaxNormalFootprint && wt < kMaxNormalFootprint;
  float dh_ds = 0.0, dh_dt = 0.0;
  if (resolved) {
    vec4 h;  // H at s0 ± ws/2, then t0 ± wt/2
    if (filtered) {
      h = vec4(height_field_filtered(maps, s0 + 0.5 * ws, t0, ws, wt),
               height_field_filtered(maps, s0 - 0.5 * ws, t0, ws, wt),
               height_field_filtered(maps, s0, t0 + 0.5 * wt, ws, wt),
               height_field_filtered(maps, s0, t0 - 0.5 * wt, ws, wt));
    } else {
      h = vec4(height_field(maps, s0 + 0.5 * ws, t0), height_field(maps, s0 - 0.5 * ws, t0),
               height_field(maps, s0, t0 + 0.5 * wt), height_field(maps, s0, t0 - 0.5 * wt));
    }
    dh_ds = (h.x - h.y) / ws;
    dh_dt = (h.z - h.w) / wt;
  }
  float depth = max(q.depth, 0.0);
  float around = q.rho > 0.0 ? depth * dh_ds * maps.u_repeat / (2.0 * kPi * q.rho) : 0.0;
  float along = depth * (dh_dt * maps.v_per_metre + dh_ds * maps.u_repeat * u_twist_rad_per_m / (2.0 * kPi));
  vec3 tangent_u = cross(m.axis, e);
  float slope_w = m.slope + clamp(point_w(q), 0.0, 1.0) * m.depth_slope;
  vec3 tangent_v = normalize(m.axis + slope_w * e);
#ifdef CROTCH_FADE
  // The displacement is d·f·H: H's differences scaled by f, and H times f's gradient.
  {
    vec3 p = m.frustum.shape.base + q.p;
    float step = relief_fade_step(m.map.record);
    float f = clamp(relief_fade(m.map.record, p), 0.0, 1.0);
    float df_da = (clamp(relief_fade(m.map.record, p + step * tangent_u), 0.0, 1.0) -
                   clamp(relief_fade(m.map.record, p - step * tangent_u), 0.0, 1.0)) / (2.0 * step);
    float df_db = (clamp(relief_fade(m.map.record, p + step * tangent_v), 0.0, 1.0) -
                   clamp(relief_fade(m.map.record, p - step * tangent_v), 0.0, 1.0)) / (2.0 * step);
    float h0 = filtered ? height_field_filtered(maps, s0, t0, ws, wt) : height_field(maps, s0, t0);
    around = f * around + depth * h0 * df_da;
    along = f * along + depth * h0 * df_db;
  }
#endif
  vec3 offset = around * tangent_u + along * tangent_v;
  // perturb(n0): normalize(n0 − offset), n0 where that is degenerate.
  vec3 n0 = normalize(e - slope_w * m.axis);
  vec3 n = n0 - offset;
  float len = length(n);
  result.hit.normal = len > 0.0 && len < kInfinity ? n / len : n0;
  n0 = surface_normal(m.frustum, q.y, e);
  n = n0 - offset;
  len = length(n);
  result.shading_normal = len > 0.0 && len < kInfinity ? n / len : n0;
}
#endif

// The nearest hit of `ray` with t_min < t < t_max on the relief solid of `frustum` under
// `map` (map.depth_m > 0). With describe false only hit.kind and hit.t are set.
ReliefHitF intersect_relief_f(RayF ray, FrustumF frustum, ReliefMapF map, float t_min, float t_max, bool describe) {
  ReliefHitF result = ReliefHitF(FrustumHitF(kHitNone, 0.0, vec3(0.0), 0.0, vec3(0.0)), 0.0, 0.0, vec3(0.0), false);
  ShellDepths depths = relief_shell_depths(frustum.shape, map.depth_m, u_relief_max_depth_per_radius);
  FrustumShapeF shell = relief_shell(frustum.shape, map.depth_m, u_relief_max_depth_per_radius);
  if (!(shell.length_m > 0.0) || !(shell.radius0 >= 0.0) || !(dot(ray.direction, ray.direction) > 0.0))
    return result;
  Marcher m;
  m.frustum = frustum;
  m.map = map;
  m.ray = local_ray(ray, shell);
  m.axis = shell.axis;
  m.slope = frustum.shape.slope;
  m.radius0 = frustum.shape.radius0;
  m.length_m = shell.length_m;
  m.depth0 = depths.lower_m;
  m.depth_slope = (depths.upper_m - depths.lower_m) / shell.length_m;
  m.lower_offset = shell.lower_offset - dot(shell.lower_normal, shell.base);
  m.upper_offset = shell.upper_offset - dot(shell.upper_normal, shell.base);
  SolidInterval iv =
      clamp_interval(local_solid_interval(shell, m.ray, m.lower_offset, m.upper_offset), m.ray.shift, t_min, t_max);
  if (!iv.hit) return result;
  AxisFrame frame = axis_frame(shell.axis);
  m.e0 = frame.e0;
  m.e1 = frame.e1;
  m.t_enter = iv.t_enter - m.ray.shift;
  m.t_exit = iv.t_exit - m.ray.shift;
  m.v_enter = 0.0;
  m.v_exit = 0.0;
  if (!u_relief_exact_v) {
    m.v_enter = exact_v_m(m, marcher_point(m, m.t_enter));
    m.v_exit = exact_v_m(m, marcher_point(m, m.t_exit));
  }

  int steps = max(1, u_relief_linear_steps);
  bool enter_on_shell = iv.enter == kBoundarySide;
  bool exit_on_shell = iv.exit == kBoundarySide;
  bool start_inside = marcher_inside(m, m.t_enter, enter_on_shell);
  bool from_inside = start_inside && iv.enter == kBoundaryRange;

  float hit_local = 0.0;
  uint boundary = kBoundaryRange;
  bool found = false;
  if (start_inside && !from_inside) {
    hit_local = m.t_enter;
    boundary = iv.enter;
    found = true;
  } else {
    float previous = m.t_enter;
    for (int k = 1; k <= steps && !found; ++k) {
      float t = k == steps ? m.t_exit : m.t_enter + (m.t_exit - m.t_enter) * float(k) / float(steps);
      bool in_solid = marcher_inside(m, t, k == steps && exit_on_shell);
      if (in_solid == start_inside) {
        previous = t;
        continue;
      }
      float outside = from_inside ? t : previous, inside = from_inside ? previous : t;
      for (int b = 0; b < u_relief_bisection_steps; ++b) {
        float mid = 0.5 * (outside + inside);
        if (marcher_inside(m, mid, false))
          inside = mid;
        else
          outside = mid;
      }
      hit_local = from_inside ? inside : outside;
      if (!(m.ray.shift + hit_local > t_min)) hit_local = inside;
      found = true;
    }
    if (!found && from_inside) {
      bool capped = (iv.exit == kBoundaryLower && (shell.caps & 1u) != 0u) ||
                    (iv.exit == kBoundaryUpper && (shell.caps & 2u) != 0u);
      if (iv.exit == kBoundarySide || capped) {
        hit_local = m.t_exit;
        boundary = iv.exit;
        found = true;
      }
    }
  }
  if (!found) return result;
  float t = boundary == kBoundaryRange ? m.ray.shift + hit_local
            : hit_local == m.t_enter   ? iv.t_enter
                                       : iv.t_exit;
  if (!(t > t_min && t < t_max)) return result;

  result.hit.t = t;
  bool on_cap = (boundary == kBoundaryLower && (shell.caps & 1u) != 0u) ||
                (boundary == kBoundaryUpper && (shell.caps & 2u) != 0u);
  result.hit.kind = on_cap ? (boundary == kBoundaryLower ? kHitLowerCap : kHitUpperCap) : kHitSide;
  result.from_inside = from_inside;
#ifdef GBUFFER_PASS
  if (describe) describe_relief_hit_f(m, ray, t, hit_local, boundary, on_cap, shell, result);
#endif
  return result;
}
