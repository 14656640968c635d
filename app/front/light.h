// light.h — the light front ends grow `?E` grammars in (docs/spec/light.md): sylva's sun and
// sky photons on every core (core/cpu/light_tracer.h), one shared, stateless oracle.
// Header-only, so the Python module (which does not link app/front's GL parts) shares it.
#pragma once

#include "core/cpu/light_tracer.h"

namespace sylva {

inline const LightOracle& cpu_light_oracle() {
  static const PhotonLightOracle oracle(0);
  return oracle;
}

}  // namespace sylva
