// tessellate.cpp — frusta to triangle meshes (see tessellate.h).
#include "core/geometry/tessellate.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <glm/geometric.hpp>
#include <cstdio>
#include <numeric>
#include <string>

namespace sylva {

namespace {

constexpr double kTwoPi = 6.283185307179586;

// Unit radial direction at raw angle `u_raw` (turns) in the frustum's axis frame.
glm::dvec3 radial_at(const AxisFrame& frame, double u_raw) {
  return std::cos(kTwoPi * u_raw) * frame.e0 + std::sin(kTwoPi * u_raw) * frame.e1;
}

// Point of the surface at raw angle u_raw and parameter v in [0,1] between the cuts.
glm::dvec3 surface_point(const FrustumShape& s, const glm::dvec3& radial, double v) {
  const double y_lower = generator_crossing_y(s, s.lower, radial);
  const double y_upper = generator_crossing_y(s, s.upper, radial);
  const double y = y_lower + v * (y_upper - y_lower);
  return s.base + y * s.axis + s.radius_at(y) * radial;
}

// Centre of a cap: where the cap plane crosses the axis.
glm::dvec3 plane_axis_point(const FrustumShape& s, const Plane& p) {
  const double y = (p.offset - glm::dot(p.normal, s.base)) / glm::dot(p.normal, s.axis);
  return s.base + y * s.axis;
}

}  // namespace

size_t TriangleMesh::memory_bytes() const {
  return positions.capacity() * sizeof(glm::dvec3) + normals.capacity() * sizeof(glm::dvec3) +
         uvs.capacity() * sizeof(glm::dvec2) + indices.capacity() * sizeof(uint32_t) +
         triangle_frustum.capacity() * sizeof(uint32_t);
}

int tessellation_columns(const TessellateOptions& o) {
  if (o.segments_around > 0) return std::max(3, o.segments_around);
  return 8 << std::max(0, o.level);
}

int tessellation_rows(const TessellateOptions& o) { return 1 << std::max(0, o.level); }

MeshSize tessellation_size(uint64_t frusta, const TessellateOptions& o) {
  // In long double: 6 levels x 4096 columns x a million frusta must not wrap.
  const long double n = tessellation_columns(o), k = std::min(tessellation_rows(o), 1 << 20);
  const long double vertices = static_cast<long double>(frusta) * ((n + 1) * (k + 1) + 2 * (n + 2));
  const long double triangles = static_cast<long double>(frusta) * n * (2 * k + 2);
  const long double bytes = vertices * (sizeof(glm::dvec3) * 2 + sizeof(glm::dvec2)) +
                            triangles * (3 * sizeof(uint32_t) + sizeof(uint32_t));
  const auto clamp = [](long double x) { return x >= 1.8e19L ? UINT64_MAX : static_cast<uint64_t>(x); };
  return {clamp(vertices), clamp(triangles), clamp(bytes)};
}

void check_mesh_fits(const MeshSize& size, uint64_t already_bytes) {
  const auto gib = [](long double b) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3Lg GiB", b / (1u << 30));
    return std::string(text);
  };
  const long double total = static_cast<long double>(size.bytes) + already_bytes;
  if (total > kMaxMeshBytes)
    throw MeshTooLarge("the mesh would take " + gib(total) + ", more than the limit of " + gib(kMaxMeshBytes) +
                       " for a mesh (" + std::to_string(size.triangles) +
                       " triangles in this plant alone); lower --mesh-level or --segments-around");
}

