// fog_map.glsl — fog mode map on the GPU (docs/fog-map.md, "The GL map walk"): the sun-space
// depth maps the CPU built (core/light/sun_map.h, uploaded by core/gl/gl_fog.h) walked along a
// camera ray exactly as SunDepthMap::lit_parts walks them — a DDA over the tiles (an
// unallocated tile, or one the ray crosses above its largest height, lit whole; below its
// smallest, dark whole), a DDA over the texels of the others (Amanatides & Woo) with the one
// crossing of the ray's height and the texel's in closed form — and the lit pieces, merged as
// they come, integrated with fog.glsl's closed forms as they close (the CPU's integrate_lit).
// No random numbers, no shadow map: the image is the same for any seed.
//
// Every loop has a fixed bound and breaks out (fog.frag.glsl says why llvmpipe needs it). The
// bounds are the grid's worst case (a line crosses at most 2n + 1 cells of an n × n grid), so
// a walk never reaches them; one that did would stop there, lit from that point on, and set
// `capped`.

struct GpuSunMap {
  vec4 centre_half;   // centre − the set's origin, half extent (metres)
  vec4 to_sun_texel;  // s, texel size (metres)
  vec4 e0_size;       // e0, texels a side
  vec4 e1_tiles;      // e1, tiles a side
  uvec4 first_tile;   // the map's first entry in fog_map_slots
};
layout(std430, binding = FOG_MAPS_BINDING) readonly buffer FogMaps { GpuSunMap fog_maps[]; };
layout(std430, binding = FOG_MAP_SLOTS_BINDING) readonly buffer FogMapSlots { uint fog_map_slots[]; };
layout(std430, binding = FOG_MAP_RANGES_BINDING) readonly buffer FogMapRanges { vec2 fog_map_ranges[]; };
layout(std430, binding = FOG_MAP_TEXELS_BINDING) readonly buffer FogMapTexels { float fog_map_texels[]; };

// The lit pieces of one walk as one open run (sun_map.cpp's LitRun), each closed piece
// integrated at once by one closed form along the ray (docs/fog-map.md "One formula a
// piece"). Below the fog's top the camera's optical depth τ from the stretch's start `lo`
// and the sun's optical depth at the same point are tied linearly: along the ray
// dσ/dτ = −k·d_y, so τ_sun falls by (d_y/s_y)·τ and T·T_sun = T_sun(lo)·e^{−κτ} (κ fog.glsl's
// sun rate) — however dark the gaps before a piece, which shadow the sun, not the camera.
// A piece [t0, t1] then adds albedo·T(τ_sun(lo) + κ·τ_anchor)·exp_integral(Δτ, |κ|) (one
// exponent: τ + τ_sun at the anchor, never negative), the anchor its start (κ >= 0) or end
// (κ < 0) as fog_lit_segment's, τ(lo, t0) and Δτ = τ(t0, t1) each
// from the density at its lower end (fog_clipped_optical_depth's form, so that a ray from
// where the density underflows still sees the fog below): the value fog_lit_segment gives
// after fog_optical_depth over the gaps, in six exponentials, with no clipping and no depth
// carried from piece to piece. In float the exponent τ_sun(lo) + κ·τ is good to a few ulps
// of its larger term: a relative error of about 1e-7·τ_sun(lo), which only a sun grazing a
// dense fog makes visible.
struct FogMapRun {
  bool open;
  float start, end;  // the open piece
  float sun;         // the in-scatter of the closed pieces
  // The ray, set once: its stretch [lo, hi] inside the fog (lit: there is one, the sun is
  // up and the fog scatters), its heights, κ, τ_sun(lo).
  bool lit;
  float lo, hi, kappa, sun_depth_lo;
  FogHeights heights;
};

FogMapRun fog_map_run(FogMedium m, vec3 o, vec3 d, vec3 s, float a, float b) {
  FogHeights h = fog_heights_of(m, o.y);
  FogMapRun run = FogMapRun(false, 0.0, 0.0, 0.0, false, 0.0, 0.0, 0.0, 0.0, h);
  FogClip clip = fog_clip_heights(h, d.y, a, b);
  run.lit = !clip.empty && s.y > kFogMinSunY && m.albedo > 0.0;
  if (!run.lit) return run;
  run.lo = clip.t0;
  run.hi = min(clip.t1, kFogFar);
  run.kappa = fog_sun_rate(d.y, s.y);
  run.sun_depth_lo = fog_sun_optical_depth_at(m, fog_height_at(h, d.y, run.lo), h.top, s.y);
  return run;
}

