#include "nudge/yaml_file.hpp"

#include <cctype>
#include <charconv>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace nudge {

namespace {

bool is_quoted(const YAML::Node& node) { return node.Tag() == "!"; }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool all_digits(const std::string& s, size_t from) {
  if (from >= s.size()) return false;
  for (size_t i = from; i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
  return true;
}

// YAML's special floats; OpenCV writes `.Inf`, `-.Inf` and `.Nan`.
std::optional<double> special_float(const std::string& text) {
  const std::string s = lower(text);
  if (s == ".inf" || s == "+.inf") return std::numeric_limits<double>::infinity();
  if (s == "-.inf") return -std::numeric_limits<double>::infinity();
  if (s == ".nan") return std::numeric_limits<double>::quiet_NaN();
  return std::nullopt;
}

// A decimal number, whole text, in the C locale whatever the process's locale is.
std::optional<double> decimal(const std::string& text) {
  // from_chars takes a leading '-' but not YAML's leading '+'.
  const size_t start = !text.empty() && text[0] == '+' ? 1 : 0;
  if (start >= text.size()) return std::nullopt;
  if (start == 1 && (text[1] == '+' || text[1] == '-')) return std::nullopt;
  // from_chars also takes "inf" and "nan" spelled out, which are text to OpenCV and YAML.
  for (size_t i = start; i < text.size(); ++i)
    if (std::isalpha(static_cast<unsigned char>(text[i])) && text[i] != 'e' && text[i] != 'E') return std::nullopt;
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data() + start, end, value, std::chars_format::general);
  if (ptr != end) return std::nullopt;
  if (ec == std::errc::result_out_of_range) return std::nullopt;
  if (ec != std::errc()) return std::nullopt;
  return value;
}

}  // namespace

YAML::Node parse_yaml(const std::string& text, const std::string& source, const std::string& kind) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(source + ": not a valid " + kind + " file: line " + std::to_string(e.mark.line + 1) +
                             ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ": not a valid " + kind + " file: " + e.msg);
  }
}

YAML::Node read_yaml_file(const std::string& path, const std::string& kind) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open " + kind + " file");
  std::string text;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<size_t>(in.gcount()));
    if (text.size() > kMaxYamlFileBytes)
      throw std::runtime_error(path + ": larger than a " + kind + " file can be (" +
                               std::to_string(kMaxYamlFileBytes >> 20) + " MB)");
  }
  if (in.bad()) throw std::runtime_error(path + ": cannot open " + kind + " file");
  return parse_yaml(text, path, kind);
}

std::optional<YAML::Node> yaml_field(const YAML::Node& map, const std::string& key) {
  if (!map.IsMap()) return std::nullopt;
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (!it->first.IsScalar() || it->first.Scalar() != key) continue;
    const YAML::Node value = it->second;
    if (!value.IsDefined() || value.IsNull()) return std::nullopt;
    return value;
  }
  return std::nullopt;
}

std::vector<std::string> yaml_keys(const YAML::Node& map) {
  std::vector<std::string> keys;
  if (!map.IsMap()) return keys;
  for (auto it = map.begin(); it != map.end(); ++it)
    keys.push_back(it->first.IsScalar() ? it->first.Scalar() : "(a key that is not text)");
  return keys;
}

std::optional<int> yaml_int(const YAML::Node& node) {
  if (!node.IsScalar() || is_quoted(node)) return std::nullopt;
  const std::string& s = node.Scalar();
  const size_t sign = !s.empty() && (s[0] == '+' || s[0] == '-') ? 1 : 0;
  if (!all_digits(s, sign)) return std::nullopt;
  int value = 0;
  const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(begin, s.data() + s.size(), value);
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return value;
}

std::optional<double> yaml_number(const YAML::Node& node) {
  if (!node.IsScalar() || is_quoted(node)) return std::nullopt;
  if (const auto special = special_float(node.Scalar())) return special;
  return decimal(node.Scalar());
}

std::optional<std::string> yaml_text(const YAML::Node& node) {
  if (!node.IsScalar()) return std::nullopt;
  if (!is_quoted(node) && yaml_number(node)) return std::nullopt;
  return node.Scalar();
}

}  // namespace nudge
