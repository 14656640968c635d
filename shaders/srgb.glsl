// srgb.glsl — the sRGB transfer function's inverse (IEC 61966-2-1), as core/util/color.cpp's
// srgb_to_linear: the images' texels are filtered encoded and decoded after (bark.glsl's
// bark albedo, mesh.frag.glsl's leaf images).

// Encoded [0, 1] → linear.
vec3 srgb_to_linear(vec3 encoded) {
  vec3 c = clamp(encoded, 0.0, 1.0);
  return mix(pow((c + 0.055) / 1.055, vec3(2.4)), c / 12.92, lessThanEqual(c, vec3(0.04045)));
}
