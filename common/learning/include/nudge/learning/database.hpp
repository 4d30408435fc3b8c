#pragma once
// The object database on disk: one folder per object under a root folder,
//   <root>/<name>/object.json      metadata: format version, name, run, time, height, radius, views
//   <root>/<name>/features.bin     every view's keypoints and descriptors, with a checksum
//   <root>/<name>/view_NN.png      the training images
// An object is written into a temporary sibling folder (every file fsync'ed), which then replaces
// the old one in one rename: a crash or a full disk mid-write leaves the previous database intact.
// docs/learning.md describes the format.
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "nudge/learning/model.hpp"

namespace nudge::learning {

// 1: keypoints and descriptors; 2: also each keypoint's colour (older objects load without).
inline constexpr int kDatabaseFormatVersion = 2;

class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Writes one file's bytes durably (open, write, fsync, close); throws std::runtime_error naming the
// file. Injectable so tests can fail a write part-way.
using FileWriter = std::function<void(const std::string& path, const std::string& bytes)>;
void write_file_durably(const std::string& path, const std::string& bytes);

struct LoadReport {
  std::vector<std::shared_ptr<const ObjectModel>> models;
  std::vector<std::string> errors;  // one per object that could not be read, naming its file
};

class ObjectDatabase {
 public:
  // Creates the root folder if missing. Throws DatabaseError naming it when that fails.
  explicit ObjectDatabase(std::string root, FileWriter writer = write_file_durably);

  const std::string& root() const { return root_; }

  // Stores (or replaces) the model under its name, training images included. Throws DatabaseError
  // naming the object and the file when anything fails; the database then holds what it held before.
  void store(const ObjectModel& model) const;

  // The names of the stored objects, sorted (temporary folders of an unfinished write are not objects).
  std::vector<std::string> names() const;
  // Reads one object; with_images also loads its training images. Throws DatabaseError naming the
  // file for a missing, corrupt or newer-format object.
  ObjectModel load(const std::string& name, bool with_images = false) const;
  // Reads every object; one that fails is reported in errors and skipped, the rest still load.
  LoadReport load_all(bool with_images = false) const;
  // One training image of a stored object (for match pictures). Throws DatabaseError.
  cv::Mat load_view_image(const std::string& name, int view) const;

 private:
  std::string root_;
  FileWriter writer_;
};

// Whether `name` can name a folder: 1-100 characters of [A-Za-z0-9_.-], not starting with '.'.
bool valid_object_name(const std::string& name);

}  // namespace nudge::learning
