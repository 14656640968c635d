// fog_cones.frag.glsl — one shadow cone's interval along one pixel's ray, appended to the
// pixel's list (fog_lists.glsl). The pass draws the pyramids' back faces with no depth test:
// every ray that meets a cone leaves its pyramid through a back face in front of the eye,
// whether the eye is outside the pyramid or inside it, so one draw covers both (the
// frusta need EYE_INSIDE for that; a cone interval needs no nearest hit). The interval is
// clipped to what the pixel sees (the G-buffer's plant, the ground) and dropped when
// nothing is left, so cones behind the surface take no node.

flat in FrustumShapeF v_shape;

layout(binding = G_NORMAL_DISTANCE_UNIT) uniform sampler2D g_normal_distance;
uniform vec3 u_eye_rel_cones;     // eye − the cone set's origin
uniform float u_eye_above_ground;
uniform uint u_fog_capacity;      // nodes in FogNodes

vec3 camera_ray_direction(vec2 pixel) {
  float sx = (2.0 * pixel.x / u_image_size.x - 1.0) * u_half_size.x;
  float sy = (1.0 - 2.0 * pixel.y / u_image_size.y) * u_half_size.y;
  return u_forward + sx * u_right + sy * u_up;
}

void main() {
  vec2 pixel = vec2(gl_FragCoord.x - 0.5 + u_jitter.x, u_image_size.y - gl_FragCoord.y - 0.5 + u_jitter.y);
  vec3 dir = camera_ray_direction(pixel);
  float len = length(dir);
  vec2 interval = shadow_cone_interval(RayF(u_eye_rel_cones, dir), v_shape) * len;  // metres
  // What the pixel sees ends the interval (shade.frag.glsl's choice between plant and ground).
  float plant_m = texelFetch(g_normal_distance, ivec2(gl_FragCoord.xy), 0).w;
  float t_end = min(plant_m >= 0.0 ? plant_m : kInfinity, fog_ground_distance(u_eye_above_ground, dir.y / len));
  interval.y = min(interval.y, t_end);
  if (!(interval.y > interval.x)) return;
  uint pixel_index = uint(gl_FragCoord.y) * uint(u_image_size.x) + uint(gl_FragCoord.x);
  atomicAdd(fog_fragments, 1u);
  uint node = atomicAdd(fog_next_node, 1u);
  atomicMax(fog_largest_pass, node + 1u);
  if (node >= u_fog_capacity) {
    atomicAdd(fog_overflow_fragments, 1u);
    fog_overflowed[pixel_index] = 1u;
    return;
  }
  fog_nodes[node] = FogNode(interval.x, interval.y, atomicExchange(fog_heads[pixel_index], node));
}
