#pragma once
// The camera's simulation backend (--source sim): renders the world service's states.
#include <cstdint>
#include <string>

#include "nudge/bus/service.hpp"

namespace nudge::camera_service {

struct SimOptions {
  std::string scene_file;   // the scene the world service simulates (objects matched by name)
  double noise_sigma = -1;  // Gaussian pixel noise in grey levels; < 0: the scene's
  bool snapshots = false;   // answer CAMERA_SNAPSHOT_REQUEST with 1280x960 stills
  int8_t pixel_format = 0;  // image_t::FORMAT_* of the published frames
  int8_t snapshot_format = 0;  // and of the stills
  int jpeg_quality = 90;
  int count = 0;            // stop after this many stereo pairs; 0 = no limit
  int max_lag_ms = 0;        // > 0: states that waited longer in the input queue are not drawn
  int motion_blur = 0;      // > 1: average this many renders across the interval since the last
                            // state (the shutter open for the whole frame); 0 or 1: sharp
};

// Loads the scene (SceneError names the file and field), starts the service and renders one
// stereo pair per SIM_STATE until stopped. Returns the exit code.
int run_sim_camera(bus::Service& service, const SimOptions& options);

}  // namespace nudge::camera_service
