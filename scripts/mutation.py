#!/usr/bin/env python3
"""Mutation check of the core algorithms: do the unit tests notice plausible one-line bugs?

Each mutant replaces one exact piece of source (it must occur exactly once) with a plausible bug:
a sign flip, an off-by-one, a dropped term, swapped operands, > for >=. For each mutant the
affected unit-test binaries are rebuilt in a build directory of their own (build-mutation; ccache
makes the rebuilds cheap) and run with a timeout. A mutant is killed when a test fails or times
out. Every source file is restored afterwards, whatever happens (Ctrl-C, a crash: a copy of the
file being mutated waits in build-mutation/backup/ and is put back at the next start).

Not a CI step (about an hour on 2 shared cores): run it before releasing a change to a core
algorithm (docs/architecture.md, "Tests, in layers"):

    scripts/mutation.py                 # every mutant; writes docs/results/mutation.{json,md}
    scripts/mutation.py --only kalman   # the mutants whose id contains "kalman" (no results written)
    scripts/mutation.py --list          # the mutants, without running anything
    scripts/mutation.py --rerun-survivors  # after adding tests: only the last run's survivors (and
                                           # mutants new to the list), merged into the results

Survivors must be explained: a mutant that survives without a `harmless` reason in the list
below makes the script exit 1 (either add a test that kills it or say why it cannot matter).
"""
import argparse
import datetime
import json
import os
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.path.join(ROOT, "build-mutation")
BACKUP = os.path.join(BUILD, "backup")
RESULTS = os.path.join(ROOT, "docs", "results")
TEST_TIMEOUT_S = 300  # per test binary; the slowest takes ~10 s unmutated

SYMMETRY = ["symmetry_test"]
SEGMENTATION = ["segmentation_test"]
MOTION = ["motion_segmentation_tests"]
GEOMETRY = ["geometry_test"]
TRACKING = ["tracking_test"]
ROBOT = ["robot_test", "robot_workspace_tests"]

DETECTOR = "common/symmetry/src/detector.cpp"
VOTE = "common/symmetry/src/vote.cpp"
QUANTISE = "common/symmetry/src/quantise.hpp"
SEPT = "common/segmentation/src/sept.cpp"
CONTOUR = "common/segmentation/src/contour.cpp"
SEGMENT = "common/segmentation/src/segment.cpp"
MOTION_CPP = "common/segmentation/src/motion.cpp"
TRIANGULATION = "common/geometry/src/triangulation.cpp"
KALMAN = "common/tracking/src/kalman.cpp"
KINEMATICS = "common/robot/src/kinematics.cpp"


def m(ident, path, find, replace, tests, harmless=None):
    return {"id": ident, "file": path, "find": find, "replace": replace, "tests": tests, "harmless": harmless}


