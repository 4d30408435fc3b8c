#pragma once
// sim_state_t -> the poses a renderer of the simulated lab needs (nudge::sim::PoseSnapshot): used
// by the camera's sim backend to draw what the world service simulated, and by experiments that
// re-render a recorded run's ground truth.
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim_state_t.hpp"

namespace nudge::bus {

// Throws std::invalid_argument when num_objects disagrees with the objects sent.
sim::PoseSnapshot poses_of(const sim_state_t& state);

}  // namespace nudge::bus
