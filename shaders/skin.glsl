// skin.glsl — the GLSL side of core/geometry/skin.h: the axis frame, u/v (eq. 7), the eq. 8 normal,
// the bounding pyramid of sec. 2.6, and the 64-byte GpuSegment record with its unpacking.
// Same names and order as skin.h / skin.cpp, in float, relative to the record's origin_hi.
//
// Where float needs other thresholds than skin.cpp's double (each is a "tip or degenerate"
// test, not part of the geometry): surface_normal treats |Nl|, |Nu| below 1e-5 of the
// segment's size as a tip (double: 1e-9, below float's rounding of a cut point), and
// bounding_pyramid_vertex takes the cut-plane tilt direction only above 1e-4 (any
// direction ⊥ axis bounds the cone; a float-rounded perpendicular normal has ~1e-7 tilt).

const float kPi = 3.14159265358979323846;

// Duff et al. 2017, as axis_frame in skin.cpp. copysign(1, n.z) from the sign bit, so
// that −0 gives −1 like the C++ (a ternary on n.z >= 0 would not), because the frame is
// discontinuous at n.z = 0 and the record's normals are stored in it.
struct AxisFrame {
  vec3 e0;
  vec3 e1;
};
AxisFrame axis_frame(vec3 n) {
  float sign_z = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;
  float a = -1.0 / (sign_z + n.z);
  float b = n.x * n.y * a;
  return AxisFrame(vec3(1.0 + sign_z * n.x * n.x * a, sign_z * b, -sign_z * n.x),
                   vec3(b, sign_z + n.y * n.y * a, -n.y));
}

// Axial coordinate y where the generator line base + y·axis + r(y)·radial crosses the
// plane (normal, offset), offset relative to the record origin like shape.base.
float generator_crossing_y(FrustumShapeF s, vec3 plane_normal, float plane_offset, vec3 radial) {
  float k = s.slope;
  float nd = dot(plane_normal, radial);
  float height = plane_offset - dot(plane_normal, s.base);
  return (height - s.radius0 * nd) / (dot(plane_normal, s.axis) + k * nd);
}

// What the shader knows of a frustum: UnpackedGpuSegment of skin.h, in float.
struct FrustumF {
  FrustumShapeF shape;  // relative to the record's origin_hi
  float u_offset;       // turns
  float v_lower_m;      // metres (v_upper_m = v_lower_m + length)
  uint material;
  bool knuckle;
};

float wrap_turns(float turns) {
  float w = turns - floor(turns);
  return w >= 1.0 ? 0.0 : w;
}

// Raw u (turns in [0,1)) of a direction ⊥ axis.
float raw_u(vec3 axis, vec3 radial) {
  AxisFrame f = axis_frame(axis);
  return wrap_turns(atan(dot(radial, f.e1), dot(radial, f.e0)) / (2.0 * kPi));
}

struct SurfaceUV {
  float u;    // turns in [0,1)
  float v;    // eq. 7: 0 on the lower cut, 1 on the upper cut
  float v_m;  // metres of arc length
};

// surface_uv of skin.cpp for a hit at axial coordinate y with radial ê (FrustumHitF).
SurfaceUV surface_uv(FrustumF fr, float y, vec3 radial, float twist_rad_per_m) {
  FrustumShapeF s = fr.shape;
  float y_lower = generator_crossing_y(s, s.lower_normal, s.lower_offset, radial);
  float y_upper = generator_crossing_y(s, s.upper_normal, s.upper_offset, radial);
  SurfaceUV uv;
  uv.v = (y - y_lower) / (y_upper - y_lower);
  uv.v_m = fr.v_lower_m + uv.v * s.length_m;
  uv.u = wrap_turns(raw_u(s.axis, radial) - fr.u_offset + twist_rad_per_m * uv.v_m / (2.0 * kPi));
  return uv;
}

// surface_normal of skin.cpp (NormalMode::interpolated, eq. 8) for a side hit at axial
// coordinate y with radial ê; knuckles and tips use the exact cone normal.
vec3 surface_normal(FrustumF fr, float y, vec3 radial) {
  FrustumShapeF s = fr.shape;
  vec3 exact = normalize(radial - s.slope * s.axis);
  if (fr.knuckle) return exact;
  float y_lower = generator_crossing_y(s, s.lower_normal, s.lower_offset, radial);
  float y_upper = generator_crossing_y(s, s.upper_normal, s.upper_offset, radial);
  // Nl = Pl − base, Nu = Pu − top, relative to the base (the record origin cancels).
  vec3 nl = y_lower * s.axis + (s.radius0 + s.slope * y_lower) * radial;
  vec3 nu = (y_upper - s.length_m) * s.axis + (s.radius0 + s.slope * y_upper) * radial;
  float radius1 = s.radius0 + s.slope * s.length_m;
  float tiny = 1e-5 * (s.length_m + max(s.radius0, radius1));
  float ll = length(nl), lu = length(nu);
  nl = ll > tiny ? nl / ll : exact;
  nu = lu > tiny ? nu / lu : exact;
  float v = clamp((y - y_lower) / (y_upper - y_lower), 0.0, 1.0);
  vec3 n = (1.0 - v) * nl + v * nu;
  float len = length(n);
  return len > 1e-6 ? n / len : exact;
}

