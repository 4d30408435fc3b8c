#include "nudge/launcher/config.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace nudge::launcher {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::runtime_error(source + ": " + what);
}

double seconds(const json& object, const std::string& key, double fallback, const std::string& where,
               const std::string& source) {
  if (!object.contains(key)) return fallback;
  if (!object[key].is_number()) fail(source, where + key + " must be a number of seconds");
  const double value = object[key].get<double>();
  if (!(value >= 0) || !std::isfinite(value)) fail(source, where + key + " must be >= 0");
  return value;
}

std::string text(const json& object, const std::string& key, const std::string& fallback, const std::string& where,
                 const std::string& source) {
  if (!object.contains(key)) return fallback;
  if (!object[key].is_string()) fail(source, where + key + " must be a string");
  return object[key].get<std::string>();
}

RestartPolicy restart_policy(const std::string& name, const std::string& where, const std::string& source) {
  if (name == "always") return RestartPolicy::kAlways;
  if (name == "on-failure") return RestartPolicy::kOnFailure;
  if (name == "never") return RestartPolicy::kNever;
  fail(source, where + "restart is '" + name + "': always, on-failure or never");
}

ProcessSpec process_spec(const json& p, size_t index, const std::string& source) {
  const std::string where = "processes[" + std::to_string(index) + "].";
  if (!p.is_object()) fail(source, where.substr(0, where.size() - 1) + " must be an object");
  ProcessSpec spec;
  spec.name = text(p, "name", "", where, source);
  if (spec.name.empty()) fail(source, where + "name is missing");
  if (spec.name.find('/') != std::string::npos) fail(source, where + "name '" + spec.name + "' has a '/'");
  if (!p.contains("command") || !p["command"].is_array() || p["command"].empty())
    fail(source, where + "command must be a non-empty array of strings");
  for (const auto& arg : p["command"]) {
    if (!arg.is_string()) fail(source, where + "command must be a non-empty array of strings");
    spec.command.push_back(arg.get<std::string>());
  }
  spec.lcm_url_flag = text(p, "lcm_url_flag", spec.lcm_url_flag, where, source);
  spec.restart = restart_policy(text(p, "restart", "always", where, source), where, source);
  return spec;
}

}  // namespace

LaunchConfig parse_launch_config(const std::string& content, const std::string& source) {
  json root;
  try {
    root = json::parse(content);
  } catch (const json::parse_error& e) {
    fail(source, std::string("not JSON: ") + e.what());
  }
  if (!root.is_object()) fail(source, "must be a JSON object");
  LaunchConfig config;
  config.lcm_url = text(root, "lcm_url", config.lcm_url, "", source);
  config.log_dir = text(root, "log_dir", config.log_dir, "", source);
  config.stop_timeout_s = seconds(root, "stop_timeout_s", config.stop_timeout_s, "", source);
  if (root.contains("backoff")) {
    const json& b = root["backoff"];
    if (!b.is_object()) fail(source, "backoff must be an object");
    config.backoff.initial_s = seconds(b, "initial_s", config.backoff.initial_s, "backoff.", source);
    config.backoff.max_s = seconds(b, "max_s", config.backoff.max_s, "backoff.", source);
    config.backoff.stable_s = seconds(b, "stable_s", config.backoff.stable_s, "backoff.", source);
  }
  if (!root.contains("processes") || !root["processes"].is_array() || root["processes"].empty())
    fail(source, "processes must be a non-empty array");
  std::set<std::string> names;
  for (size_t i = 0; i < root["processes"].size(); ++i) {
    ProcessSpec spec = process_spec(root["processes"][i], i, source);
    if (!names.insert(spec.name).second) fail(source, "two processes are named '" + spec.name + "'");
    config.processes.push_back(std::move(spec));
  }
  return config;
}

LaunchConfig load_launch_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the launch file " + path);
  std::stringstream content;
  content << in.rdbuf();
  return parse_launch_config(content.str(), path);
}

std::vector<std::string> command_line(const ProcessSpec& spec, const std::string& lcm_url) {
  std::vector<std::string> argv = spec.command;
  if (spec.lcm_url_flag.empty()) return argv;
  if (spec.lcm_url_flag.back() == '=') {
    argv.push_back(spec.lcm_url_flag + lcm_url);
  } else {
    argv.push_back(spec.lcm_url_flag);
    argv.push_back(lcm_url);
  }
  return argv;
}

double restart_delay_s(int quick_failures, const Backoff& backoff) {
  const int doublings = std::clamp(quick_failures - 1, 0, 30);
  return std::min(backoff.max_s, backoff.initial_s * std::pow(2.0, doublings));
}

}  // namespace nudge::launcher
