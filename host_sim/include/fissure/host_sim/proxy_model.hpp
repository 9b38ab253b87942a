#pragma once
// The proxy builder's const model for a scene's host simulation: the scene's Hunt-Crossley law,
// the tool planes of each jaw, and which rt tool part each host jaw's contacts act on. Every
// place that builds proxies from a HostSimulation (the session's host step, `fissure render`'s
// patches, the proxy tests) takes its model from here, so the jaw → part rule is written once.
#include <optional>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/proxy_builder.hpp"
#include "fissure/host_sim/scene_description.hpp"

namespace fissure::host {

/// The model for `sim`, built from `scene`; nullopt when the simulation has no tool nodes to
/// build from (the bullet collision method).
[[nodiscard]] std::optional<ProxyBuilderModel> proxy_model_for(const SceneDescription& scene, const HostSimulation& sim);

}  // namespace fissure::host
