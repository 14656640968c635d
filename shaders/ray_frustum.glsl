// ray_frustum.glsl — the GLSL twin of core/geometry/ray_frustum.cpp's float intersector (Bhagvat et al. 2009,
// sec. 2.5, eq. 9–10, made robust): the same structs and functions, same names, same
// order, same order of operations, so the two read side by side. What each step does and
// why is said once, in ray_frustum.cpp; only GLSL-specific points are noted here.
//
// Differences that GLSL forces: no templates (float only), no references (inout), no
// member functions (RayRange.contains is ray_range_contains), no std::numeric_limits
// (kInfinity from its bits), and no struct member named `length` (it parses as the
// .length() method): it is length_m here. The compiler may contract a·b + c into an FMA;
// that changes results by an ulp, not the algorithm.

#define kInfinity uintBitsToFloat(0x7F800000u)  // +inf (a const initializer cannot call it)

// FrustumHitKind
const uint kHitNone = 0u;
const uint kHitSide = 1u;
const uint kHitLowerCap = 2u;
const uint kHitUpperCap = 3u;

// A ray in the frame of a FrustumShapeF (relative to that shape's per-segment origin).
struct RayF {
  vec3 origin;
  vec3 direction;
};

// A FrustumShape in float, relative to a per-segment origin.
struct FrustumShapeF {
  vec3 base;
  vec3 axis;
  float length_m;  // C++: length (a member named length clashes with GLSL's .length())
  float radius0;
  float slope;
  vec3 lower_normal;
  float lower_offset;
  vec3 upper_normal;
  float upper_offset;
  uint caps;  // bit 0: lower cap, bit 1: upper cap
};

struct FrustumHitF {
  uint kind;  // a kHit* value
  float t;
  vec3 normal;
  float y;
  vec3 radial;
};

// The frame-relative shape: everything relative to the segment base.
struct LocalShape {
  vec3 axis;
  float length_m;  // C++: length (a member named length clashes with GLSL's .length())
  float radius0;
  float slope;
  vec3 lower_normal;
  float lower_offset;  // relative to the base
  vec3 upper_normal;
  float upper_offset;  // relative to the base
  bool cap_lower;
  bool cap_upper;
};

// The caller's range, checked on the final t = shift + t_local.
struct RayRange {
  float shift;
  float t_min;
  float t_max;
};
bool ray_range_contains(RayRange range, float t_local) {
  float t = range.shift + t_local;
  return t > range.t_min && t < range.t_max;
}

struct LocalHit {
  uint kind;
  float t_local;
  vec3 point;  // relative to the base
};

bool frustum_inside_planes(LocalShape s, vec3 p) {
  return dot(s.lower_normal, p) >= s.lower_offset && dot(s.upper_normal, p) <= s.upper_offset;
}

// core/geometry/cone_quadric.h, shared with relief.glsl as the C++ shares it.
struct ConeQuadric {
  float A;
  float half_b;
  float C;
  float radial_sq;
  float moment_sq;
  float discriminant;
};

ConeQuadric cone_quadric(vec3 origin_perp, vec3 dir_perp, float rho, float slope_dir_y) {
  ConeQuadric f;
  f.A = dot(dir_perp, dir_perp) - slope_dir_y * slope_dir_y;
  f.half_b = dot(origin_perp, dir_perp) - rho * slope_dir_y;
  f.C = dot(origin_perp, origin_perp) - rho * rho;
  vec3 radial_term = rho * dir_perp - slope_dir_y * origin_perp;
  vec3 moment = cross(origin_perp, dir_perp);
  f.radial_sq = dot(radial_term, radial_term);
  f.moment_sq = dot(moment, moment);
  f.discriminant = f.radial_sq - f.moment_sq;
  return f;
}

int frustum_side_roots(float A, float half_b, float C, float discriminant, out float roots[2]) {
  roots[0] = 0.0;
  roots[1] = 0.0;
  if (!(discriminant >= 0.0)) return 0;
  float sign_b = half_b >= 0.0 ? 1.0 : -1.0;
  float q = -(half_b + sign_b * sqrt(discriminant));
  int count = 0;
  if (A != 0.0) roots[count++] = q / A;
  if (q != 0.0 && (discriminant > 0.0 || count == 0)) roots[count++] = C / q;
  if (count == 2 && roots[1] < roots[0]) {
    float swap_value = roots[0];
    roots[0] = roots[1];
    roots[1] = swap_value;
  }
  return count;
}

