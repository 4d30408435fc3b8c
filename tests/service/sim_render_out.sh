#!/usr/bin/env bash
# nudge-sim-render --out DIR with a missing DIR used to write nothing and say nothing (issue 12):
# it must refuse before simulating (exit 2, naming the directory), and write into one that exists.
# usage: sim_render_out.sh NUDGE_SIM_RENDER SCENE
set -uo pipefail
render=${1:?usage: sim_render_out.sh NUDGE_SIM_RENDER SCENE}
scene=${2:?usage: sim_render_out.sh NUDGE_SIM_RENDER SCENE}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

out=$("$render" "$scene" --out "$work/missing" --repeat 1 2>&1)
rc=$?
if [ $rc -ne 2 ] || ! grep -q -- "--out $work/missing: no such directory" <<<"$out"; then
  echo "FAILED: exit $rc, output: $out" >&2
  exit 1
fi
[ ! -e "$work/missing" ] || { echo "FAILED: the directory was created" >&2; exit 1; }
"$render" "$scene" --out "$work" --repeat 1 >/dev/null 2>&1 || { echo "FAILED: rendering into $work" >&2; exit 1; }
for f in left.png right.png left_still.png right_still.png; do
  [ -s "$work/$f" ] || { echo "FAILED: $work/$f not written" >&2; exit 1; }
done
echo "PASSED: a missing --out is refused by name; an existing one receives the images"
