#include "run_logs.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

namespace fs = std::filesystem;

namespace nudge::experiments {

std::vector<std::pair<std::string, fs::path>> run_logs(const std::vector<std::string>& run_sets) {
  std::vector<std::pair<std::string, fs::path>> logs;
  for (size_t k = 0; k < run_sets.size(); ++k) {
    std::vector<std::pair<std::string, fs::path>> in_set;
    for (const auto& entry : fs::directory_iterator(run_sets[k])) {
      const std::string scene = entry.path().filename().string();
      const fs::path log = entry.path() / scene / (scene + ".lcmlog");
      if (fs::exists(log)) in_set.emplace_back(std::to_string(k + 1) + ":" + scene, log);
    }
    std::sort(in_set.begin(), in_set.end());
    logs.insert(logs.end(), in_set.begin(), in_set.end());
  }
  if (logs.empty()) throw std::runtime_error("no run logs (<scene>/<scene>/<scene>.lcmlog) under the RUNS_DIRs given");
  return logs;
}

fs::path own_directory() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (n <= 0) throw std::runtime_error("cannot find this program's directory");
  path[n] = '\0';
  return fs::path(path).parent_path();
}

std::string shell_quote(const std::string& s) {
  std::string quoted = "'";
  for (char c : s) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

namespace {

// The run's own nudge-symmetry command, from the launch.json beside its log (services/).
std::vector<std::string> symmetry_command(const fs::path& log) {
  const fs::path launch = log.parent_path() / "services" / "launch.json";
  std::ifstream in(launch);
  if (!in) throw std::runtime_error("cannot read " + launch.string() + " (the run's services)");
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  std::smatch process;
  if (!std::regex_search(s, process, std::regex(R"re("name":\s*"symmetry",\s*"command":\s*\[([^\]]*)\])re")))
    throw std::runtime_error(launch.string() + ": no symmetry process");
  std::vector<std::string> words;
  const std::string list = process[1].str();
  const std::regex word(R"re("([^"]*)")re");
  for (auto it = std::sregex_iterator(list.begin(), list.end(), word); it != std::sregex_iterator(); ++it)
    words.push_back((*it)[1].str());
  if (words.empty()) throw std::runtime_error(launch.string() + ": the symmetry process has no command");
  return words;
}

}  // namespace

void replay_symmetry(const fs::path& log, const std::string& extra, const fs::path& out) {
  const auto words = symmetry_command(log);
  // The binary this program was built with, not the path recorded (it may be another checkout's).
  std::string command = shell_quote((own_directory() / "nudge-symmetry").string());
  for (size_t i = 1; i < words.size(); ++i) command += " " + shell_quote(words[i]);
  command += " " + extra + " --lcm-in " + shell_quote("file://" + log.string() + "?speed=0") + " --lcm-out " +
             shell_quote("file://" + out.string() + "?mode=w") + " >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("nudge-symmetry failed on " + log.string());
}

std::vector<double> parse_list(const std::string& text, const std::string& flag) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !(v > 0)) throw std::invalid_argument(flag + ": not a positive number: '" + item + "'");
    values.push_back(v);
  }
  return values;
}

}  // namespace nudge::experiments
