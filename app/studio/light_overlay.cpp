// light_overlay.cpp — see light_overlay.h.
#include "app/studio/light_overlay.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/scene/render_common.h"

namespace sylva::studio {

ImU32 light_colour(double q) {
  // viridis at 0, 1/4, 1/2, 3/4 and 1 (matplotlib's table), linearly between.
  static constexpr std::array<std::array<float, 3>, 5> kStops = {{{0.267f, 0.005f, 0.329f},
                                                                   {0.230f, 0.322f, 0.546f},
                                                                   {0.128f, 0.567f, 0.551f},
                                                                   {0.369f, 0.789f, 0.383f},
                                                                   {0.993f, 0.906f, 0.144f}}};
  const double t = std::isfinite(q) ? std::clamp(q, 0.0, 1.0) * 4 : 0;
  const size_t i = std::min<size_t>(3, static_cast<size_t>(t));
  const float f = static_cast<float>(t - static_cast<double>(i));
  const auto& a = kStops[i];
  const auto& b = kStops[i + 1];
  return ImGui::ColorConvertFloat4ToU32(
      ImVec4(a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f, 1.0f));
}

std::vector<QueryDot> query_dots(const Camera& camera, ImVec2 origin, ImVec2 size, double sensor_radius_m,
                                 const std::vector<PlantQueries>& plants) {
  std::vector<QueryDot> dots;
  if (!(size.x >= 1 && size.y >= 1)) return dots;
  Scene view;
  view.camera = camera;
  view.width = static_cast<uint32_t>(size.x);
  view.height = static_cast<uint32_t>(size.y);
  const render_common::CameraFrame frame = render_common::camera_frame(view);
  // Pixels per metre at depth 1.
  const double pixels_per_m = 0.5 * frame.height / frame.half_height;
  for (const PlantQueries& pq : plants) {
    if (!pq.plant || !pq.queries) continue;
    for (const GrowQuery& q : *pq.queries) {
      const auto at = render_common::frame_pixel(frame, place_point(*pq.plant, q.position));
      if (!at || at->x < 0 || at->y < 0 || at->x > frame.width || at->y > frame.height) continue;
      QueryDot d;
      d.centre = ImVec2(origin.x + static_cast<float>(at->x), origin.y + static_cast<float>(at->y));
      const double r = sensor_radius_m * pq.plant->scale * pixels_per_m / at->depth;
      d.radius = static_cast<float>(std::clamp(r, 2.0, 9.0));
      d.q = q.q;
      d.colour = light_colour(q.q);
      d.depth = at->depth;
      dots.push_back(d);
    }
  }
  std::stable_sort(dots.begin(), dots.end(), [](const QueryDot& a, const QueryDot& b) { return a.depth > b.depth; });
  return dots;
}

void draw_query_dots(ImDrawList* dl, const std::vector<QueryDot>& dots, ImVec2 origin, ImVec2 size) {
  dl->PushClipRect(origin, ImVec2(origin.x + size.x, origin.y + size.y), true);
  for (const QueryDot& d : dots) {
    dl->AddCircleFilled(d.centre, d.radius + 1, IM_COL32(20, 20, 20, 200), 12);
    dl->AddCircleFilled(d.centre, d.radius, d.colour, 12);
  }
  // The legend: the ramp from q = 0 to q = 1 at the top right.
  const float w = 120, h = 10, pad = 8;
  const ImVec2 at(origin.x + size.x - w - pad, origin.y + pad + ImGui::GetTextLineHeight());
  dl->AddRectFilled(ImVec2(at.x - 4, at.y - ImGui::GetTextLineHeight() - 4), ImVec2(at.x + w + 4, at.y + h + 4),
                    IM_COL32(0, 0, 0, 140));
  const int steps = 24;
  for (int i = 0; i < steps; ++i) {
    const float x0 = at.x + w * static_cast<float>(i) / steps, x1 = at.x + w * static_cast<float>(i + 1) / steps;
    dl->AddRectFilled(ImVec2(x0, at.y), ImVec2(x1, at.y + h), light_colour((i + 0.5) / steps));
  }
  dl->AddText(ImVec2(at.x, at.y - ImGui::GetTextLineHeight() - 2), IM_COL32(230, 230, 230, 255), "q 0");
  dl->AddText(ImVec2(at.x + w - ImGui::CalcTextSize("1").x, at.y - ImGui::GetTextLineHeight() - 2),
              IM_COL32(230, 230, 230, 255), "1");
  dl->PopClipRect();
}

}  // namespace sylva::studio
