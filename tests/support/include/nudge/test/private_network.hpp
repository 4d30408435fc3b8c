#pragma once
// A network of the test's own for integration tests that run services over UDP multicast: a new
// network namespace (root only) whose loopback carries LCM's multicast group, so that no traffic
// leaves the test and two tests (or checkouts) running at once do not hear each other.
#include <gtest/gtest.h>

#include <string>

namespace nudge::test {

// The LCM URL the services use inside the namespace (ttl=0: loopback only; 16 MB receive buffers).
inline const std::string kPrivateLcmUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216";

enum class PrivateNetwork {
  kReady,         // this process (and what it starts from now on) is in a namespace of its own
  kNotPermitted,  // not root, or no network namespaces here: the test is skipped
  kRouteFailed,   // the namespace is made but its loopback could not be set up
};

// Moves this process into a new network namespace, brings its loopback up with the multicast
// route, and asks for larger socket buffers where the kernel lets a namespace have them (not
// needed to pass).
PrivateNetwork enter_private_network();

}  // namespace nudge::test

// In a test body, first: skips the test unless it can have a network of its own (root), fails it
// when the namespace's loopback cannot be set up.
#define NUDGE_TEST_ENTER_PRIVATE_NETWORK()                                                                   \
  do {                                                                                                       \
    const ::nudge::test::PrivateNetwork nudge_network_ = ::nudge::test::enter_private_network();            \
    if (nudge_network_ == ::nudge::test::PrivateNetwork::kNotPermitted)                                      \
      GTEST_SKIP() << "needs root to make a private network namespace";                                      \
    ASSERT_EQ(nudge_network_, ::nudge::test::PrivateNetwork::kReady)                                         \
        << "ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo failed in the new namespace"; \
  } while (false)
