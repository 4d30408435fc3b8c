#include "nudge/flags.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace nudge {

double parse_double(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value)) {
    throw FlagError(what + ": expected a finite number, got '" + text + "'");
  }
  return value;
}

int parse_int(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || value < -2147483647L ||
      value > 2147483647L) {
    throw FlagError(what + ": expected an integer, got '" + text + "'");
  }
  return static_cast<int>(value);
}

std::vector<std::string> split_list(const std::string& list, char separator) {
  std::vector<std::string> items;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, separator);)
    if (!item.empty()) items.push_back(item);
  return items;
}

Flags::Flags(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

void Flags::add(const std::string& name, int arity, const std::string& help, std::string default_text,
                std::function<void(const std::vector<std::string>&)> assign) {
  specs_[name] = Spec{arity, help, std::move(default_text), std::move(assign)};
  order_.push_back(name);
}

void Flags::add_string(const std::string& name, std::string* value, const std::string& help) {
  add(name, 1, help, *value, [value](const std::vector<std::string>& v) { *value = v[0]; });
}

void Flags::add_int(const std::string& name, int* value, const std::string& help) {
  add(name, 1, help, std::to_string(*value),
      [value, name](const std::vector<std::string>& v) { *value = parse_int(v[0], "--" + name); });
}

void Flags::add_double(const std::string& name, double* value, const std::string& help) {
  std::ostringstream def;
  def << *value;
  add(name, 1, help, def.str(),
      [value, name](const std::vector<std::string>& v) { *value = parse_double(v[0], "--" + name); });
}

void Flags::add_bool(const std::string& name, bool* value, const std::string& help) {
  add(name, 0, help, *value ? "on" : "off", [value](const std::vector<std::string>&) { *value = true; });
}

void Flags::add_doubles(const std::string& name, std::vector<double>* values, int arity,
                        const std::string& help) {
  std::ostringstream def;
  for (size_t i = 0; i < values->size(); ++i) def << (i ? " " : "") << (*values)[i];
  add(name, arity, help, def.str(), [values, name](const std::vector<std::string>& v) {
    values->clear();
    for (const auto& s : v) values->push_back(parse_double(s, "--" + name));
  });
}

void Flags::set_positional(const std::string& name, const std::string& help) {
  positional_name_ = name;
  positional_help_ = help;
}

// Parsing is CLI11's (Debian's libcli11-dev): it matches --name value, --name=value, switches,
// N-valued flags and positionals anywhere. What users see stays ours: the help text (help(), from
// our table, printed for --help/-h wherever it stands), the error messages naming the flag, the
// last value winning when a flag is repeated, and values converted by our strict parsers.
bool Flags::parse(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
    // A switch given a value: CLI11 would read "--on=1" as "on"; ours takes none.
    const auto eq = arg.find('=');
    if (arg.compare(0, 2, "--") == 0 && eq != std::string::npos) {
      const auto it = specs_.find(arg.substr(2, eq - 2));
      if (it != specs_.end() && it->second.arity == 0) throw FlagError(arg.substr(0, eq) + " takes no value");
    }
  }
  CLI::App app(summary_, program_);
  app.set_help_flag();   // ours: help() above
  app.allow_extras();    // unknown flags are named below, in our words
  std::map<std::string, std::vector<std::string>> values;
  std::map<std::string, CLI::Option*> options;
  for (const auto& name : order_) {
    const Spec& spec = specs_.at(name);
    if (spec.arity == 0) {
      options[name] = app.add_flag("--" + name);
    } else {
      options[name] = app.add_option("--" + name, values[name])
                          ->expected(spec.arity)
                          ->allow_extra_args(false)
                          ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    }
  }
  std::vector<std::string> positional;
  app.add_option("positional", positional);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ArgumentMismatch& e) {
    const std::string what = e.what();  // "--name: 2 required TEXT missing"
    const std::string flag = what.substr(0, what.find(':'));
    const auto it = specs_.find(flag.size() > 2 ? flag.substr(2) : flag);
    if (it == specs_.end()) throw FlagError(what);
    throw FlagError(flag + " needs " + std::to_string(it->second.arity) + " value(s)");
  } catch (const CLI::ParseError& e) {
    throw FlagError(e.what());
  }
  for (const std::string& extra : app.remaining()) {
    if (extra.compare(0, 2, "--") == 0 && extra.size() > 2)
      throw FlagError("unknown flag " + extra.substr(0, extra.find('=')) + " (see --help)");
    positional.push_back(extra);  // "-x": a positional argument, as it always was
  }
  for (const auto& name : order_) {
    if (options[name]->count() == 0) continue;
    const Spec& spec = specs_.at(name);
    if (spec.arity > 0 && static_cast<int>(values[name].size()) != spec.arity)
      throw FlagError("--" + name + " needs " + std::to_string(spec.arity) + " value(s)");
    spec.assign(values[name]);
    given_[name] = true;
  }
  positional_.insert(positional_.end(), positional.begin(), positional.end());
  return true;
}

std::string Flags::help() const {
  std::ostringstream out;
  out << "usage: " << program_ << " [options]";
  if (!positional_name_.empty()) out << " " << positional_name_;
  out << "\n" << summary_ << "\n";
  if (!positional_name_.empty()) out << "\n  " << positional_name_ << "  " << positional_help_ << "\n";
  out << "\noptions:\n";
  for (const auto& name : order_) {
    const Spec& spec = specs_.at(name);
    std::string head = "  --" + name;
    if (spec.arity == 1) head += " V";
    for (int k = 0; k < spec.arity && spec.arity > 1; ++k) head += " V" + std::to_string(k + 1);
    out << head;
    if (head.size() < 26) out << std::string(26 - head.size(), ' ');
    else out << "\n" << std::string(26, ' ');
    out << spec.help;
    if (!spec.default_text.empty()) out << " [" << spec.default_text << "]";
    out << "\n";
  }
  out << "  --help                  this text\n";
  return out.str();
}

}  // namespace nudge
