#pragma once
// A small command-line parser shared by services and tools. Flags are declared with their
// default and help text; parse() reports unknown flags and bad values naming the flag.
//   --name value   --name=value   --switch   positional arguments are kept in order.
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace nudge {

class FlagError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Flags {
 public:
  explicit Flags(std::string program, std::string summary);

  void add_string(const std::string& name, std::string* value, const std::string& help);
  void add_int(const std::string& name, int* value, const std::string& help);
  void add_double(const std::string& name, double* value, const std::string& help);
  void add_bool(const std::string& name, bool* value, const std::string& help);  // a switch
  // A flag that takes `arity` values (e.g. --canny LOW HIGH).
  void add_doubles(const std::string& name, std::vector<double>* values, int arity,
                   const std::string& help);
  void set_positional(const std::string& name, const std::string& help);

  // Throws FlagError naming the offending flag. Returns false if --help was given
  // (the help text has then been printed to stdout).
  bool parse(int argc, char** argv);
  const std::vector<std::string>& positional() const { return positional_; }
  bool given(const std::string& name) const { return given_.count(name) > 0; }
  std::string help() const;

 private:
  struct Spec {
    int arity;  // 0 for switches
    std::string help;
    std::string default_text;
    std::function<void(const std::vector<std::string>&)> assign;
  };
  void add(const std::string& name, int arity, const std::string& help, std::string default_text,
           std::function<void(const std::vector<std::string>&)> assign);

  std::string program_, summary_, positional_name_, positional_help_;
  std::map<std::string, Spec> specs_;
  std::vector<std::string> order_;
  std::vector<std::string> positional_;
  std::map<std::string, bool> given_;
};

// "a,b,,c" -> {"a", "b", "c"}: the items of a comma-separated flag value, empty ones dropped.
std::vector<std::string> split_list(const std::string& list, char separator = ',');

// Strict numeric parsing: the whole string must be a finite number.
double parse_double(const std::string& text, const std::string& what);
int parse_int(const std::string& text, const std::string& what);

}  // namespace nudge
