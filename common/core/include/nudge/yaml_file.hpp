#pragma once
// Configuration files (calibration, workspace, scenes) read with yaml-cpp, which is fuzzed
// upstream; OpenCV's cv::FileStorage loops for ever on some malformed YAML (docs/reliability.md).
// The files stay what OpenCV writes and reads: the `%YAML:1.0` header is an unknown directive
// to yaml-cpp (ignored) and `!!opencv-matrix` a tag. Scalars are typed as OpenCV types them.
#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

namespace nudge {

// Larger configuration files are refused before they are parsed (ours are a few KB).
constexpr size_t kMaxYamlFileBytes = 4 << 20;

// Parses the file at `path`, a `kind` file ("stereo rig", "workspace", "scene"). Throws
// std::runtime_error naming the file: "PATH: cannot open KIND file", "PATH: not a valid KIND
// file: line L, column C: WHAT" (1-based), or that it is larger than kMaxYamlFileBytes.
YAML::Node read_yaml_file(const std::string& path, const std::string& kind);

// The same for text already in memory; `source` names it in errors.
YAML::Node parse_yaml(const std::string& text, const std::string& source, const std::string& kind);

// The value of `key` in `map`, or nothing if `map` is not a map, has no such key, or its value is
// null (`key:` or `key: ~`), as OpenCV's FileNode::empty() / isNone(). The first of duplicates.
std::optional<YAML::Node> yaml_field(const YAML::Node& map, const std::string& key);

// A map's keys in file order; a key that is not a scalar reads "(a key that is not text)".
std::vector<std::string> yaml_keys(const YAML::Node& map);

// An unquoted scalar written as an integer ([+-]digits) that fits an int.
std::optional<int> yaml_int(const YAML::Node& node);

// An unquoted scalar written as a number: an integer, a decimal (`1.`, `.5`, `5.79e+02`), or
// YAML's `.inf`, `-.inf`, `.nan` in any case (OpenCV writes `.Inf`, `.Nan`).
std::optional<double> yaml_number(const YAML::Node& node);

// A scalar that is not a number (a quoted one always is text).
std::optional<std::string> yaml_text(const YAML::Node& node);

}  // namespace nudge