MUTANTS = [
    # ---- detector: sub-bin refinement and peak finding (thesis eq. 3.1-3.2)
    m("detector.fallback_dr_sign", DETECTOR, "dr = hrr < 0 ? -gr / hrr : 0;", "dr = hrr < 0 ? gr / hrr : 0;", SYMMETRY),
    m("detector.fallback_dt_sign", DETECTOR, "dt = htt < 0 ? -gt / htt : 0;", "dt = htt < 0 ? gt / htt : 0;", SYMMETRY),
    m("detector.hrt_divisor", DETECTOR, "V(1, -1)) / 4;", "V(1, -1)) / 2;", SYMMETRY),
    m("detector.newton_dr_term_sign", DETECTOR, "dr = (-gr * htt + gt * hrt) / det;", "dr = (-gr * htt - gt * hrt) / det;",
      SYMMETRY),
    m("detector.gradient_swapped", DETECTOR, "const double gr = (V(1, 0) - V(-1, 0)) / 2",
      "const double gr = (V(-1, 0) - V(1, 0)) / 2", SYMMETRY),
    m("detector.maximum_test", DETECTOR, "if (hrr < 0 && det > 1e-12)", "if (hrr > 0 && det > 1e-12)", SYMMETRY),
    m("detector.wrap_mirror_off_by_one", DETECTOR, "if (mirror) b = m.cols - 1 - b;", "if (mirror) b = m.cols - b;",
      SYMMETRY),
    m("detector.peak_ratio_dropped", DETECTOR, "if (best < params_.min_peak_ratio * first_peak) break;",
      "if (false && best < params_.min_peak_ratio * first_peak) break;", SYMMETRY),
    m("detector.wrap_r_not_negated", DETECTOR, "if (theta_deg > 90) { theta_deg -= 180; r = -r; }",
      "if (theta_deg > 90) { theta_deg -= 180; }", SYMMETRY),
    m("detector.offset_sign", DETECTOR, "double r = b + off.x - acc.r_max;", "double r = b - off.x - acc.r_max;",
      SYMMETRY),
    m("detector.skew_r_scale", DETECTOR, "r *= std::cos(phi);", "r /= std::cos(phi);", SYMMETRY),
    m("detector.skew_theta_sign", DETECTOR, "theta -= phi;", "theta += phi;", SYMMETRY),
    m("detector.suppression_off_by_one", DETECTOR, "dr <= params_.suppress_r; ++dr", "dr < params_.suppress_r; ++dr",
      SYMMETRY),
    # ---- voting (Algorithm 1): the fast path, the reference loop and their shared quantisation
    m("quantise.rotation_sign", QUANTISE, "return (u2 * t.c + v2 * t.s + (1 << (kFixedShift - 1))) >> kFixedShift;",
      "return (u2 * t.c - v2 * t.s + (1 << (kFixedShift - 1))) >> kFixedShift;", SYMMETRY),
    m("quantise.row_sign", QUANTISE, "return (v2 * t.c - u2 * t.s + (1 << kFixedShift)) >> (kFixedShift + 1);",
      "return (v2 * t.c + u2 * t.s + (1 << kFixedShift)) >> (kFixedShift + 1);", SYMMETRY),
    m("quantise.dmin_factor_dropped", QUANTISE, "std::ceil(2.0 * p.dmin - 1e-9)", "std::ceil(p.dmin - 1e-9)", SYMMETRY),
    m("quantise.bin_rounding", QUANTISE, "return ((s + sum_offset + 2) >> 2)", "return ((s + sum_offset + 1) >> 2)",
      SYMMETRY),
    m("vote.copy_dropped", VOTE, "h[2 * hist_size + idx] + h[3 * hist_size + idx];", "h[2 * hist_size + idx];",
      SYMMETRY),
    m("vote.rounding_offset", VOTE, "static_cast<uint32_t>(layout.dmax2 - layout.dmin2), offset + 2};",
      "static_cast<uint32_t>(layout.dmax2 - layout.dmin2), offset + 1};", SYMMETRY),
    m("vote.reference_dmax_boundary", VOTE, "if (dx < layout.dmin2 || dx > layout.dmax2) continue;",
      "if (dx < layout.dmin2 || dx >= layout.dmax2) continue;", SYMMETRY),
    m("vote.centre_off_by_one", VOTE, "u2_[k] = 2 * p.x - (edges.width - 1);",
      "u2_[k] = 2 * p.x - edges.width;", SYMMETRY),
    m("vote.once_per_row_inverted", VOTE, "if (s.stamp[bins[q]] == row_id) continue;",
      "if (s.stamp[bins[q]] != row_id) continue;", SYMMETRY),
    m("vote.max_row_pixels_boundary", VOTE, "count > params_.max_row_pixels)) continue;",
      "count >= params_.max_row_pixels)) continue;", SYMMETRY),
    m("vote.skew_shift_sign", VOTE, "std::lround(-4.0 * row * tan_phi)", "std::lround(4.0 * row * tan_phi)", SYMMETRY),
    m("vote.short_row_partners", VOTE, "row_lanes & ~((2u << i) - 1));", "row_lanes & ~((4u << i) - 1));", SYMMETRY),
    # ---- SEPT (Algorithm 2), DP contour (Algorithms 3-4), back to the image
    m("sept.max_width_boundary", SEPT, "if (width > params_.max_width) break;", "if (width >= params_.max_width) break;",
      SEGMENTATION),
    m("sept.max_mid_boundary", SEPT, "if (deviation >= params_.max_mid) continue;",
      "if (deviation > params_.max_mid) continue;", SEGMENTATION),
    m("sept.column_floor", SEPT, "std::ceil(0.5 * width)", "std::floor(0.5 * width)", SEGMENTATION),
    m("sept.weight_factor_dropped", SEPT, "1.0 - deviation / (2.0 * params_.max_mid)",
      "1.0 - deviation / params_.max_mid", SEGMENTATION),
    m("sept.best_weight_inverted", SEPT, "cells[column] < weight) cells[column] = weight;",
      "cells[column] > weight) cells[column] = weight;", SEGMENTATION),
    m("sept.columns_off_by_one", SEPT, "std::ceil(params_.max_width / 2)) + 1;", "std::ceil(params_.max_width / 2));",
      SEGMENTATION),
    m("dp.horizontal_reward_swapped", CONTOUR, "sept[c] * p.reward_horizontal : p.penalty_horizontal;",
      "sept[c] * p.reward_vertical : p.penalty_horizontal;", SEGMENTATION),
    m("dp.start_anywhere_dropped", CONTOUR, "double best = std::max(0.0, reward);", "double best = reward;",
      SEGMENTATION,
      harmless="equivalent: it changes only cells whose score stays <= 0 (0 becomes a negative value). Such a "
               "cell is never a predecessor (above > 0), never the best cell, and a positive cell's own vertical "
               "score (>= w Rver) always beats a run arriving from it (<= w Rhor, Rhor < Rver), so best_path's "
               "cells and score are the same"),
    m("dp.zero_predecessor", CONTOUR, "if (above[k] > 0 && above[k] + reward > best) {",
      "if (above[k] >= 0 && above[k] + reward > best) {", SEGMENTATION,
      harmless="equivalent: best starts at max(0, reward), so 0 + reward > best never holds and a cell scoring "
               "0 is never chosen as a predecessor either way"),
    m("dp.vertical_penalty_swapped", CONTOUR, "sept[c] * p.reward_vertical : p.penalty_vertical;",
      "sept[c] * p.reward_vertical : p.penalty_horizontal;", SEGMENTATION),
    m("dp.backtrack_direction", CONTOUR, "t.from_left.at<uint8_t>(r, c)) {\n      --c;",
      "t.from_left.at<uint8_t>(r, c)) {\n      ++c;", SEGMENTATION),
    m("segment.left_side_sign", SEGMENT, "contour.left.push_back(place(-cell.column, v));",
      "contour.left.push_back(place(cell.column, v));", SEGMENTATION),
    m("segment.row_off_by_one", SEGMENT, "const double v = buffer.first_row + cell.row;",
      "const double v = buffer.first_row + cell.row + 1;", SEGMENTATION),
    m("segment.snap_comparison", SEGMENT, "if (d2 <= best) {", "if (d2 >= best) {", SEGMENTATION),
    # ---- motion segmentation (sec. 6.4)
    m("motion.pair_weaker_side", MOTION_CPP, "std::max(std::min(left, right_near), std::min(left_near, right));",
      "std::max(std::max(left, right_near), std::min(left_near, right));", MOTION),
    m("motion.threshold_boundary", MOTION_CPP, "if (half_width < 0 && pair >= threshold)",
      "if (half_width < 0 && pair > threshold)", MOTION),
    m("motion.opening_window", MOTION_CPP, "int value = windowed[y - run + 1];", "int value = windowed[y - run];",
      MOTION),
    m("motion.area_counts_rows", MOTION_CPP, "area += 2L * half_width[y] + 1;", "area += 1;", MOTION),
    m("motion.shift_sign", MOTION_CPP, ".dot(frame_before.normal) -\n                 line_before.r;",
      ".dot(frame_before.normal) +\n                 line_before.r;", MOTION),
    m("motion.facing_inverted", MOTION_CPP, "if (std::cos(line.theta - reference.theta) < 0) {",
      "if (std::cos(line.theta - reference.theta) > 0) {", MOTION),
    m("motion.mask_reach", MOTION_CPP, "const double reach = half_width[y] + 0.5, v = first_row + y;",
      "const double reach = half_width[y] - 0.5, v = first_row + y;", MOTION),
    m("motion.leading_half_swapped", MOTION_CPP, "const int after_x0 = leading_is_positive ? centre : 0;",
      "const int after_x0 = leading_is_positive ? 0 : centre;", MOTION),
    m("motion.median_factor_dropped", MOTION_CPP, "if (2 * seen >= total) return level;",
      "if (seen >= total) return level;", MOTION),
    m("motion.colour_channel_dropped", MOTION_CPP, "std::max(in[3 * x], std::max(in[3 * x + 1], in[3 * x + 2]))",
      "std::max(in[3 * x], in[3 * x + 1])", MOTION),
    m("motion.uncovered_inverted", MOTION_CPP, "if (image.contains(back) && mask.at<uint8_t>(back)) continue;",
      "if (image.contains(back) && !mask.at<uint8_t>(back)) continue;", MOTION),
    m("motion.foot_offset_sign", MOTION_CPP, "foot_before - rotation * foot_after +", "foot_before + rotation * foot_after +",
      MOTION),
    # ---- triangulation (sec. 4.1)
    m("triangulation.plane_normal_column", TRIANGULATION, "return solver.eigenvectors().col(0);",
      "return solver.eigenvectors().col(2);", GEOMETRY),
    m("triangulation.projection_sign", TRIANGULATION, "r1 -= r1.dot(normal) * normal;", "r1 += r1.dot(normal) * normal;",
      GEOMETRY),
    m("triangulation.depth_swapped", TRIANGULATION, "params.zmax * r1 / r1.z(), params.zmax * r2 / r2.z()",
      "params.zmax * r1 / r2.z(), params.zmax * r2 / r2.z()", GEOMETRY),
    m("triangulation.crossing_fraction", TRIANGULATION, "(distance[i] / (distance[i] - distance[j]))",
      "(distance[j] / (distance[i] - distance[j]))", GEOMETRY),
    m("triangulation.overlap_start", TRIANGULATION, "along(*lo1) > along(*lo2) ? *lo1 : *lo2;",
      "along(*lo1) < along(*lo2) ? *lo1 : *lo2;", GEOMETRY),
    m("triangulation.overlap_end", TRIANGULATION, "along(*hi1) < along(*hi2) ? *hi1 : *hi2;",
      "along(*hi1) > along(*hi2) ? *hi1 : *hi2;", GEOMETRY),
    m("triangulation.sample_spacing", TRIANGULATION, "static_cast<double>(i) / (samples - 1);",
      "static_cast<double>(i) / samples;", GEOMETRY,
      harmless="nearly equivalent: the samples only estimate the plane through the camera centre and the image "
               "line; stopping one sample short of the segment's end leaves every sample on that line, so the "
               "fitted plane moves only through the lens distortion's slight curvature of the undistorted "
               "samples (the end rays are kept either way)"),
    # ---- Kalman filter (sec. 5.2.4)
    m("kalman.joseph_krk_dropped", KALMAN, "p_ = i_kh * p_ * i_kh.transpose() + k * r * k.transpose();",
      "p_ = i_kh * p_ * i_kh.transpose();", TRACKING),
    m("kalman.transition_half", KALMAN, "m(0, 4) = m(1, 5) = 0.5;", "m(0, 4) = m(1, 5) = 1.0;", TRACKING),
    m("kalman.innovation_variance_swapped", KALMAN, "s(1, 1) += params_.measurement_var_theta;",
      "s(1, 1) += params_.measurement_var_r;", TRACKING),
    m("kalman.process_noise_off_by_one", KALMAN, "for (int i = 0; i < 6; ++i) p_(i, i) += params_.process_noise[i];",
      "for (int i = 0; i < 5; ++i) p_(i, i) += params_.process_noise[i];", TRACKING),
    m("kalman.innovation_sign", KALMAN, "return {m.r - x_(0), m.theta_deg - x_(1)};",
      "return {x_(0) - m.r, m.theta_deg - x_(1)};", TRACKING),
    m("kalman.normalise_parity", KALMAN, "if (static_cast<long long>(turns) % 2 != 0) line.r = -line.r;",
      "if (static_cast<long long>(turns) % 2 == 0) line.r = -line.r;", TRACKING),
    m("kalman.align_rounding", KALMAN, "std::round((theta_ref_deg - line.theta_deg) / 180.0);",
      "std::floor((theta_ref_deg - line.theta_deg) / 180.0);", TRACKING),
    m("kalman.hold_coupling_kept", KALMAN, "  p_.topRightCorner<2, 4>().setZero();\n", "", TRACKING),
    m("kalman.gate_without_inverse", KALMAN, "return nu.dot(innovation_covariance().ldlt().solve(nu));",
      "return nu.dot(innovation_covariance() * nu);", TRACKING),
    m("kalman.flip_sign_pattern", KALMAN, "t << -1, 1, -1, 1, -1, 1;", "t << -1, 1, 1, 1, -1, 1;", TRACKING),
    # ---- inverse kinematics (App. B)
    m("kinematics.theta6_sign_at_pi", KINEMATICS, "w.theta6 = w.theta4 - std::atan2(-r36(1, 0), -r36(0, 0));",
      "w.theta6 = std::atan2(-r36(1, 0), -r36(0, 0)) - w.theta4;", ROBOT),
    m("kinematics.theta6_sign_at_zero", KINEMATICS, "w.theta6 = std::atan2(r36(1, 0), r36(0, 0)) - w.theta4;",
      "w.theta6 = std::atan2(r36(1, 0), r36(0, 0)) + w.theta4;", ROBOT),
    m("kinematics.theta6_positive_branch", KINEMATICS, "w.theta6 = std::atan2(-r36(2, 1), r36(2, 0));",
      "w.theta6 = std::atan2(r36(2, 1), r36(2, 0));", ROBOT),
    m("kinematics.flip_branch_test", KINEMATICS, "positive_branch_has_no_flip = -r36(0, 2) >= 0;",
      "positive_branch_has_no_flip = r36(0, 2) >= 0;", ROBOT),
    m("kinematics.singular_branch_test", KINEMATICS, "if (r36(2, 2) > 0) {", "if (r36(2, 2) < 0) {", ROBOT),
    m("kinematics.alias_nearest", KINEMATICS,
      "const double distance = std::fabs(candidate - seed);\n    if (distance < best_distance) {",
      "const double distance = std::fabs(candidate - seed);\n    if (distance > best_distance) {", ROBOT),
    m("kinematics.theta1_offset_sign", KINEMATICS, "? phi + delta : phi + kPi - delta;", "? phi - delta : phi + kPi - delta;",
      ROBOT),
    m("kinematics.law_of_cosines_sign", KINEMATICS, "(l.a2 * l.a2 - l.d4 * l.d4 + rho * rho)",
      "(l.a2 * l.a2 + l.d4 * l.d4 + rho * rho)", ROBOT),
    m("kinematics.theta3_operands", KINEMATICS, "l.a2 - (u * c2 + p.z() * s2), p.z() * c2 - u * s2);",
      "l.a2 - (u * c2 + p.z() * s2), u * c2 - p.z() * s2);", ROBOT),
    m("kinematics.wrist_configuration", KINEMATICS, "c.wrist = std::cos(q[3]) >= 0", "c.wrist = std::sin(q[3]) >= 0",
      ROBOT),
    m("kinematics.tool_order", KINEMATICS, "return flange_pose(model, q) * model.tool;",
      "return model.tool * flange_pose(model, q);", ROBOT),
    m("kinematics.dh_sign", KINEMATICS, "st, ct * ca, -ct * sa,", "st, ct * ca, ct * sa,", ROBOT),
    m("kinematics.singular_flag", KINEMATICS, "wrist.sin_theta5 < options.wrist_singularity_tolerance;",
      "wrist.sin_theta5 > options.wrist_singularity_tolerance;", ROBOT),
]


