#include "nudge/learning/database.hpp"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc >= 2.28)
#include <unistd.h>

#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "binary_io.hpp"

namespace fs = std::filesystem;

namespace nudge::learning {

namespace {

constexpr const char* kMetadataFile = "object.json";
constexpr const char* kFeaturesFile = "features.bin";

std::string view_file(int view) {
  char name[32];
  std::snprintf(name, sizeof name, "view_%02d.png", view);
  return name;
}

// A view's object mask (ModelView::mask), stored only for a view learned with one.
std::string mask_file(int view) {
  char name[32];
  std::snprintf(name, sizeof name, "view_%02d_mask.png", view);
  return name;
}

std::string png_bytes(const cv::Mat& image, const std::string& what) {
  std::vector<uchar> png;
  if (!cv::imencode(".png", image, png)) throw std::runtime_error("cannot encode " + what + " as PNG");
  return std::string(png.begin(), png.end());
}

void fsync_directory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) throw std::runtime_error("cannot open folder " + dir + ": " + std::strerror(errno));
  const int rc = ::fsync(fd);
  const int saved = errno;
  ::close(fd);
  if (rc != 0) throw std::runtime_error("cannot flush folder " + dir + ": " + std::strerror(saved));
}

std::string metadata_json(const ObjectModel& model) {
  cv::FileStorage out(".json", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_JSON);
  out << "format_version" << kDatabaseFormatVersion;
  out << "name" << model.info.name;
  out << "run_id" << model.info.run_id;
  out << "object_key" << model.info.object_key;
  out << "learned_utime" << std::to_string(model.info.learned_utime);  // int64: FileStorage has no 64-bit ints
  out << "height" << model.info.height;
  out << "radius" << model.info.radius;
  out << "features" << kFeaturesFile;
  if (model.info.sift_recorded) {
    const SiftParams& sift = model.info.sift;
    out << "sift" << "{" << "contrast_threshold" << sift.contrast_threshold << "edge_threshold" << sift.edge_threshold
        << "octave_layers" << sift.octave_layers << "equalise_clip" << sift.equalise_clip << "equalise_tile_px"
        << sift.equalise_tile_px << "}";
  }
  out << "views" << "[";
  for (size_t v = 0; v < model.views.size(); ++v) {
    const ModelView& view = model.views[v];
    out << "{" << "image" << view_file(static_cast<int>(v)) << "wrist_angle" << view.wrist_angle;
    out << "box" << "[:" << view.box.x << view.box.y << view.box.width << view.box.height << "]";
    if (!view.mask.empty()) out << "mask" << mask_file(static_cast<int>(v));
    out << "descriptors" << view.features.size() << "}";
  }
  out << "]";
  return out.releaseAndGetString();
}

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw std::runtime_error("cannot read " + path);
  return bytes.str();
}

// Parses object.json into the model's info and views (features come from features.bin);
// `has_mask[v]`: whether view v lists a mask file.
ObjectModel parse_metadata(const std::string& path, std::vector<bool>& has_mask) {
  const std::string text = read_whole_file(path);
  ObjectModel model;
  try {
    cv::FileStorage in(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_JSON);
    if (!in.isOpened() || in["format_version"].empty()) throw std::runtime_error("no format_version");
    const int version = static_cast<int>(in["format_version"]);
    if (version > kDatabaseFormatVersion)
      throw std::runtime_error("format version " + std::to_string(version) + " is newer than this program reads (" +
                               std::to_string(kDatabaseFormatVersion) + ")");
    if (version < 1) throw std::runtime_error("bad format_version " + std::to_string(version));
    model.info.name = static_cast<std::string>(in["name"]);
    model.info.run_id = static_cast<std::string>(in["run_id"]);
    model.info.object_key = static_cast<std::string>(in["object_key"]);
    model.info.learned_utime = std::stoll(static_cast<std::string>(in["learned_utime"]));
    model.info.height = static_cast<double>(in["height"]);
    model.info.radius = static_cast<double>(in["radius"]);
    // The SIFT settings, recorded since 2026-12-02 (an older object has none: left unknown).
    const cv::FileNode sift = in["sift"];
    if (sift.isMap()) {
      model.info.sift.contrast_threshold = static_cast<double>(sift["contrast_threshold"]);
      model.info.sift.edge_threshold = static_cast<double>(sift["edge_threshold"]);
      model.info.sift.octave_layers = static_cast<int>(sift["octave_layers"]);
      model.info.sift.equalise_clip = static_cast<double>(sift["equalise_clip"]);
      model.info.sift.equalise_tile_px = static_cast<int>(sift["equalise_tile_px"]);
      model.info.sift_recorded = true;
    }
    const cv::FileNode views = in["views"];
    if (!views.isSeq()) throw std::runtime_error("no views list");
    for (const cv::FileNode& node : views) {
      ModelView view;
      view.wrist_angle = static_cast<double>(node["wrist_angle"]);
      std::vector<int> box;
      node["box"] >> box;
      if (box.size() != 4) throw std::runtime_error("a view's box is not 4 numbers");
      view.box = cv::Rect(box[0], box[1], box[2], box[3]);
      has_mask.push_back(!node["mask"].empty());
      model.views.push_back(std::move(view));
    }
  } catch (const cv::Exception& e) {
    throw std::runtime_error("not valid JSON: " + e.msg);
  } catch (const std::logic_error& e) {  // std::stoll
    throw std::runtime_error(std::string("bad learned_utime: ") + e.what());
  }
  return model;
}

std::string temporary_folder(const std::string& root, const std::string& name) {
  static std::atomic<int> counter{0};
  return root + "/." + name + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
}