void fog_map_close(inout FogMapRun run, FogMedium m, vec3 d) {
  if (!run.open) return;
  run.open = false;
  float t0 = max(run.start, run.lo), t1 = min(run.end, run.hi);
  if (!run.lit || !(t1 > t0)) return;
  float tau0 = fog_clipped_optical_depth(m, run.heights, d.y, run.lo, t0);
  float dtau = fog_clipped_optical_depth(m, run.heights, d.y, t0, t1);
  if (dtau == 0.0) return;
  float anchor = run.kappa >= 0.0 ? tau0 : tau0 + dtau;
  run.sun += fog_flush_tiny(m.albedo * fog_transmittance_of_depth(run.sun_depth_lo + run.kappa * anchor) *
                            fog_exp_integral(dtau, abs(run.kappa)));
}

void fog_map_add(inout FogMapRun run, FogMedium m, vec3 d, float a, float b) {
  if (!(b > a)) return;
  if (run.open && a <= run.end) {
    run.end = max(run.end, b);
    return;
  }
  fog_map_close(run, m, d);
  run.open = true;
  run.start = a;
  run.end = b;
}

// The part of [t0, t1] where x(t) = (ax + t·bx, ay + t·by) lies in [0, n]²; false when none.
bool fog_map_clip(float ax, float bx, float ay, float by, float n, inout float t0, inout float t1) {
  if (bx == 0.0) {
    if (!(ax >= 0.0 && ax <= n)) return false;
  } else {
    float lo = -ax / bx, hi = (n - ax) / bx;
    t0 = max(t0, min(lo, hi));
    t1 = min(t1, max(lo, hi));
  }
  if (by == 0.0) {
    if (!(ay >= 0.0 && ay <= n)) return false;
  } else {
    float lo = -ay / by, hi = (n - ay) / by;
    t0 = max(t0, min(lo, hi));
    t1 = min(t1, max(lo, hi));
  }
  return t1 > t0;
}