def run(cmd, timeout=None):
    """Runs cmd in a process group of its own, killed whole on a timeout or an interrupt: a
    compiler left running would write an object of the mutated source after it was restored."""
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    return subprocess.CompletedProcess(cmd, proc.returncode, out)


def restore_backups():
    """Puts back a source file left mutated by a run that was killed outright."""
    if not os.path.isdir(BACKUP):
        return
    for name in os.listdir(BACKUP):
        with open(os.path.join(BACKUP, name)) as f:
            record = json.load(f)
        with open(os.path.join(ROOT, record["file"]), "w") as f:
            f.write(record["text"])
        os.remove(os.path.join(BACKUP, name))
        print(f"restored {record['file']} from an interrupted run", file=sys.stderr)


class Mutated:
    """Applies one mutant for the duration of a with-block; the original is always written back."""

    def __init__(self, mutant):
        self.mutant = mutant
        self.path = os.path.join(ROOT, mutant["file"])
        self.backup = os.path.join(BACKUP, mutant["id"] + ".json")

    def __enter__(self):
        with open(self.path) as f:
            self.original = f.read()
        count = self.original.count(self.mutant["find"])
        if count != 1:
            raise LookupError(f"{self.mutant['id']}: the text to mutate occurs {count} times in {self.mutant['file']}")
        os.makedirs(BACKUP, exist_ok=True)
        with open(self.backup + ".tmp", "w") as f:  # whole or not at all
            json.dump({"file": self.mutant["file"], "text": self.original}, f)
        os.replace(self.backup + ".tmp", self.backup)
        with open(self.path, "w") as f:
            f.write(self.original.replace(self.mutant["find"], self.mutant["replace"]))
        return self

    def __exit__(self, *exc):
        with open(self.path, "w") as f:
            f.write(self.original)
        os.utime(self.path, None)  # newer than any object built from the mutant
        os.remove(self.backup)
        return False


