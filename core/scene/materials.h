// materials.h — what a skeleton's material index means to the renderers and the glTF
// export: its default albedo (linear RGB). A plant's bark (scene.h) is its wood's, material
// 0's, only: its albedo (texture or colour) and height map (relief, displacement) apply
// to material 0 and never to needles, leaves or fronds (materials 1 and up).
#pragma once

#include <cstdint>

namespace sylva {

// Default albedo by material index, linear RGB (materials past the table reuse its last
// entry).
inline constexpr double kMaterialAlbedo[][3] = {
    {0.30, 0.20, 0.12},  // 0 wood, bark
    {0.16, 0.34, 0.10},  // 1 leaves, needles, cactus skin
    {0.22, 0.40, 0.16},  // 2 succulent skin
    {0.85, 0.75, 0.35},  // 3 flowers, fruit
};
inline constexpr uint32_t kMaterialTableSize = sizeof kMaterialAlbedo / sizeof kMaterialAlbedo[0];

// The default albedo of material `index` (the table's last entry past its end).
inline constexpr const double* default_material_albedo(uint32_t index) {
  return kMaterialAlbedo[index < kMaterialTableSize ? index : kMaterialTableSize - 1];
}

}  // namespace sylva
