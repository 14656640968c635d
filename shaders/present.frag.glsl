// present.frag.glsl — a frame's picture into the caller's target (render_gl.h, GlTarget):
// the beauty the shade passes accumulated, divided by their number, opaque, one texel per
// pixel (the target is the frame's size; GL's rows run bottom-up in both). The linear
// values are what GlRenderer::read_back returns (the same float product); SRGB encodes
// them for a display target as core/util/color.cpp's linear_to_srgb does.

layout(binding = ACCUMULATION_UNIT) uniform sampler2D u_accumulation;
uniform float u_inv_samples;  // 1 / spp

layout(location = 0) out vec4 colour;

#ifdef SRGB
// IEC 61966-2-1, clamped to [0, 1]; NaN gives 0.
vec3 linear_to_srgb(vec3 linear) {
  vec3 x = clamp(linear, 0.0, 1.0);
  x = mix(vec3(0.0), x, equal(x, x));
  return mix(1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055, 12.92 * x, lessThanEqual(x, vec3(0.0031308)));
}
#endif

void main() {
  vec3 beauty = texelFetch(u_accumulation, ivec2(gl_FragCoord.xy), 0).rgb * u_inv_samples;
#ifdef SRGB
  beauty = linear_to_srgb(beauty);
#endif
  colour = vec4(beauty, 1.0);
}