def build(targets):
    result = run(["nice", "cmake", "--build", BUILD, "-j2", "--target", *targets])
    return result.returncode == 0, result.stdout[-3000:]


def run_tests(targets):
    """None when every test passes, else what failed first."""
    for target in targets:
        binary = os.path.join(BUILD, "bin", target)
        try:
            result = run(["nice", binary, "--gtest_brief=1"], timeout=TEST_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            return f"{target}: timed out after {TEST_TIMEOUT_S} s"
        if result.returncode != 0:
            failed = [line.split("]", 1)[1].strip() for line in result.stdout.splitlines()
                      if line.startswith("[  FAILED  ]") and "," not in line and "listed below" not in line]
            return f"{target}: " + (", ".join(failed[:3]) if failed else f"exit {result.returncode}")
    return None


def cpu_model():
    out = subprocess.run(["lscpu"], stdout=subprocess.PIPE, text=True).stdout
    return next((l.split(":", 1)[1].strip() for l in out.splitlines() if l.startswith("Model name")), "unknown")


def score(outcomes):
    """The outcomes that count (the mutant built and its tests ran: killed or survived), and the killed ones."""
    scored = [o for o in outcomes if o["status"] in ("killed", "survived")]
    return scored, [o for o in scored if o["status"] == "killed"]


def write_results(outcomes, seconds):
    scored, killed = score(outcomes)
    survivors = [o for o in scored if o["status"] == "survived"]
    summary = {
        "mutants": len(scored),
        "killed": len(killed),
        "kill_ratio": round(len(killed) / len(scored), 3) if scored else None,
        "survivors": [{"id": o["id"], "file": o["file"], "mutation": o["mutation"], "reason": o["harmless"]}
                      for o in survivors],
        "not_compiling": [o["id"] for o in outcomes if o["status"] == "build_failed"],
        "outcomes": outcomes,
        "runtime_s": round(seconds),
        "cpu": cpu_model(),
        "commit": run(["git", "rev-parse", "HEAD"]).stdout.strip(),
        "date": datetime.datetime.utcnow().strftime("%Y-%m-%dT%H:%MZ"),
    }
    os.makedirs(RESULTS, exist_ok=True)
    for name, text in (("mutation.json", json.dumps(summary, indent=2) + "\n"), ("mutation.md", markdown(summary))):
        tmp = os.path.join(RESULTS, name + ".tmp")
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, os.path.join(RESULTS, name))


