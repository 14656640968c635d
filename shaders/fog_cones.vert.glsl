// fog_cones.vert.glsl — vertex pulling for the shadow cones, as frusta.vert.glsl for the
// frusta (Bhagvat et al. 2009 sec. 2.6): vertex gl_VertexID draws corner kPyramidTriangles[gl_VertexID
// % PYRAMID_VERTICES] of the bounding pyramid of cone gl_VertexID / PYRAMID_VERTICES, built
// from its record (fog_lists.glsl); no vertex buffer.

flat out FrustumShapeF v_shape;  // relative to the cone set's origin

uniform vec3 u_eye_rel_cones;     // eye − the cone set's origin (from double)

void main() {
  uint cone = uint(gl_VertexID / PYRAMID_VERTICES);
  FrustumShapeF s = shadow_cone_shape(fog_cones[cone]);
  float radius_max = max(s.radius0, s.radius0 + s.slope * s.length_m);
  float size = s.length_m + radius_max;
  // The frusta's margins (frusta.vert.glsl): far above float rounding, far below a pixel.
  vec3 corner = bounding_pyramid_vertex(s, kPyramidTriangles[gl_VertexID % PYRAMID_VERTICES],
                                        1e-4 * radius_max + 1e-6 * size, 1e-4 * size);
  gl_Position = camera_clip_position(corner - u_eye_rel_cones);
  v_shape = s;
}
