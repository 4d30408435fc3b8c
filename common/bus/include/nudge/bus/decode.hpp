#pragma once
// Decoding a message off the bus without trusting it.
//
// LCM 1.3.1's generated decode() returns -1 for most bad input, but it can also THROW (a string
// that declares length 0 or a negative length, an array size of -1) and it allocates an array of
// the declared size before checking that the bytes are there (a 114-byte image_t may declare a
// 2 GB payload). decode_message() turns all of that into an error message instead.
#include <exception>
#include <string>
#include <type_traits>

#include "nudge/image_t.hpp"

namespace nudge::bus {

// What is wrong with an encoded image_t (fingerprint included) whose camera string or `size`
// declares more bytes than `size_bytes` holds, or a negative length; "" when they fit.
std::string check_encoded_image(const void* data, int size_bytes);

// What is wrong with the element count of a variable-length array in an encoded message of the
// named type (arm_command_t, candidates_t, axes_t, symmetry_lines_t, track_t, sim_state_t,
// contours_t, recognition_t): negative, or more elements than the bytes left could hold. decode() would
// allocate the declared count first: 157 bytes of arm_command_t could ask for 16 GB (found by
// fuzz_messages). "" when they fit or the type has no such array.
std::string check_declared_lengths(const std::string& type_name, const void* data, int size_bytes);

// Length checks done before decoding, so that no declared length is allocated unchecked.
template <typename Msg>
std::string check_before_decode(const void* data, int size_bytes) {
  if constexpr (std::is_same_v<Msg, image_t>) return check_encoded_image(data, size_bytes);
  return check_declared_lengths(Msg::getTypeName(), data, size_bytes);
}

// Decodes `size_bytes` bytes into *msg. Returns "" on success, else why the bytes are not a Msg.
template <typename Msg>
std::string decode_message(const void* data, int size_bytes, Msg* msg) {
  const std::string problem = check_before_decode<Msg>(data, size_bytes);
  if (!problem.empty()) return problem;
  const std::string what = std::to_string(size_bytes) + " bytes do not decode as " + Msg::getTypeName();
  try {
    if (msg->decode(data, 0, size_bytes) < 0) return what;
  } catch (const std::exception& e) {
    return what + " (" + e.what() + ")";
  }
  return {};
}

}  // namespace nudge::bus
