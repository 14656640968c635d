// light_overlay.h — the studio's colouring of light queries by their answers (docs/light.md
// "Front ends", the Light (?E) panel): every `?E` of the grown plants drawn as a dot over
// the picture at the turtle's position where it stands, coloured by its q on a viridis
// ramp (dark violet at 0, yellow at 1) and as large as its sensor sphere seen from the
// camera (2 to 9 pixels). Dots are drawn far to near, so nearer ones cover farther ones;
// the picture's depth does not hide them (a bud inside the crown is the one to see).
#pragma once

#include <imgui.h>

#include <vector>

#include "core/grow/grow.h"
#include "core/scene/scene.h"

namespace sylva::studio {

// q in [0, 1] (clamped) on the viridis ramp, opaque.
ImU32 light_colour(double q);

struct QueryDot {
  ImVec2 centre;      // screen position
  float radius = 0;   // pixels
  ImU32 colour = 0;
  double q = 0;
  double depth = 0;   // metres along the view
};

// One plant's queries (its frame) and the plant that places them in the world.
struct PlantQueries {
  const ScenePlant* plant = nullptr;
  const std::vector<GrowQuery>* queries = nullptr;
};

// The dots of `plants`' queries seen by `camera` in an image of `size` pixels whose top
// left corner is at `origin` on the screen, sensors of `sensor_radius_m`; those behind the
// eye or outside the image are left out. Sorted far to near.
std::vector<QueryDot> query_dots(const Camera& camera, ImVec2 origin, ImVec2 size, double sensor_radius_m,
                                 const std::vector<PlantQueries>& plants);

// Draws `dots` (with a dark rim) and a legend of the ramp, "q 0 … 1", at the image's top
// right corner.
void draw_query_dots(ImDrawList* dl, const std::vector<QueryDot>& dots, ImVec2 origin, ImVec2 size);

}  // namespace sylva::studio
