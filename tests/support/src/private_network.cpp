#include "nudge/test/private_network.hpp"

#include <sched.h>
#include <unistd.h>

#include <cstdlib>

namespace nudge::test {

PrivateNetwork enter_private_network() {
  if (geteuid() != 0 || unshare(CLONE_NEWNET) != 0) return PrivateNetwork::kNotPermitted;
  if (std::system("ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo") != 0)
    return PrivateNetwork::kRouteFailed;
  // net.core.rmem_max is global: a namespace can usually neither raise it nor hide it (scripts/lib.sh).
  (void)std::system("sysctl -qw net.core.rmem_max=16777216 net.core.rmem_default=16777216 2>/dev/null");
  return PrivateNetwork::kReady;
}

}  // namespace nudge::test
