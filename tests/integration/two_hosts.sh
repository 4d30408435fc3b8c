#!/usr/bin/env bash
# Integration test (issue 12, "Several hosts"): the services split over two hosts as on a lab's
# LAN. Two network namespaces ("robot": world, camera, arm, a monitor; "workstation": symmetry,
# triangulation, the supervisor, a monitor) joined by a veth pair, each with its own address and
# the LCM group routed on the veth, LCM at ttl=1. Both namespaces live inside a private one of
# the test's own, so nothing reaches the host's network. Checks:
#   - ttl=0 keeps traffic on its host: a camera publishing at ttl=0 on the robot is not heard on
#     the workstation (docs/reliability.md: keeping a robot's channels private);
#   - at ttl=1 the segmentation loop runs across the two hosts as on one: camera frames and
#     SIM_STATE go robot -> workstation, ARM_COMMAND workstation -> robot, and the cup is
#     segmented (summary.json: segmented 1);
#   - heartbeats are seen on both sides: a service SIGKILLed on one host is named silent by the
#     monitor on the other (symmetry killed on the workstation, the camera on the robot).
# usage: two_hosts.sh BIN_DIR SOURCE_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: two_hosts.sh BIN_DIR SOURCE_DIR}
src=${2:?usage: two_hosts.sh BIN_DIR SOURCE_DIR}
nudge_test_in_private_network "$@"
nudge_test_work_dir
scene=$src/common/sim/scenes/single_cup.yaml
calibration=$src/config/calibration_sim.yaml
group=239.255.76.67
url="udpm://$group:7667?ttl=1&recv_buf_size=16777216"

# Two hosts: a network namespace each, held open by a sleeping process; a veth pair between them.
unshare -n sleep 600 & robot=$!
unshare -n sleep 600 & workstation=$!
sleep 0.2
if ! ip link add nudge-robot type veth peer name nudge-ws 2>"$work/veth.err"; then
  echo "SKIPPED: cannot make a veth pair: $(cat "$work/veth.err")" >&2
  exit 77
fi
ip link set nudge-robot netns $robot
ip link set nudge-ws netns $workstation
host_setup() {  # PID INTERFACE ADDRESS: loopback, the LAN address, the LCM group routed on the LAN
  nsenter -t "$1" -n sh -ec "ip link set lo up; ip addr add $3/24 dev $2; ip link set $2 up multicast on
                             ip route add $group/32 dev $2"
}
host_setup $robot nudge-robot 10.76.67.1
host_setup $workstation nudge-ws 10.76.67.2
# Commands run "on" a host (nsenter execs them: $! is the service's own pid).
on_robot="nsenter -t $robot -n"
on_workstation="nsenter -t $workstation -n"

# ttl=0: the camera's heartbeats stay on the robot.
$on_workstation lcm-logger --lcm-url "$url" "$work/ttl0.lcmlog" 2>/dev/null & logger=$!
sleep 0.5
$on_robot timeout -s INT 3 "$bin/nudge-camera" --lcm-url "udpm://$group:7667?ttl=0" --source sim --scene "$scene" \
  2>"$work/camera_ttl0.log" || true  # its heartbeats: three in 3 s
grep -q "started:" "$work/camera_ttl0.log" || { echo "FAILED: the ttl=0 camera did not start" >&2; cat "$work/camera_ttl0.log" >&2; exit 1; }
kill -INT $logger; wait $logger || true
heard_ttl0=$(stat -c %s "$work/ttl0.lcmlog" 2>/dev/null || echo 0)
[ "$heard_ttl0" = 0 ] || { echo "FAILED: the workstation heard $heard_ttl0 bytes sent at ttl=0 on the robot" >&2; exit 1; }

# ttl=1: the loop across the two hosts.
$on_workstation "$bin/nudge-symmetry" --lcm-url "$url" --lines 5 --theta-min -25 --theta-max 25 --once-per-row \
  --mirror-tolerance 15 2>"$work/symmetry.log" & symmetry=$!
$on_workstation "$bin/nudge-triangulation" --lcm-url "$url" --calibration "$calibration" 2>"$work/triangulation.log" &
$on_workstation "$bin/nudge-monitor" --lcm-url "$url" 2>"$work/monitor_workstation.log" &
$on_robot "$bin/nudge-camera" --lcm-url "$url" --source sim --scene "$scene" --snapshots 2>"$work/camera.log" & camera=$!
$on_robot "$bin/nudge-arm" --lcm-url "$url" --backend sim --clock sim 2>"$work/arm.log" &
$on_robot "$bin/nudge-monitor" --lcm-url "$url" 2>"$work/monitor_robot.log" &
for s in symmetry triangulation camera arm monitor_robot monitor_workstation; do
  wait_for 30 "$s started" log_has "started:" "$work/$s.log"
done
$on_robot "$bin/nudge-world" --lcm-url "$url" --scene "$scene" --realtime-factor 1 --rate 10 2>"$work/world.log" &
status=0
$on_workstation timeout -s INT 200 "$bin/nudge-supervisor" --lcm-url "$url" --calibration "$calibration" \
  --out "$work" --run-id two_hosts --first-seq 1000 --max-attempts 2 2>"$work/supervisor.log" || status=$?
summary=$(cat "$work/two_hosts/summary.json" 2>/dev/null || true)
if [ $status -ne 0 ] || ! grep -q '"segmented":1,' <<<"$summary"; then
  echo "FAILED: the loop across two hosts (supervisor exit $status): $summary" >&2
  tail -n 30 "$work"/*.log >&2
  exit 1
fi
grep -h "ended:" "$work/supervisor.log"

# Heartbeats both ways: each monitor names the other host's killed service.
kill -KILL $symmetry; wait $symmetry 2>/dev/null || true
wait_for 10 "the robot's monitor naming the killed symmetry" log_has "no heartbeat: .*symmetry" "$work/monitor_robot.log"
kill -KILL $camera; wait $camera 2>/dev/null || true
wait_for 10 "the workstation's monitor naming the killed camera" \
  log_has "no heartbeat: .*camera" "$work/monitor_workstation.log"
grep -h "no heartbeat" "$work/monitor_robot.log" "$work/monitor_workstation.log"
echo "PASSED: ttl=0 stayed on its host; at ttl=1 the loop segmented the cup across two hosts; heartbeats seen both ways"
