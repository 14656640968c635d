// impostor.h — the impostor cards of a glTF export's last level of detail
// (core/io/gltf_lod.h) drawn by the CPU ray caster: the CardRenderer export_gltf asks for.
#pragma once

#include <cstdint>
#include <map>

#include "core/io/gltf.h"
#include "core/scene/scene.h"

namespace sylva {

// A CardRenderer that ray-casts the plant alone (no ground, no fog) with `materials` (the
// scene's table) from 100 card heights away along the card's normal — nearly orthographic
// — with the sun behind the camera and above, `spp` samples a pixel. Colour: the beauty
// in sRGB; alpha: 1 where the pixel's centre sees the plant, else 0, and there the mean
// colour of the covered pixels (no sky or ground bleeds into the card's filtered edge).
CardRenderer cpu_card_renderer(std::map<uint32_t, SceneMaterial> materials, uint32_t spp = 4);

}  // namespace sylva
