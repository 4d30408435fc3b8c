#pragma once
// The fuzz targets (issue 12), shared by the libFuzzer programs (-DNUDGE_FUZZ=ON, clang) and by
// fuzz_replay_test (any compiler), which runs every kept input through the same code so that
// what a fuzzer once found stays fixed. Each target takes arbitrary bytes, feeds them to code a
// service or tool runs on untrusted input, and accepts only the documented outcomes: a value,
// or the error the API names. Anything else (a crash, a sanitizer report, another exception)
// is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace nudge::fuzz {

struct Target {
  std::string name;  // also the folder of its inputs: tests/fuzz/corpus/NAME, tests/fuzz/crashes/NAME
  int (*run)(const uint8_t* data, size_t size);
};

// Every message type a service subscribes to, through bus::decode_message (and bus::to_mat for
// the images that decode).
int fuzz_messages(const uint8_t* data, size_t size);
// Compressed image bytes, as a PNG/MJPEG image_t through bus::to_mat (header check, then decode).
int fuzz_image(const uint8_t* data, size_t size);
// A calibration file (geometry::load_rig).
int fuzz_calibration(const uint8_t* data, size_t size);
// A workspace file (robot::load_workspace).
int fuzz_workspace(const uint8_t* data, size_t size);
// The symmetry detector on an edge set built from the bytes (size, parameters, points).
int fuzz_detector(const uint8_t* data, size_t size);
#ifdef NUDGE_FUZZ_HAVE_SIM
// A scene file (sim::load_scene).
int fuzz_scene(const uint8_t* data, size_t size);
#endif

const std::vector<Target>& targets();

}  // namespace nudge::fuzz