// Puts the finished folder `temp` in place of `final_dir` in one step: rename() when there is no
// old one, otherwise an atomic exchange (renameat2) after which `temp` holds the old object.
// Returns whether `temp` now holds an old object to delete.
bool install(const std::string& temp, const std::string& final_dir) {
  if (!fs::exists(final_dir)) {
    if (std::rename(temp.c_str(), final_dir.c_str()) != 0)
      throw std::runtime_error("cannot rename " + temp + " to " + final_dir + ": " + std::strerror(errno));
    return false;
  }
  if (::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, final_dir.c_str(), RENAME_EXCHANGE) != 0)
    throw std::runtime_error("cannot exchange " + temp + " with " + final_dir + ": " + std::strerror(errno));
  return true;
}

}  // namespace

void write_file_durably(const std::string& path, const std::string& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + path + ": " + std::strerror(errno));
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      throw std::runtime_error("cannot write " + path + ": " + why);
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    throw std::runtime_error("cannot flush " + path + ": " + why);
  }
  if (::close(fd) != 0) throw std::runtime_error("cannot close " + path + ": " + std::strerror(errno));
}

bool valid_object_name(const std::string& name) {
  if (name.empty() || name.size() > 100 || name[0] == '.') return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'; });
}

ObjectDatabase::ObjectDatabase(std::string root, FileWriter writer) : root_(std::move(root)), writer_(std::move(writer)) {
  std::error_code ec;
  fs::create_directories(root_, ec);
  if (ec || !fs::is_directory(root_))
    throw DatabaseError("object database " + root_ + ": cannot create the folder" + (ec ? ": " + ec.message() : ""));
}

void ObjectDatabase::store(const ObjectModel& model) const {
  const std::string& name = model.info.name;
  if (!valid_object_name(name))
    throw DatabaseError("object name '" + name + "' is not usable as a folder name ([A-Za-z0-9_.-], not starting with '.')");
  const std::string temp = temporary_folder(root_, name);
  const std::string final_dir = root_ + "/" + name;
  try {
    if (!fs::create_directory(temp)) throw std::runtime_error("cannot create " + temp);
    for (size_t v = 0; v < model.views.size(); ++v) {
      const cv::Mat& image = model.views[v].image;
      if (image.empty()) throw std::runtime_error("view " + std::to_string(v) + " has no image to store");
      writer_(temp + "/" + view_file(static_cast<int>(v)), png_bytes(image, "view " + std::to_string(v)));
      const cv::Mat& mask = model.views[v].mask;
      if (!mask.empty()) writer_(temp + "/" + mask_file(static_cast<int>(v)), png_bytes(mask, "view " + std::to_string(v) + "'s mask"));
    }
    std::vector<const Features*> features;
    for (const auto& view : model.views) features.push_back(&view.features);
    writer_(temp + "/" + kFeaturesFile, detail::encode_features(features, kDatabaseFormatVersion));
    writer_(temp + "/" + kMetadataFile, metadata_json(model));  // last: a folder with it is complete
    fsync_directory(temp);
    const bool replaced_old = install(temp, final_dir);
    fsync_directory(root_);
    if (replaced_old) fs::remove_all(temp);
  } catch (const std::exception& e) {
    std::error_code ignored;
    fs::remove_all(temp, ignored);
    throw DatabaseError("object database " + root_ + ": cannot store object " + name + ": " + e.what() +
                        " (the database still holds what it held before)");
  }
}

std::vector<std::string> ObjectDatabase::names() const {
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(root_)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && valid_object_name(name)) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

ObjectModel ObjectDatabase::load(const std::string& name, bool with_images) const {
  const std::string dir = root_ + "/" + name;
  std::string file = dir + "/" + kMetadataFile;
  try {
    std::vector<bool> has_mask;
    ObjectModel model = parse_metadata(file, has_mask);
    if (model.info.name != name) throw std::runtime_error("names object '" + model.info.name + "', not its folder's name");
    file = dir + "/" + kFeaturesFile;
    std::vector<Features> features = detail::decode_features(read_whole_file(file), kDatabaseFormatVersion);
    if (features.size() != model.views.size())
      throw std::runtime_error("holds " + std::to_string(features.size()) + " views, object.json lists " +
                               std::to_string(model.views.size()));
    for (size_t v = 0; v < features.size(); ++v) model.views[v].features = std::move(features[v]);
    if (with_images) {
      for (size_t v = 0; v < model.views.size(); ++v) {
        file = dir + "/" + view_file(static_cast<int>(v));
        model.views[v].image = cv::imread(file, cv::IMREAD_UNCHANGED);
        if (model.views[v].image.empty()) throw std::runtime_error("missing or undecodable image");
        if (!has_mask[v]) continue;
        file = dir + "/" + mask_file(static_cast<int>(v));
        model.views[v].mask = cv::imread(file, cv::IMREAD_GRAYSCALE);
        if (model.views[v].mask.empty()) throw std::runtime_error("missing or undecodable mask");
        if (model.views[v].mask.size() != model.views[v].image.size()) throw std::runtime_error("the mask is not its view's size");
      }
    }
    return model;
  } catch (const std::exception& e) {
    throw DatabaseError("object database: " + file + ": " + e.what());
  }
}

LoadReport ObjectDatabase::load_all(bool with_images) const {
  LoadReport report;
  for (const std::string& name : names()) {
    try {
      report.models.push_back(std::make_shared<ObjectModel>(load(name, with_images)));
    } catch (const DatabaseError& e) {
      report.errors.push_back(e.what());
    }
  }
  return report;
}

cv::Mat ObjectDatabase::load_view_image(const std::string& name, int view) const {
  const std::string file = root_ + "/" + name + "/" + view_file(view);
  cv::Mat image = cv::imread(file, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw DatabaseError("object database: " + file + ": missing or undecodable image");
  return image;
}

}  // namespace nudge::learning
