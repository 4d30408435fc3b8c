#!/usr/bin/env bash
# lcm-spy finds every nudge type in the jar the build makes (what scripts/spy.sh puts on the
# CLASSPATH). Headless: the Spy class lists the types it found before it opens its window.
# usage: spy_types.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build=${1:?usage: spy_types.sh BUILD_DIR SOURCE_DIR}
src=${2:?usage: spy_types.sh BUILD_DIR SOURCE_DIR}
jar="$build/share/nudge_lcmtypes.jar"
[ -f "$jar" ] || { echo "FAILED: $jar was not built" >&2; exit 1; }
expected=$(ls "$src"/lcmtypes/*.lcm | wc -l)
found=$(CLASSPATH="$jar:/usr/share/java/lcm.jar:/usr/share/java/jchart2d.jar" \
        timeout 60 java -Djava.awt.headless=true lcm.spy.Spy 2>&1 | sed -n 's/^Found \([0-9]*\) LCM types.*/\1/p')
if [ "$found" != "$expected" ]; then
  echo "FAILED: lcm-spy found '${found}' nudge types, lcmtypes/ has $expected" >&2
  exit 1
fi
echo "PASSED: lcm-spy finds all $expected nudge types"
