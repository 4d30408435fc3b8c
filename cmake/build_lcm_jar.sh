#!/bin/sh
# Generates Java classes for the nudge LCM types and packs them into a jar for lcm-spy.
# usage: build_lcm_jar.sh LCM_GEN JAVAC JAR LCM_JAR WORK_DIR OUT_JAR FILE.lcm...
set -e
lcm_gen=$1; javac=$2; jar=$3; lcm_jar=$4; work=$5; out=$6
shift 6
rm -rf "$work"
mkdir -p "$work/src" "$work/classes" "$(dirname "$out")"
"$lcm_gen" -j --jpath "$work/src" "$@"
"$javac" -nowarn -cp "$lcm_jar" -d "$work/classes" "$work"/src/nudge/*.java
"$jar" cf "$out.tmp" -C "$work/classes" .
mv "$out.tmp" "$out"
