#!/usr/bin/env bash
# Smoke test of the soak (issue 12, docs/reliability.md "Soak"): experiments/soak.sh for 12 s
# (world -> camera -> symmetry -> tracker -> triangulation in a private network namespace) and
# the recorder's run.json must hold latencies for every stage and RSS and CPU for every process.
# usage: soak_smoke.sh SOURCE_DIR BIN_DIR
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
src=${1:?usage: soak_smoke.sh SOURCE_DIR BIN_DIR}
bin=${2:?usage: soak_smoke.sh SOURCE_DIR BIN_DIR}
nudge_test_require_namespace -n "a private network namespace"
nudge_test_work_dir
status=0
NUDGE_BIN=$bin "$src/experiments/soak.sh" --seconds 12 --warmup 2 --out "$work" || status=$?
[ $status -eq 77 ] && exit 77
if [ $status -ne 0 ] || [ ! -s "$work/run.json" ]; then
  echo "FAILED: soak.sh exit $status, no run.json" >&2
  cat "$work"/*.log >&2 || true
  exit 1
fi
python3 - "$work/run.json" "$work/rss.csv" <<'PY'
import json, sys
run = json.load(open(sys.argv[1]))
problems = []
for stage in ("camera", "symmetry", "tracker", "triangulation"):
    s = run["stages"].get(stage)
    if not s or s["latency_samples"] < 10 or not s["p50_ms"] > 0 or not s["p99_ms"] >= s["p50_ms"]:
        problems.append(f"stage {stage}: {s}")
for name in ("world", "camera", "symmetry", "tracker", "triangulation"):
    p = run["processes"].get(name)
    if not p or not p.get("rss_mb_last", 0) > 1 or "cpu_percent_mean" not in p or "socket_drops" not in p:
        problems.append(f"process {name}: {p}")
for channel in ("SYMMETRY_LEFT", "TRACK_RIGHT", "AXES"):
    if run["channels"].get(channel, {}).get("camera_frames_unanswered", -1) < 0:
        problems.append(f"channel {channel}: no unanswered count")
rows = open(sys.argv[2]).read().splitlines()
if len(rows) < 5 * 10:
    problems.append(f"rss.csv: {len(rows)} rows, expected a sample a second per process")
if problems:
    print("FAILED:\n  " + "\n  ".join(problems), file=sys.stderr)
    sys.exit(1)
print("PASSED: soak smoke: " + ", ".join(f"{k} p99 {v['p99_ms']:.0f} ms" for k, v in run["stages"].items()))
PY