TriangleMesh tessellate(const SkinnedSkeleton& skinned, const TessellateOptions& o) {
  check_mesh_fits(tessellation_size(skinned.frusta.size(), o));
  const int n = tessellation_columns(o), k = tessellation_rows(o);
  TriangleMesh mesh;
  const size_t per_frustum_vertices = static_cast<size_t>(n + 1) * (k + 1) + 2 * (n + 2);
  mesh.positions.reserve(skinned.frusta.size() * per_frustum_vertices);
  mesh.normals.reserve(mesh.positions.capacity());
  mesh.uvs.reserve(mesh.positions.capacity());
  mesh.indices.reserve(skinned.frusta.size() * static_cast<size_t>(n) * (2 * k + 2) * 3);
  mesh.triangle_frustum.reserve(mesh.indices.capacity() / 3);

  // Top-row points of each frustum, reused as the bottom row of the frustum above it
  // when the two share their cut plane: the mesh is watertight by construction.
  std::vector<std::vector<glm::dvec3>> top_rows(skinned.frusta.size());
  std::vector<glm::dvec3> radials(static_cast<size_t>(n) + 1);
  for (size_t f = 0; f < skinned.frusta.size(); ++f) {
    const Frustum& fr = skinned.frusta[f];
    const FrustumShape& s = fr.shape;
    const AxisFrame frame = axis_frame(s.axis);
    const uint32_t first = static_cast<uint32_t>(mesh.positions.size());
    const double twist_turns_per_m = fr.twist_rad_per_m / kTwoPi;
    const Frustum* below = fr.parent >= 0 ? &skinned.frusta[static_cast<size_t>(fr.parent)] : nullptr;
    // (`below` is the frustum under it in its chain, or the last of the chain its
    // continuation goes on from, skin.h: mitred onto it, the same plane.)
    const bool shares_cut = below && below->kind == FrustumKind::segment &&
                            fr.kind == FrustumKind::segment && below->shape.upper.normal == s.lower.normal &&
                            below->shape.upper.offset == s.lower.offset &&
                            !top_rows[static_cast<size_t>(fr.parent)].empty();
    // One generator line per column: through the shared cut point, or at texture u = i/n
    // on the lower cut (texture u = raw − u_offset + twist·v_m, so raw = u + u_offset − …).
    for (int i = 0; i <= n; ++i) {
      glm::dvec3 radial = radial_at(frame, static_cast<double>(i) / n + fr.u_offset - twist_turns_per_m * fr.v_lower_m);
      if (shares_cut) {
        const glm::dvec3 w = top_rows[static_cast<size_t>(fr.parent)][static_cast<size_t>(i)] - s.base;
        const glm::dvec3 perp = w - glm::dot(w, s.axis) * s.axis;
        const double len = glm::length(perp);
        if (len > 1e-12 * (s.length + s.radius0)) radial = perp / len;
      }
      radials[static_cast<size_t>(i)] = radial;
    }
    radials[static_cast<size_t>(n)] = radials[0];
    for (int j = 0; j <= k; ++j) {
      const double v = static_cast<double>(j) / k;
      // The end rows take the cut's v_m exactly, so a joint's shared row has one v_m on
      // both sides (the lerp can be an ulp off at v = 1) and displacement agrees there.
      const double v_m = j == 0 ? fr.v_lower_m : j == k ? fr.v_upper_m : fr.v_lower_m + v * (fr.v_upper_m - fr.v_lower_m);
      for (int i = 0; i <= n; ++i) {
        glm::dvec3 p = surface_point(s, radials[static_cast<size_t>(i)], v);
        if (j == 0 && shares_cut) p = top_rows[static_cast<size_t>(fr.parent)][static_cast<size_t>(i)];
        mesh.positions.push_back(p);
        mesh.normals.push_back(surface_normal(fr, p, o.normals));
        mesh.uvs.push_back({static_cast<double>(i) / n, v_m});
      }
    }
    top_rows[f].assign(mesh.positions.end() - (n + 1), mesh.positions.end());
    if (shares_cut) {
      top_rows[static_cast<size_t>(fr.parent)].clear();  // no longer needed
      top_rows[static_cast<size_t>(fr.parent)].shrink_to_fit();
    }
    auto vertex = [&](int i, int j) { return first + static_cast<uint32_t>(j * (n + 1) + i); };
    const bool tip_lower = s.radius0 == 0, tip_upper = s.radius1 == 0;
    for (int j = 0; j < k; ++j) {
      for (int i = 0; i < n; ++i) {
        const uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
        // Counter-clockwise seen from outside: u grows counter-clockwise about the axis.
        if (!(j == 0 && tip_lower)) {
          mesh.indices.insert(mesh.indices.end(), {a, b, c});
          mesh.triangle_frustum.push_back(static_cast<uint32_t>(f));
        }
        if (!(j == k - 1 && tip_upper)) {
          mesh.indices.insert(mesh.indices.end(), {a, c, d});
          mesh.triangle_frustum.push_back(static_cast<uint32_t>(f));
        }
      }
    }
    if (!o.caps) continue;
    auto cap = [&](const Plane& plane, int row, bool lower) {
      const uint32_t centre = static_cast<uint32_t>(mesh.positions.size());
      const glm::dvec3 normal = lower ? -plane.normal : plane.normal;
      mesh.positions.push_back(plane_axis_point(s, plane));
      mesh.normals.push_back(normal);
      mesh.uvs.push_back({0.0, lower ? fr.v_lower_m : fr.v_upper_m});
      // Rim vertices again, with the cap's flat normal.
      const uint32_t rim = static_cast<uint32_t>(mesh.positions.size());
      for (int i = 0; i <= n; ++i) {
        mesh.positions.push_back(mesh.positions[vertex(i, row)]);
        mesh.normals.push_back(normal);
        mesh.uvs.push_back(mesh.uvs[vertex(i, row)]);
      }
      for (int i = 0; i < n; ++i) {
        const uint32_t a = rim + static_cast<uint32_t>(i), b = rim + static_cast<uint32_t>(i + 1);
        if (lower) mesh.indices.insert(mesh.indices.end(), {centre, b, a});
        else mesh.indices.insert(mesh.indices.end(), {centre, a, b});
        mesh.triangle_frustum.push_back(static_cast<uint32_t>(f));
      }
    };
    if (s.cap_lower && !tip_lower) cap(s.lower, 0, true);
    if (s.cap_upper && !tip_upper) cap(s.upper, k, false);
  }
  return mesh;
}

