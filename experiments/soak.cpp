// nudge-exp-soak: the recorder of a soak run (issue 12, "Load"; experiments/soak.sh starts the
// pipeline and this beside it, docs/reliability.md "Soak").
//
//   nudge-exp-soak record --seconds 600 --pids camera=12,symmetry=13 --out run.json --csv rss.csv
//     listens to every stage's output for --seconds and writes, per stage, the latency of each
//     message (its receive time minus the capture time of the frame it comes from), the frames
//     each stage never answered, and per process RSS and CPU over time (from /proc) with the
//     datagrams its sockets dropped.
//   nudge-exp-soak plot --csv rss.csv --out soak_rss.png   RSS against time, one line a process
//
// Capture time: a camera that stamps frames with the wall clock gives it in utime. A simulated
// camera stamps simulated time; then the frame's capture is when this recorder first heard its
// utime (on SIM_STATE, the world's state the camera renders, else on CAMERA_*).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "nudge/axes_t.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/contours_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/atomic_file.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/timing.hpp"
#include "nudge/track_t.hpp"
#include "report.hpp"
#include "soak_probe.hpp"

using namespace nudge;
namespace soak = nudge::experiments::soak;

namespace {

constexpr int64_t kWallStampedWithinUs = 60LL * 1000000;  // a utime this close to now is wall-clock time
constexpr int64_t kInFlightUs = 3000000;                  // frames younger than this at the end are not judged

// The stage a channel belongs to: its producer.
std::string stage_of(const std::string& channel) {
  for (const char* prefix : {"CAMERA", "SYMMETRY", "CONTOURS", "TRACK"})
    if (channel.rfind(prefix, 0) == 0) {
      std::string s = prefix;
      std::transform(s.begin(), s.end(), s.begin(), ::tolower);
      return s == "track" ? "tracker" : s;
    }
  if (channel == "AXES") return "triangulation";
  return channel;
}

// The camera channel an output channel answers: SYMMETRY_LEFT, TRACK_LEFT_2 -> CAMERA_LEFT.
std::string source_camera(const std::string& channel) {
  if (channel.find("LEFT") != std::string::npos) return "CAMERA_LEFT";
  if (channel.find("RIGHT") != std::string::npos) return "CAMERA_RIGHT";
  return "";
}

struct ChannelRecord {
  std::vector<double> latency_ms;
  std::set<int64_t> frame_ids;  // or utimes, for AXES
  int64_t received = 0;
};

struct ProcessRecord {
  int pid = 0;
  std::vector<double> t_s, rss_mb, cpu_percent;
  double cpu_seconds_start = -1, cpu_seconds_end = 0;
  int64_t socket_drops = 0;
};

class Recorder {
 public:
  Recorder(int64_t start_utime, int64_t warmup_us) : start_(start_utime), warmup_end_(start_utime + warmup_us) {}

  // The capture time of the frame stamped `utime`, heard at `recv` (see the file comment).
  int64_t capture_time(int64_t utime, int64_t recv) {
    if (std::llabs(recv - utime) < kWallStampedWithinUs) return utime;
    const auto [it, inserted] = first_heard_.emplace(utime, recv);
    return it->second;
  }
  void note_source(int64_t utime, int64_t recv) { capture_time(utime, recv); }

  void note(const std::string& channel, int64_t utime, int64_t frame_id, int64_t recv) {
    ChannelRecord& r = channels_[channel];
    ++r.received;
    const int64_t latency_us = recv - capture_time(utime, recv);
    if (recv >= warmup_end_) r.latency_ms.push_back(latency_us * 1e-3);
    r.frame_ids.insert(frame_id);
    if (channel.rfind("CAMERA", 0) == 0) camera_frames_[channel].emplace_back(frame_id, recv, utime);
  }

  void note_heartbeat(const heartbeat_t& hb) { heartbeats_[hb.instance] = hb; }

  void sample_processes(std::map<std::string, ProcessRecord>& processes, int64_t now) const {
    for (auto& [name, p] : processes) {
      const auto s = soak::sample_process(p.pid);
      if (!s) continue;
      const double t = (now - start_) * 1e-6;
      double cpu = 0;
      if (!p.t_s.empty() && t > p.t_s.back()) cpu = 100.0 * (s->cpu_seconds - p.cpu_seconds_end) / (t - p.t_s.back());
      if (p.cpu_seconds_start < 0) p.cpu_seconds_start = s->cpu_seconds;
      p.cpu_seconds_end = s->cpu_seconds;
      p.t_s.push_back(t);
      p.rss_mb.push_back(s->rss_mb);
      p.cpu_percent.push_back(cpu);
      p.socket_drops = soak::socket_drops(p.pid);
    }
  }

