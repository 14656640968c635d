// light_tracer.h — sylva's answer to the grammar's light queries (docs/spec/light.md,
// core/scene/light_queries.h): sun and sky photons traced through the exact frusta and
// polygon leaves of every plant, and the light they carry through each sensor sphere.
//
// The estimator (docs/light.md): N photons in K = clamp(√N/4, 1, 4096) batches of
// parallel photons. A batch's direction ω toward the light is drawn, from a stream keyed
// by (environment.seed, step), from the sun's disc (uniform) for K_sun = ⌊K·s + u⌋ batches
// — s the sun's share of the open-sky scalar irradiance (sky.h), u uniform: unbiased — and
// from the sky (in proportion to its radiance over solid angle) for the rest, each set
// spread by the R2 sequence. Photon i of a batch leaves a uniform point of the disc of
// radius R perpendicular to ω, tangent to the bounding sphere (centre c, radius R) of the
// plants and sensors. Every direction's disc covers the whole sphere, so with no obstacle
// the photons' track length through a sensor of radius r has the mean N·(4/3)r³/R²
// whatever the sky; q is the track length the sensor receives over that mean (a
// track-length estimate of scalar irradiance), its standard error from the photons'
// spread (as if independent: the shared directions of a batch make it an
// over-estimate where directions are stratified), and its direction the track-weighted
// mean of ω. Parallel photons make the search exact and cheap: each batch projects the
// sensors onto its disc in a 2D grid, and a photon tests only the sensors of its cell.
//
// A photon's track ends at the ground plane and, for each sensor, at the first surface it
// meets that does not cross the sensor's sphere (light.md: a sensor ignores the twig it
// sits on and its own leaf). "Crosses" is decided conservatively: a frustum whose axis
// segment passes within r + its larger radius of the centre, a leaf whose polygon passes
// within r (exact point-triangle distance). Past a surface some sensor ignores, the
// photon is traced on (at most kMaxLightHitsPerPhoton surfaces), from the far side of a
// frustum's solid or just past a leaf.
//
// The plants are skinned with the oracle's SkinOptions styled by the scene's skin (the
// defaults: the frusta every renderer draws); where they blend their crotches
// (SkinOptions::blend_crotches, docs/joints.md) a photon meets the fillets too, each named
// by its heavier group's frustum (crotch_tracer.h nearest_wood), so a sensor ignores a
// fillet of the twig it sits on as it ignores the twig.
//
// Sums are kept in fixed point (integers), so the answers do not depend on how photons
// are split over threads: the same inputs give the same answers on any thread count.
// Cost: O(N·(sensors per cell + log P per photon that crosses one) + K·sensors) for P
// primitives; memory O(P + sensors·threads).
#pragma once

#include <span>
#include <vector>

#include "core/geometry/skin.h"
#include "core/scene/light_queries.h"

namespace sylva {

inline constexpr int kMaxLightHitsPerPhoton = 64;

class PhotonLightOracle final : public LightOracle {
 public:
  explicit PhotonLightOracle(unsigned threads = 0, SkinOptions skin = {}) : threads_(threads), skin_(skin) {}
  Expected<std::vector<LightAnswer>> answer(std::span<const Skeleton> plants, std::span<const glm::dvec3> sensors,
                                            const Scene& scene, int64_t step,
                                            LightAnswerStats* stats = nullptr) const override;

 private:
  unsigned threads_;
  SkinOptions skin_;
};

// The backward estimate of the same q (tests cross-check the photons with it): from each
// sensor's centre, `rays` rays toward directions drawn as the photons draw theirs, each
// counting 1 when it leaves the plants' bounding sphere without meeting a surface the
// sensor does not ignore, nor the ground. Its std_error is the binomial one.
Expected<std::vector<LightAnswer>> gather_light(std::span<const Skeleton> plants, std::span<const glm::dvec3> sensors,
                                                const Scene& scene, int64_t step, uint64_t rays,
                                                const SkinOptions& skin = {});

}  // namespace sylva