def markdown(s):
    lines = [
        "# Mutation check of the core algorithms",
        "",
        f"`scripts/mutation.py` planted {s['mutants']} one-line bugs (sign flips, off-by-ones, dropped terms, "
        f"swapped operands, boundary comparisons) in the detector, voting, SEPT/DP, motion segmentation, "
        f"triangulation, the Kalman filter and the inverse kinematics, one at a time, and ran the affected unit tests. "
        f"**{s['killed']} of {s['mutants']} were caught ({100 * s['kill_ratio']:.0f} %).**",
        "",
        f"Commit {s['commit'][:10]}, {s['date']}, {s['runtime_s']} s on {s['cpu']} (2 cores, shared).",
        "",
        "## Survivors and why they are harmless",
        "",
    ]
    if not s["survivors"]:
        lines.append("None.")
    for o in s["survivors"]:
        lines.append(f"- `{o['id']}` ({o['file']}): {o['reason'] or '**UNEXPLAINED**'}")
    lines += ["", "## Every mutant", "", "| mutant | status | caught by |", "|---|---|---|"]
    for o in s["outcomes"]:
        lines.append(f"| `{o['id']}` | {o['status']} | {o.get('detail') or ''} |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", help="run only the mutants whose id contains this text (no results written)")
    parser.add_argument("--list", action="store_true", help="list the mutants and exit")
    parser.add_argument("--rerun-survivors", action="store_true",
                        help="run only the survivors of docs/results/mutation.json and mutants it lacks; merge")
    args = parser.parse_args()
    chosen = [x for x in MUTANTS if not args.only or args.only in x["id"]]
    previous, previous_seconds = {}, 0
    if args.rerun_survivors:
        with open(os.path.join(RESULTS, "mutation.json")) as f:
            earlier = json.load(f)
        previous = {o["id"]: o for o in earlier["outcomes"]}
        previous_seconds = earlier.get("runtime_s", 0)  # the results report the whole check's time
        # (survivors already explained as harmless are not rerun)
        chosen = [x for x in chosen if x["id"] not in previous or
                  (previous[x["id"]]["status"] != "killed" and not x["harmless"])]
    if args.list:
        for x in chosen:
            print(f"{x['id']:45s} {x['file']}")
        return 0
    # SIGTERM and SIGHUP unwind like Ctrl-C, through every restoring with-block (SIGINT too when
    # started in the background, where the shell would have it ignored).
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    restore_backups()
    # Objects of an earlier, interrupted run may hold a mutant: touching the sources rebuilds them.
    for path in sorted({x["file"] for x in MUTANTS}):
        os.utime(os.path.join(ROOT, path), None)
    if not os.path.exists(os.path.join(BUILD, "CMakeCache.txt")):
        r = run(["cmake", "-S", ROOT, "-B", BUILD, "-DCMAKE_BUILD_TYPE=Release"])
        if r.returncode != 0:
            print(r.stdout, file=sys.stderr)
            return 2
    targets = sorted({t for x in chosen for t in x["tests"]})
    ok, log = build(targets)
    failure = run_tests(targets) if ok else "build failed:\n" + log
    if failure:
        print(f"the unmutated tests do not pass, nothing to measure: {failure}", file=sys.stderr)
        return 2
    start = time.time()
    outcomes = []
    try:
        for i, x in enumerate(chosen, 1):
            outcome = {"id": x["id"], "file": x["file"], "mutation": f"{x['find']!r} -> {x['replace']!r}",
                       "harmless": x["harmless"]}
            try:
                with Mutated(x):
                    ok, log = build(x["tests"])
                    if not ok:
                        outcome.update(status="build_failed", detail=log.splitlines()[-1] if log else "")
                    else:
                        failed = run_tests(x["tests"])
                        outcome.update(status="killed" if failed else "survived", detail=failed)
            except LookupError as e:
                outcome.update(status="stale", detail=str(e))
            outcomes.append(outcome)
            print(f"[{i}/{len(chosen)}] {x['id']}: {outcome['status']} {outcome.get('detail') or ''}", flush=True)
    except KeyboardInterrupt:
        print("interrupted: sources restored", file=sys.stderr)
        return 130
    finally:
        build(targets)  # leave the mutation build matching the restored sources
    seconds = time.time() - start + previous_seconds
    if previous:  # the earlier outcomes, in list order, with the rerun ones replaced
        rerun = {o["id"]: o for o in outcomes}
        outcomes = [rerun.get(x["id"], dict(previous.get(x["id"]), harmless=x["harmless"]))
                    for x in MUTANTS if x["id"] in rerun or x["id"] in previous]
    scored, killed = score(outcomes)
    killed = len(killed)
    print(f"{killed}/{len(scored)} mutants killed in {seconds:.0f} s")
    unexplained = [o["id"] for o in scored if o["status"] == "survived" and not o["harmless"]]
    stale = [o["id"] for o in outcomes if o["status"] in ("stale", "build_failed")]
    if not args.only:
        write_results(outcomes, seconds)
    if unexplained:
        print("survivors without a reason (add a test or explain): " + ", ".join(unexplained), file=sys.stderr)
    if stale:
        print("mutants to update (text not found once, or not compiling): " + ", ".join(stale), file=sys.stderr)
    return 1 if unexplained or stale or (scored and killed < 0.9 * len(scored)) else 0


if __name__ == "__main__":
    sys.exit(main())