  // Camera frames (heard before end - kInFlightUs) that `channel` never answered.
  int64_t unanswered(const std::string& channel, int64_t end) const {
    const std::string camera = channel == "AXES" ? "CAMERA_LEFT" : source_camera(channel);
    const auto cam = camera_frames_.find(camera);
    const auto out = channels_.find(channel);
    if (cam == camera_frames_.end() || out == channels_.end()) return -1;
    int64_t missing = 0;
    for (const auto& [frame_id, recv, utime] : cam->second) {
      if (recv > end - kInFlightUs) continue;
      const int64_t key = channel == "AXES" ? utime : frame_id;
      if (!out->second.frame_ids.count(key)) ++missing;
    }
    return missing;
  }

  // frame_ids skipped over by the channel (what the producer never sent, or this recorder lost).
  static int64_t gaps(const ChannelRecord& r) {
    if (r.frame_ids.size() < 2) return 0;
    return *r.frame_ids.rbegin() - *r.frame_ids.begin() + 1 - static_cast<int64_t>(r.frame_ids.size());
  }

  std::string json(const std::map<std::string, ProcessRecord>& processes, int64_t end, const std::string& label,
                   const std::vector<double>& load) const {
    JsonWriter j(6);
    j.begin_object();
    j.field("label", label);
    j.field("seconds", (end - start_) * 1e-6);
    j.field("warmup_s", (warmup_end_ - start_) * 1e-6);
    j.field("cpu", experiments::machine_description());
    j.key("load_average_1min").begin_array();
    for (double l : load) j.value(l);
    j.end_array();
    j.key("channels").begin_object();
    std::map<std::string, std::vector<double>> by_stage;
    for (const auto& [channel, r] : channels_) {
      j.key(channel).begin_object();
      j.field("stage", stage_of(channel));
      j.field("received", static_cast<long long>(r.received));
      if (channel != "AXES") j.field("frame_id_gaps", static_cast<long long>(gaps(r)));
      if (channel.rfind("CAMERA", 0) != 0) j.field("camera_frames_unanswered", static_cast<long long>(unanswered(channel, end)));
      latency_fields(j, r.latency_ms);
      j.end_object();
      auto& all = by_stage[stage_of(channel)];
      all.insert(all.end(), r.latency_ms.begin(), r.latency_ms.end());
    }
    j.end_object();
    j.key("stages").begin_object();
    for (const auto& [stage, samples] : by_stage) {
      j.key(stage).begin_object();
      latency_fields(j, samples);
      j.end_object();
    }
    j.end_object();
    j.key("processes").begin_object();
    for (const auto& [name, p] : processes) {
      j.key(name).begin_object();
      j.field("pid", p.pid);
      if (!p.rss_mb.empty()) {
        const size_t after_warmup = index_after(p.t_s, (warmup_end_ - start_) * 1e-6);
        j.field("rss_mb_first", p.rss_mb.front());
        j.field("rss_mb_after_warmup", p.rss_mb[after_warmup]);
        j.field("rss_mb_last", p.rss_mb.back());
        j.field("rss_mb_max", *std::max_element(p.rss_mb.begin(), p.rss_mb.end()));
        j.field("rss_growth_mb", p.rss_mb.back() - p.rss_mb[after_warmup]);
        const double span = p.t_s.back() - p.t_s.front();
        j.field("cpu_percent_mean", span > 0 ? 100.0 * (p.cpu_seconds_end - p.cpu_seconds_start) / span : 0.0);
      }
      j.field("socket_drops", static_cast<long long>(p.socket_drops));
      j.end_object();
    }
    j.end_object();
    j.key("heartbeats").begin_object();
    for (const auto& [instance, hb] : heartbeats_) {
      j.key(instance).begin_object();
      j.field("service", hb.service);
      j.field("messages_in", static_cast<long long>(hb.messages_in));
      j.field("messages_out", static_cast<long long>(hb.messages_out));
      j.field("errors", static_cast<long long>(hb.errors));
      j.field("status", hb.status);
      j.end_object();
    }
    j.end_object();
    j.end_object();
    return j.str();
  }