// Corner `corner` (0..3 on the lower plane, 4..7 on the upper, counter-clockwise about
// the axis) of bounding_pyramid(shape, shell_m) of skin.cpp, with the end planes pushed out
// by `end_margin_m` so that float rounding never cuts a cap or a cut curve out of it.
const vec2 kPyramidCornerSigns[4] = vec2[4](vec2(1.0, 1.0), vec2(-1.0, 1.0), vec2(-1.0, -1.0),
                                            vec2(1.0, -1.0));
vec3 bounding_pyramid_vertex(FrustumShapeF s, int corner, float shell_m, float end_margin_m) {
  float r0 = s.radius0 + shell_m;
  float k = s.slope;
  vec3 tl = s.lower_normal - dot(s.lower_normal, s.axis) * s.axis;
  vec3 tu = s.upper_normal - dot(s.upper_normal, s.axis) * s.axis;
  vec3 t = dot(tl, tl) >= dot(tu, tu) ? tl : tu;
  vec3 e0 = dot(t, t) > 1e-8 ? normalize(t) : axis_frame(s.axis).e0;
  vec3 e1 = cross(s.axis, e0);
  vec2 signs = kPyramidCornerSigns[corner & 3];
  vec3 dir = signs.x * e0 + signs.y * e1;
  bool upper = corner >= 4;
  vec3 n = upper ? s.upper_normal : s.lower_normal;
  float offset = upper ? s.upper_offset + end_margin_m : s.lower_offset - end_margin_m;
  float nd = dot(n, dir);
  float den = dot(n, s.axis) + k * nd;
  float height = offset - dot(n, s.base);
  float y = (height - r0 * nd) / max(den, 0.1);  // kMinCrossingDenominator
  return s.base + y * s.axis + (r0 + k * y) * dir;
}

// The 12 triangles of bounding_pyramid, counter-clockwise from outside.
const int kPyramidTriangles[36] = int[36](0, 2, 1, 0, 3, 2,  // lower face
                                          4, 5, 6, 4, 6, 7,  // upper face
                                          0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5,
                                          2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7);

// The GPU record of skin.h, 64 bytes; std430 lays it out exactly as the C++ struct (every
// member 4-byte aligned, arrays of scalars with stride 4).
struct GpuSegment {
  float origin_hi[3];
  float axis_scaled[3];
  float radius0;
  float radius1;
  float lower_axis_y;
  float upper_axis_y;
  float v_lower_m;
  uint meta;
  uint bits[4];
};

// Bit i of the 128-bit field is bit (i % 32) of word i / 32; count <= 20 (a field crosses
// at most one word boundary).
uint get_bits(uint words[4], int first_bit, int count) {
  int word = first_bit >> 5;
  int shift = first_bit & 31;
  uint v = words[word] >> uint(shift);
  if (shift + count > 32) v |= words[word + 1] << uint(32 - shift);
  return v & ((1u << uint(count)) - 1u);
}

float decode_snorm(uint v, int bits) {
  float max_value = float((1u << uint(bits - 1)) - 1u);
  int q = int(v << uint(32 - bits)) >> (32 - bits);  // sign-extend
  return max(-1.0, float(q) / max_value);
}

// Residual scale of one origin component (skin.cpp): one float ulp of |origin_hi|.
float residual_scale(float hi) { return max(abs(hi), 1e-30) * exp2(-23.0); }

// unpack_gpu_segment of skin.cpp in float, relative to the record's origin_hi: shape.base
// is the small residual base − origin_hi, plane offsets are relative to origin_hi.
FrustumF unpack_gpu_segment(GpuSegment g) {
  FrustumF u;
  vec3 axis_scaled = vec3(g.axis_scaled[0], g.axis_scaled[1], g.axis_scaled[2]);
  vec3 base;
  for (int i = 0; i < 3; ++i)
    base[i] = 0.5 * decode_snorm(get_bits(g.bits, 16 * i, 16), 16) * residual_scale(g.origin_hi[i]);
  u.shape.base = base;
  u.shape.length_m = length(axis_scaled);
  u.shape.axis = axis_scaled / u.shape.length_m;
  u.shape.radius0 = g.radius0;
  u.shape.slope = (g.radius1 - g.radius0) / u.shape.length_m;
  AxisFrame f = axis_frame(u.shape.axis);
  for (int p = 0; p < 2; ++p) {
    int first_bit = p == 0 ? 48 : 88;
    float a = decode_snorm(get_bits(g.bits, first_bit, 20), 20);
    float b = decode_snorm(get_bits(g.bits, first_bit + 20, 20), 20);
    float c = sqrt(max(0.0, 1.0 - a * a - b * b));
    vec3 n = normalize(a * f.e0 + b * f.e1 + c * u.shape.axis);
    float axis_y = p == 0 ? g.lower_axis_y : g.upper_axis_y;
    float offset = dot(n, base + axis_y * u.shape.axis);
    if (p == 0) {
      u.shape.lower_normal = n;
      u.shape.lower_offset = offset;
    } else {
      u.shape.upper_normal = n;
      u.shape.upper_offset = offset;
    }
  }
  u.shape.caps = (g.meta >> 24) & 3u;
  u.knuckle = ((g.meta >> 26) & 1u) != 0u;
  u.material = (g.meta >> 16) & 0xFFu;
  u.u_offset = float(g.meta & 0xFFFFu) / 65536.0;
  u.v_lower_m = g.v_lower_m;
  return u;
}
