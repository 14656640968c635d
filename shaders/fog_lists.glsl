// fog_lists.glsl — the per-pixel lists of the shadow cones' intervals along the camera
// rays (Hougs and Day 2001 sec. 3.3.1, in a rasteriser): what the cone pass (fog_cones.vert/
// frag.glsl) writes and the fog resolve (fog.frag.glsl) reads.
//
// The lists: one linked list per pixel in shader storage, appended to by every cone
// fragment with an atomic counter (the node) and an atomic exchange (the pixel's head).
// A fragment that finds the node buffer full marks its pixel overflowed; the resolve then
// marches that pixel's whole ray through the shadow map (the `brute` estimate: unbiased,
// only slower) instead of trusting an incomplete list, and counts it.

struct FogNode {         // one cone's interval along a pixel's ray, metres from the eye
  float t_in;
  float t_out;
  uint next;             // the next node of the pixel's list, FOG_LIST_END at its end
};
layout(std430, binding = FOG_NODES_BINDING) buffer FogNodes { FogNode fog_nodes[]; };
layout(std430, binding = FOG_HEADS_BINDING) buffer FogHeads { uint fog_heads[]; };            // per pixel
layout(std430, binding = FOG_OVERFLOW_BINDING) buffer FogOverflow { uint fog_overflowed[]; }; // per pixel: 1 = list incomplete
// The frame's counts (gl_fog.h GlFogCounters): next_node is reset before each cone pass.
layout(std430, binding = FOG_COUNTERS_BINDING) buffer FogCounters {
  uint fog_next_node;           // nodes taken in this pass (may exceed the capacity)
  uint fog_fragments;           // interval fragments over the frame's passes
  uint fog_overflow_fragments;  // of them, those that found the buffer full
  uint fog_overflow_pixels;     // pixels the resolve marched whole (full list or FOG_MAX_INTERVALS)
  uint fog_largest_pass;        // the most nodes one pass asked for (the next frame's capacity)
};