// The sunlit in-scatter over [a, b] in map k: SunDepthMap::lit_parts then the CPU's integrate_lit. `eye`:
// the ray's origin relative to the map set's origin; (o, d): the same ray in fog.glsl's frame
// (the medium's heights), s the sun's centre. `texels`: texels tested one by one are added;
// `capped`: set when a bound stopped the walk.
float fog_map_sun(FogMedium m, vec3 o, vec3 d, vec3 s, float a, float b, vec3 eye, uint k, inout uint texels,
                  inout bool capped) {
  GpuSunMap map = fog_maps[k];
  vec3 p = eye - map.centre_half.xyz;
  float half_extent = map.centre_half.w, texel = map.to_sun_texel.w, size = map.e0_size.w;
  int tiles = int(map.e1_tiles.w);
  vec3 to_sun = map.to_sun_texel.xyz;
  // In texels: x(t) = ax + t·bx, y(t) = ay + t·by; the height h(t) = h0 + t·hd in metres.
  float ax = (dot(p, map.e0_size.xyz) + half_extent) / texel, bx = dot(d, map.e0_size.xyz) / texel;
  float ay = (dot(p, map.e1_tiles.xyz) + half_extent) / texel, by = dot(d, map.e1_tiles.xyz) / texel;
  float h0 = dot(p, to_sun), hd = dot(d, to_sun);
  bool climbs = hd >= 0.0;
  float inv_hd = 1.0 / (hd != 0.0 ? hd : 1e-30);
  FogMapRun run = fog_map_run(m, o, d, s, a, b);
  float g0 = a, g1 = b;
  if (!fog_map_clip(ax, bx, ay, by, size, g0, g1)) {
    fog_map_add(run, m, d, a, b);
    fog_map_close(run, m, d);
    return run.sun;
  }
  fog_map_add(run, m, d, a, g0);
  // The tiles the ray crosses over [g0, g1], in order.
  const float kTile = float(FOG_MAP_TILE);
  float tax = ax / kTile, tbx = bx / kTile, tay = ay / kTile, tby = by / kTile;
  int sx = tbx > 0.0 ? 1 : tbx < 0.0 ? -1 : 0, sy = tby > 0.0 ? 1 : tby < 0.0 ? -1 : 0;
  float start = g0 + min(0.5 * (g1 - g0), 1e-6 * (1.0 + abs(g0)));
  int ix = clamp(int(floor(tax + start * tbx)), 0, tiles - 1);
  int iy = clamp(int(floor(tay + start * tby)), 0, tiles - 1);
  float t = g0;
  bool done = false;
  for (int guard = 0; guard < 4 * tiles + 8 && !done; ++guard) {
    float nx = sx > 0 ? (float(ix + 1) - tax) / tbx : sx < 0 ? (float(ix) - tax) / tbx : kInfinity;
    float ny = sy > 0 ? (float(iy + 1) - tay) / tby : sy < 0 ? (float(iy) - tay) / tby : kInfinity;
    float next = min(min(nx, ny), g1);
    if (next > t) {
      float ta = t, tb = next;
      uint slot = fog_map_slots[map.first_tile.x + uint(iy * tiles + ix)];
      float ha = h0 + ta * hd, hb = h0 + tb * hd;
      vec2 range = slot == FOG_MAP_NO_SLOT ? vec2(0.0) : fog_map_ranges[slot];
      if (slot == FOG_MAP_NO_SLOT || min(ha, hb) > range.y) {
        fog_map_add(run, m, d, ta, tb);  // no plant here, or above every plant
      } else if (!(max(ha, hb) <= range.x)) {   // not below every plant with no gap: the texels
        float lax = ax - float(ix * FOG_MAP_TILE), lay = ay - float(iy * FOG_MAP_TILE);
        const int n = FOG_MAP_TILE;
        float st = ta + min(0.5 * (tb - ta), 1e-6 * (1.0 + abs(ta)));
        int jx = clamp(int(floor(lax + st * bx)), 0, n - 1);
        int jy = clamp(int(floor(lay + st * by)), 0, n - 1);
        int ux = bx > 0.0 ? 1 : bx < 0.0 ? -1 : 0, uy = by > 0.0 ? 1 : by < 0.0 ? -1 : 0;
        float tx = ux > 0 ? (float(jx + 1) - lax) / bx : ux < 0 ? (float(jx) - lax) / bx : kInfinity;
        float ty = uy > 0 ? (float(jy + 1) - lay) / by : uy < 0 ? (float(jy) - lay) / by : kInfinity;
        float dx = ux != 0 ? 1.0 / abs(bx) : kInfinity, dy = uy != 0 ? 1.0 / abs(by) : kInfinity;
        float u = ta;
        uint base = slot * uint(FOG_MAP_TILE * FOG_MAP_TILE);
        for (int step = 0; step < 2 * n + 2; ++step) {
          float stop = min(min(tx, ty), tb);
          ++texels;
          // Lit where h0 + t·hd > w: after the crossing when the ray climbs toward the sun,
          // before it when it descends (w = −inf: the crossing at ∓inf, lit whole).
          float cross = (fog_map_texels[base + uint(jy * n + jx)] - h0) * inv_hd;
          if (climbs)
            fog_map_add(run, m, d, max(cross, u), stop);
          else
            fog_map_add(run, m, d, u, min(cross, stop));
          u = max(u, stop);
          if (!(stop < tb)) break;
          if (tx < ty) {
            jx += ux;
            tx += dx;
          } else if (ty < tx) {
            jy += uy;
            ty += dy;
          } else {
            jx += ux;
            tx += dx;
            jy += uy;
            ty += dy;
          }
          if (jx < 0 || jy < 0 || jx >= n || jy >= n) break;
        }
      }
    }
    if (!(next < g1)) {
      done = true;
      break;
    }
    t = max(t, next);
    if (nx <= ny) ix += sx;
    if (ny <= nx) iy += sy;
    if (ix < 0 || iy < 0 || ix >= tiles || iy >= tiles) done = true;
  }
  if (!done) {
    capped = true;
    fog_map_add(run, m, d, t, g1);
  }
  fog_map_add(run, m, d, g1, b);
  fog_map_close(run, m, d);
  return run.sun;
}