 private:
  static size_t index_after(const std::vector<double>& t, double t0) {
    for (size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t0) return i;
    return t.size() - 1;
  }
  static void latency_fields(JsonWriter& j, const std::vector<double>& ms) {
    j.field("latency_samples", static_cast<long long>(ms.size()));
    j.field("p50_ms", soak::quantile(ms, 0.5));
    j.field("p99_ms", soak::quantile(ms, 0.99));
    j.field("max_ms", ms.empty() ? std::nan("") : *std::max_element(ms.begin(), ms.end()));
  }

  int64_t start_, warmup_end_;
  std::map<int64_t, int64_t> first_heard_;
  std::map<std::string, ChannelRecord> channels_;
  std::map<std::string, std::vector<std::tuple<int64_t, int64_t, int64_t>>> camera_frames_;  // id, recv, utime
  std::map<std::string, heartbeat_t> heartbeats_;
};

std::map<std::string, ProcessRecord> parse_pids(const std::string& spec) {
  std::map<std::string, ProcessRecord> processes;
  for (const std::string& item : split_list(spec)) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw FlagError("--pids: '" + item + "' is not NAME=PID");
    try {
      processes[item.substr(0, eq)].pid = std::stoi(item.substr(eq + 1));
    } catch (const std::exception&) {
      throw FlagError("--pids: '" + item + "' has no number after '='");
    }
  }
  return processes;
}

std::string rss_csv(const std::map<std::string, ProcessRecord>& processes) {
  std::ostringstream csv;
  csv << "process,t_s,rss_mb,cpu_percent\n";
  for (const auto& [name, p] : processes)
    for (size_t i = 0; i < p.t_s.size(); ++i)
      csv << name << ',' << p.t_s[i] << ',' << p.rss_mb[i] << ',' << p.cpu_percent[i] << '\n';
  return csv.str();
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double l = 0;
  in >> l;
  return l;
}

int record(int argc, char** argv) {
  bus::Service service("soak", "Records latency, drops, memory and CPU of a running pipeline (issue 12).");
  double seconds = 600, warmup_s = 10, interval_s = 1;
  std::string pids, out, csv, label;
  auto& f = service.flags();
  f.add_double("seconds", &seconds, "record this long");
  f.add_double("warmup", &warmup_s, "latencies count, and RSS growth is measured, from this many seconds on");
  f.add_double("interval", &interval_s, "seconds between /proc samples");
  f.add_string("pids", &pids, "processes to sample: NAME=PID,NAME=PID,...");
  f.add_string("out", &out, "the run's JSON file; required");
  f.add_string("csv", &csv, "RSS and CPU samples (process,t_s,rss_mb,cpu_percent)");
  f.add_string("label", &label, "the run's name in its JSON");
  if (!service.parse(argc - 1, argv + 1)) return 0;
  if (out.empty()) throw FlagError("--out FILE is required");
  if (!(seconds > 0) || !(warmup_s >= 0) || warmup_s >= seconds) throw FlagError("need --seconds > --warmup >= 0");
  if (!(interval_s > 0)) throw FlagError("--interval must be > 0");
  std::map<std::string, ProcessRecord> processes = parse_pids(pids);

  service.start();
  service.subscriptions().set_stream_queue_capacity(0);  // the recorder must not drop what it measures
  const int64_t start = wall_utime();
  Recorder rec(start, static_cast<int64_t>(warmup_s * 1e6));
  auto& subs = service.subscriptions();
  subs.subscribe_timed<sim_state_t>("SIM_STATE", [&](const sim_state_t& m, const std::string&, int64_t recv) {
    rec.note_source(m.utime, recv);
  });
  subs.subscribe_timed<image_t>("CAMERA_(LEFT|RIGHT)", [&](const image_t& m, const std::string& ch, int64_t recv) {
    rec.note(ch, m.utime, m.frame_id, recv);
  });
  subs.subscribe_timed<symmetry_lines_t>("SYMMETRY_.*", [&](const symmetry_lines_t& m, const std::string& ch, int64_t recv) {
    rec.note(ch, m.utime, m.frame_id, recv);
  });
  subs.subscribe_timed<contours_t>("CONTOURS_.*", [&](const contours_t& m, const std::string& ch, int64_t recv) {
    rec.note(ch, m.utime, m.frame_id, recv);
  });
  subs.subscribe_timed<track_t>("TRACK_.*", [&](const track_t& m, const std::string& ch, int64_t recv) {
    rec.note(ch, m.utime, m.frame_id, recv);
  });
  subs.subscribe_timed<axes_t>("AXES", [&](const axes_t& m, const std::string& ch, int64_t recv) {
    rec.note(ch, m.utime, m.utime, recv);  // no frame_id: pairs are known by utime
  });
  subs.subscribe<heartbeat_t>("HEARTBEAT", [&](const heartbeat_t& m, const std::string&) { rec.note_heartbeat(m); });

  const int64_t end = start + static_cast<int64_t>(seconds * 1e6);
  int64_t next_sample = start;
  constexpr double kProgressStep_s = 10;  // a status line every 10 s of the recording
  nudge::Progress progress("nudge-exp-soak record", static_cast<int>(std::ceil(seconds / kProgressStep_s)));
  int64_t next_step = start;
  std::vector<double> load;
  while (!service.stop_requested()) {
    const int64_t now = wall_utime();
    if (now >= end) break;
    if (now >= next_step) {
      progress.step("recording, " + std::to_string((now - start) / 1000000) + " s of " +
                    std::to_string(static_cast<int>(seconds)));
      next_step += static_cast<int64_t>(kProgressStep_s * 1e6);
    }
    if (now >= next_sample) {
      rec.sample_processes(processes, now);
      load.push_back(load_average());
      next_sample += static_cast<int64_t>(interval_s * 1e6);
    }
    service.spin_once(20);
  }
  const int64_t stopped = wall_utime();
  rec.sample_processes(processes, stopped);
  write_file_atomically(out, rec.json(processes, stopped, label, load) + "\n");
  if (!csv.empty()) write_file_atomically(csv, rss_csv(processes));
  progress.clear_status();
  log::info() << "wrote " << out << (csv.empty() ? "" : " and " + csv);
  progress.finish(std::to_string((stopped - start) / 1000000) + " s recorded" +
                  (service.stop_requested() ? " (stopped early by a signal)" : "") + " into " + out);
  return 0;
}