void frustum_side_hit(LocalShape s, vec3 origin, vec3 dir, RayRange range, inout LocalHit best) {
  float origin_y = dot(origin, s.axis);
  vec3 origin_perp = origin - origin_y * s.axis;
  float dir_y = dot(dir, s.axis);
  vec3 dir_perp = dir - dir_y * s.axis;
  float rho = s.radius0 + s.slope * origin_y;
  float slope_dir_y = s.slope * dir_y;
  ConeQuadric f = cone_quadric(origin_perp, dir_perp, rho, slope_dir_y);
  float roots[2];
  int count = frustum_side_roots(f.A, f.half_b, f.C, f.discriminant, roots);
  for (int i = 0; i < count; ++i) {
    float t = roots[i];
    if (!(t < best.t_local) || !ray_range_contains(range, t)) continue;
    vec3 p = origin + t * dir;
    if (s.radius0 + s.slope * dot(p, s.axis) < 0.0) continue;  // wrong nappe
    if (!frustum_inside_planes(s, p)) continue;
    best.kind = kHitSide;
    best.t_local = t;
    best.point = p;
    return;
  }
}

void frustum_cap_hit(LocalShape s, vec3 origin, vec3 dir, vec3 normal, float offset, uint kind,
                     RayRange range, inout LocalHit best) {
  float denominator = dot(normal, dir);
  if (denominator == 0.0) return;
  float t = (offset - dot(normal, origin)) / denominator;
  if (!(t < best.t_local) || !ray_range_contains(range, t)) return;
  vec3 p = origin + t * dir;
  float y = dot(p, s.axis);
  vec3 p_perp = p - y * s.axis;
  float radius = s.radius0 + s.slope * y;
  if (!(radius > 0.0) || dot(p_perp, p_perp) > radius * radius) return;
  if (kind == kHitLowerCap ? dot(s.upper_normal, p) > s.upper_offset
                           : dot(s.lower_normal, p) < s.lower_offset)
    return;
  best.kind = kind;
  best.t_local = t;
  best.point = p;
}

vec3 frustum_radial(vec3 axis, vec3 p) {
  vec3 p_perp = p - dot(p, axis) * axis;
  float length_sq = dot(p_perp, p_perp);
  if (length_sq > 0.0) return p_perp / sqrt(length_sq);
  vec3 helper = abs(axis.x) < 0.5 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 perp = helper - dot(helper, axis) * axis;
  return perp / sqrt(dot(perp, perp));
}

LocalHit frustum_intersect_local(LocalShape s, vec3 origin, vec3 dir, RayRange range) {
  LocalHit best = LocalHit(kHitNone, kInfinity, vec3(0.0));
  frustum_side_hit(s, origin, dir, range, best);
  if (s.cap_lower)
    frustum_cap_hit(s, origin, dir, -s.lower_normal, -s.lower_offset, kHitLowerCap, range, best);
  if (s.cap_upper)
    frustum_cap_hit(s, origin, dir, s.upper_normal, s.upper_offset, kHitUpperCap, range, best);
  return best;
}

vec3 frustum_normal(LocalShape s, uint kind, vec3 radial) {
  if (kind == kHitLowerCap) return -s.lower_normal;
  if (kind == kHitUpperCap) return s.upper_normal;
  vec3 n = radial - s.slope * s.axis;
  return n / sqrt(dot(n, n));
}

FrustumHitF intersect_frustum_f(RayF ray, FrustumShapeF shape, float t_min, float t_max) {
  FrustumHitF result = FrustumHitF(kHitNone, 0.0, vec3(0.0), 0.0, vec3(0.0));
  if (!(shape.length_m > 0.0) || !(shape.radius0 >= 0.0)) return result;
  vec3 d = ray.direction;
  float dir_sq = dot(d, d);
  if (!(dir_sq > 0.0)) return result;
  // Re-centre relative to the base, then to the point nearest the midpoint.
  vec3 relative = ray.origin - shape.base;
  vec3 midpoint = (0.5 * shape.length_m) * shape.axis;
  float shift = dot(midpoint - relative, d) / dir_sq;
  vec3 origin = relative + shift * d;
  LocalShape local = LocalShape(shape.axis,
                                shape.length_m,
                                shape.radius0,
                                shape.slope,
                                shape.lower_normal,
                                shape.lower_offset - dot(shape.lower_normal, shape.base),
                                shape.upper_normal,
                                shape.upper_offset - dot(shape.upper_normal, shape.base),
                                (shape.caps & 1u) != 0u,
                                (shape.caps & 2u) != 0u);
  LocalHit hit = frustum_intersect_local(local, origin, d, RayRange(shift, t_min, t_max));
  if (hit.kind == kHitNone) return result;
  result.kind = hit.kind;
  result.t = shift + hit.t_local;
  result.y = dot(hit.point, shape.axis);
  result.radial = frustum_radial(shape.axis, hit.point);
  result.normal = frustum_normal(local, hit.kind, result.radial);
  return result;
}