void append_mesh(TriangleMesh& into, const TriangleMesh& part, uint32_t frustum_offset) {
  const uint32_t base = static_cast<uint32_t>(into.positions.size());
  into.positions.insert(into.positions.end(), part.positions.begin(), part.positions.end());
  into.normals.insert(into.normals.end(), part.normals.begin(), part.normals.end());
  into.uvs.insert(into.uvs.end(), part.uvs.begin(), part.uvs.end());
  // Range inserts grow geometrically; a reserve of the exact new size here would reallocate
  // and copy everything appended so far on every call (quadratic over many small parts:
  // the fillets of 3,318 crotches spent a sixth of their time in it).
  const size_t first_index = into.indices.size(), first_triangle = into.triangle_frustum.size();
  into.indices.insert(into.indices.end(), part.indices.begin(), part.indices.end());
  for (size_t i = first_index; i < into.indices.size(); ++i) into.indices[i] += base;
  into.triangle_frustum.insert(into.triangle_frustum.end(), part.triangle_frustum.begin(), part.triangle_frustum.end());
  for (size_t i = first_triangle; i < into.triangle_frustum.size(); ++i) into.triangle_frustum[i] += frustum_offset;
}

TriangleMesh displace(const TriangleMesh& mesh, const HeightFn& height_m, std::span<const double> scale) {
  const size_t count = mesh.positions.size();
  assert(scale.empty() || scale.size() == count);
  // Coincident vertices, found by sorting on the exact bits of their positions (no
  // tolerance: tessellate copies shared points, it does not recompute them). Each vertex
  // gets the first vertex of its group as representative.
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  auto less = [&](uint32_t a, uint32_t b) {
    const glm::dvec3 &p = mesh.positions[a], &q = mesh.positions[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  // Side vertices: used by a triangle whose v_m vary. A cap fan's triangles have one v_m.
  std::vector<char> on_side(count, 0);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* tri = &mesh.indices[3 * t];
    const double v0 = mesh.uvs[tri[0]].y;
    if (mesh.uvs[tri[1]].y != v0 || mesh.uvs[tri[2]].y != v0) on_side[tri[0]] = on_side[tri[1]] = on_side[tri[2]] = 1;
  }
  // Groups of coincident vertices; each moves by the vector of its first side vertex (none:
  // a cap's centre, which stays in the cut plane as the relief solid's caps do).
  std::vector<uint32_t> representative(count), group_start(count);
  std::vector<glm::dvec3> offset(count, glm::dvec3(0));
  for (size_t k = 0; k < count;) {
    size_t end = k + 1;
    while (end < count && mesh.positions[order[end]] == mesh.positions[order[k]]) ++end;
    uint32_t mover = order[k];
    bool moves = false;
    for (size_t q = k; q < end && !moves; ++q)
      if (on_side[order[q]]) mover = order[q], moves = true;
    for (size_t q = k; q < end; ++q) representative[order[q]] = order[k], group_start[order[q]] = static_cast<uint32_t>(k);
    if (moves)
      offset[order[k]] = (height_m(mesh.uvs[mover].x, mesh.uvs[mover].y) * (scale.empty() ? 1.0 : scale[mover])) *
                         mesh.normals[mover];
    k = end;
  }

  TriangleMesh out = mesh;
  for (size_t v = 0; v < count; ++v) out.positions[v] = mesh.positions[v] + offset[representative[v]];

  // Angle-weighted normals (Thürmer & Wüthrich 1998): each face's unit normal times its
  // angle at the vertex. Unlike area weights they do not depend on how a quad is split:
  // a vertex of the grid is the first corner of two triangles of one quad and of one of
  // the quad before it, which area weights count 2:1 (a cylinder's normals at level 0
  // would lean 7.9° off radial).
  std::vector<glm::dvec3> sum(count, glm::dvec3(0));
  auto angle = [](const glm::dvec3& e, const glm::dvec3& f) {
    return std::atan2(glm::length(glm::cross(e, f)), glm::dot(e, f));
  };
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
    const glm::dvec3 &pa = out.positions[a], &pb = out.positions[b], &pc = out.positions[c];
    const glm::dvec3 n = glm::cross(pb - pa, pc - pa);
    const double area2 = glm::length(n);
    if (!(area2 > 0)) continue;  // a degenerate face has no normal to give
    const glm::dvec3 unit = n / area2;
    sum[a] += angle(pb - pa, pc - pa) * unit;
    sum[b] += angle(pc - pb, pa - pb) * unit;
    sum[c] += angle(pa - pc, pb - pc) * unit;
  }
  // Share the sums across a group where the original normals agree (within ~0.08°).
  constexpr double kSameNormal = 1 - 1e-6;
  for (size_t v = 0; v < count; ++v) {
    glm::dvec3 n(0);
    for (size_t q = group_start[v]; q < count && representative[order[q]] == representative[v]; ++q)
      if (glm::dot(mesh.normals[order[q]], mesh.normals[v]) > kSameNormal) n += sum[order[q]];
    const double len = glm::length(n);
    out.normals[v] = len > 0 ? n / len : mesh.normals[v];
  }
  return out;
}

}  // namespace sylva
