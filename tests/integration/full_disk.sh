#!/usr/bin/env bash
# Integration test (issue 12): a calibration written to a full disk. nudge-calibrate writes its
# rig file atomically (temporary file, fsync, rename): on a full file system it must fail with a
# clear error (exit 1, naming the file and "No space left on device"), leave the old calibration
# byte for byte intact and no temporary file behind. The disk is a 64 KB tmpfs in a private mount
# namespace (unshare -m, root), so nothing outside the test sees it.
# usage: full_disk.sh BIN_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
bin=${1:?usage: full_disk.sh BIN_DIR}
data=/usr/share/doc/opencv-doc/examples/data

nudge_test_require_namespace -m "a private mount namespace"
[ -f "$data/left01.jpg" ] || { echo "FAILED: $data is missing: install opencv-doc (scripts/lib.sh does)" >&2; exit 1; }

nudge_test_work_dir
mkdir "$work/disk"

unshare -m bash -s "$bin" "$work" "$data" <<'INNER'
set -euo pipefail
bin=$1; work=$2; data=$3
mount --make-rprivate /
mount -t tmpfs -o size=64k tmpfs "$work/disk"
printf 'old calibration: must survive\n' >"$work/disk/rig.yaml"
cp "$work/disk/rig.yaml" "$work/old.yaml"
dd if=/dev/zero of="$work/disk/filler" bs=1k 2>/dev/null || true  # until the disk is full
status=0
"$bin/nudge-calibrate" --board 9x6 --square 0.025 --left "$data/left0[1-3].jpg" --right "$data/right0[1-3].jpg" \
  --out "$work/disk/rig.yaml" >"$work/out.txt" 2>"$work/err.txt" || status=$?
fail() { echo "FAILED: $*" >&2; cat "$work/err.txt" >&2; exit 1; }
[ $status -eq 1 ] || fail "exit code $status, expected 1"
grep -q "cannot write .*/disk/rig.yaml.*: No space left on device" "$work/err.txt" || fail "no clear error naming the file"
cmp -s "$work/disk/rig.yaml" "$work/old.yaml" || fail "the old calibration was changed"
if ls "$work/disk" | grep -qv "^rig.yaml$\|^filler$"; then fail "a temporary file was left behind"; fi
rm "$work/disk/filler"  # room again: the same command now replaces the old file
"$bin/nudge-calibrate" --board 9x6 --square 0.025 --left "$data/left0[1-3].jpg" --right "$data/right0[1-3].jpg" \
  --out "$work/disk/rig.yaml" >/dev/null 2>&1 || fail "no calibration with room on the disk"
grep -q "camera_matrix\|K\b\|left" "$work/disk/rig.yaml" || fail "the new calibration is not there"
echo "PASSED: full disk -> '$(grep -o 'cannot [a-z]* [^ ]*: No space left on device' "$work/err.txt" | head -1)', old file intact"
INNER