int plot_rss(int argc, char** argv) {
  Flags f("nudge-exp-soak plot", "RSS against time from a soak's CSV.");
  std::string csv, out, title = "RSS during the soak";
  f.add_string("csv", &csv, "the recorder's --csv file; required");
  f.add_string("out", &out, "PNG to write; required");
  f.add_string("title", &title, "the plot's title");
  if (!f.parse(argc - 1, argv + 1)) return 0;
  if (csv.empty() || out.empty()) throw FlagError("--csv FILE and --out FILE.png are required");
  std::ifstream in(csv);
  if (!in) throw std::runtime_error("cannot read " + csv);
  std::map<std::string, experiments::Series> series;
  std::string line;
  std::getline(in, line);
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    std::istringstream fields(line);
    std::string name, t, rss;
    if (!std::getline(fields, name, ',') || !std::getline(fields, t, ',') || !std::getline(fields, rss, ','))
      throw std::runtime_error(csv + ":" + std::to_string(row) + ": expected process,t_s,rss_mb,...");
    auto& s = series[name];
    s.label = name;
    s.points = false;
    s.x.push_back(std::stod(t) / 60.0);
    s.y.push_back(std::stod(rss));
  }
  const cv::Scalar colours[] = {{200, 80, 0}, {0, 120, 220}, {40, 160, 40}, {180, 0, 180}, {0, 0, 200},
                                {120, 120, 0}, {80, 80, 80}, {0, 160, 160}};
  std::vector<experiments::Series> all;
  for (auto& [name, s] : series) {
    s.colour = colours[all.size() % 8];
    all.push_back(s);
  }
  const cv::Mat image = experiments::plot(all, title, "minutes", "RSS, MB", {900, 520});
  if (!cv::imwrite(out, image)) throw std::runtime_error("cannot write " + out);
  log::info() << "wrote " << out;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("soak", [&] {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "record") return record(argc, argv);
    if (mode == "plot") return plot_rss(argc, argv);
    std::cerr << "usage: nudge-exp-soak record --seconds S --pids NAME=PID,... --out RUN.json [--csv RSS.csv]\n"
                 "       nudge-exp-soak plot --csv RSS.csv --out RSS.png\n";
    return 2;
  });
}
