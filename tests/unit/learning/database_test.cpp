// nudge_learning's object database: round trip, atomic replacement, failures mid-write (an injected
// failing writer; a full tmpfs in a private mount namespace when run as root), and a reader that
// refuses corrupt or newer-format objects naming the file while the rest still load.
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "nudge/learning/database.hpp"
#include "nudge/learning/synthetic.hpp"

using namespace nudge::learning;
namespace fs = std::filesystem;

namespace {

// A model of `views` small textured views (features detected, no pruning: the database does not care).
ObjectModel small_model(const std::string& name, int views, uint64_t seed, cv::Size size = {160, 120}) {
  ObjectModel model;
  model.info.name = name;
  model.info.run_id = "run_" + std::to_string(seed);
  model.info.object_key = "attempt_01";
  model.info.learned_utime = 1700000000123456 + static_cast<int64_t>(seed);
  model.info.height = 0.21;
  model.info.radius = 0.035;
  for (int v = 0; v < views; ++v) {
    ModelView view;
    view.image = synthetic::random_texture(size, seed * 100 + v);
    view.features = detect_features(view.image);
    view.box = cv::Rect(10 + v, 20, 60, 80);
    view.wrist_angle = v * CV_PI / 6;
    model.views.push_back(std::move(view));
  }
  return model;
}

std::string fresh_folder(const std::string& name) {
  const std::string dir = fs::temp_directory_path().string() + "/nudge_db_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(dir);
  return dir;
}

std::vector<std::string> entries(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

void expect_same(const ObjectModel& a, const ObjectModel& b) {
  EXPECT_EQ(a.info.name, b.info.name);
  EXPECT_EQ(a.info.run_id, b.info.run_id);
  EXPECT_EQ(a.info.object_key, b.info.object_key);
  EXPECT_EQ(a.info.learned_utime, b.info.learned_utime);
  EXPECT_DOUBLE_EQ(a.info.height, b.info.height);
  EXPECT_DOUBLE_EQ(a.info.radius, b.info.radius);
  EXPECT_EQ(a.info.sift_recorded, b.info.sift_recorded);
  EXPECT_EQ(sift_settings_difference(a.info.sift, b.info.sift), "");
  ASSERT_EQ(a.views.size(), b.views.size());
  for (size_t v = 0; v < a.views.size(); ++v) {
    EXPECT_EQ(a.views[v].box, b.views[v].box);
    EXPECT_DOUBLE_EQ(a.views[v].wrist_angle, b.views[v].wrist_angle);
    ASSERT_EQ(a.views[v].features.size(), b.views[v].features.size());
    EXPECT_EQ(cv::norm(a.views[v].features.descriptors, b.views[v].features.descriptors, cv::NORM_INF), 0);
    for (int k = 0; k < a.views[v].features.size(); ++k)
      EXPECT_EQ(a.views[v].features.keypoints[k].pt, b.views[v].features.keypoints[k].pt);
    ASSERT_EQ(a.views[v].features.colours.size(), b.views[v].features.colours.size());
    if (!a.views[v].features.colours.empty())
      EXPECT_EQ(cv::norm(a.views[v].features.colours, b.views[v].features.colours, cv::NORM_INF), 0);
  }
}

// features.bin as format version 1 wrote it (before colours): magic, version, view count; per view
// the keypoint count, 128, each keypoint's x, y, size, angle, response (float) and octave,
// class_id (int32), the descriptors (float); then the FNV-1a hash of everything before it.
std::string version_one_features(const std::vector<Features>& views) {
  std::string out = "NUDGEFT1";
  auto put = [&out](auto value) { out.append(reinterpret_cast<const char*>(&value), sizeof value); };
  put(uint32_t{1});
  put(static_cast<uint32_t>(views.size()));
  for (const Features& f : views) {
    put(static_cast<uint32_t>(f.size()));
    put(uint32_t{128});
    for (const cv::KeyPoint& k : f.keypoints) {
      for (float x : {k.pt.x, k.pt.y, k.size, k.angle, k.response}) put(x);
      put(static_cast<int32_t>(k.octave));
      put(static_cast<int32_t>(k.class_id));
    }
    out.append(reinterpret_cast<const char*>(f.descriptors.data), f.descriptors.total() * sizeof(float));
  }
  uint64_t hash = 1469598103934665603ull;
  for (char c : out) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  put(hash);
  return out;
}

void overwrite(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(ObjectDatabase, StoresAndLoadsAnObjectWithItsImages) {
  const std::string dir = fresh_folder("roundtrip");
  const ObjectDatabase db(dir);
  const ObjectModel cup = small_model("cup", 3, 1);
  db.store(cup);
  EXPECT_EQ(db.names(), std::vector<std::string>{"cup"});
  EXPECT_EQ(entries(dir + "/cup"),
            (std::vector<std::string>{"features.bin", "object.json", "view_00.png", "view_01.png", "view_02.png"}));
  const ObjectModel loaded = db.load("cup", true);
  expect_same(cup, loaded);
  EXPECT_EQ(cv::norm(loaded.views[1].image, cup.views[1].image, cv::NORM_INF), 0);
  EXPECT_TRUE(db.load("cup").views[0].image.empty());  // pictures only on request
  EXPECT_EQ(db.load_view_image("cup", 2).size(), cup.views[2].image.size());
  EXPECT_NE(read(dir + "/cup/object.json").find("\"format_version\": " + std::to_string(kDatabaseFormatVersion)),
            std::string::npos);
  fs::remove_all(dir);
}

// Format 2 added each keypoint's colour; an object stored by format 1 loads, its colours unknown.
TEST(ObjectDatabase, KeepsEachKeypointsColourAndReadsObjectsStoredWithout) {
  const std::string dir = fresh_folder("colours");
  const ObjectDatabase db(dir);
  const ObjectModel cup = small_model("cup", 2, 7);
  ASSERT_EQ(cup.views[0].features.colours.rows, cup.views[0].features.size()) << "a colour image's keypoints have colours";
  db.store(cup);
  expect_same(cup, db.load("cup"));  // colours included
  std::vector<Features> views;
  for (const ModelView& v : cup.views) views.push_back(v.features);
  overwrite(dir + "/cup/features.bin", version_one_features(views));
  std::string json = read(dir + "/cup/object.json");
  const std::string now = "\"format_version\": " + std::to_string(kDatabaseFormatVersion);
  json.replace(json.find(now), now.size(), "\"format_version\": 1");
  overwrite(dir + "/cup/object.json", json);
  const ObjectModel old = db.load("cup");
  ASSERT_EQ(old.views.size(), 2u);
  for (size_t v = 0; v < old.views.size(); ++v) {
    EXPECT_EQ(old.views[v].features.size(), cup.views[v].features.size());
    EXPECT_EQ(cv::norm(old.views[v].features.descriptors, cup.views[v].features.descriptors, cv::NORM_INF), 0);
    EXPECT_TRUE(old.views[v].features.colours.empty()) << "format 1 kept no colours";
  }
  fs::remove_all(dir);
}

TEST(ObjectDatabase, KeepsTheSiftSettingsAnObjectWasLearnedWithAndReadsObjectsStoredWithout) {
  const std::string dir = fresh_folder("sift_settings");
  const ObjectDatabase db(dir);
  ObjectModel dark = small_model("dark_jar", 2, 5);
  dark.info.sift.contrast_threshold = 0.03;
  dark.info.sift.equalise_clip = 2.5;
  dark.info.sift.equalise_tile_px = 48;
  dark.info.sift_recorded = true;
  db.store(dark);
  const ObjectModel loaded = db.load("dark_jar");
  expect_same(dark, loaded);
  EXPECT_EQ(sift_settings_difference(loaded.info.sift, SiftParams{}), "contrast 0.03 against 0.02, equalisation clip 2.5 against 0");
  // Stored before the settings were recorded: read, settings unknown.
  db.store(small_model("old_cup", 2, 6));
  EXPECT_EQ(read(dir + "/old_cup/object.json").find("sift"), std::string::npos);
  EXPECT_FALSE(db.load("old_cup").info.sift_recorded);
  fs::remove_all(dir);
}

TEST(ObjectDatabase, KeepsAViewsMaskBesideItsImage) {
  const std::string dir = fresh_folder("masks");
  const ObjectDatabase db(dir);
  ObjectModel bottle = small_model("bottle", 3, 7);
  cv::Mat mask(bottle.views[2].image.size(), CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(40, 10, 30, 90)).setTo(255);
  bottle.views[2].mask = mask;  // the standing view's
  db.store(bottle);
  EXPECT_EQ(entries(dir + "/bottle"), (std::vector<std::string>{"features.bin", "object.json", "view_00.png", "view_01.png",
                                                                "view_02.png", "view_02_mask.png"}));
  const ObjectModel loaded = db.load("bottle", true);
  expect_same(bottle, loaded);
  EXPECT_TRUE(loaded.views[0].mask.empty());
  ASSERT_EQ(loaded.views[2].mask.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(loaded.views[2].mask, mask, cv::NORM_INF), 0);
  EXPECT_TRUE(db.load("bottle").views[2].mask.empty()) << "pictures only on request";
  // A mask the metadata lists but that is gone, or of another size: refused naming its file.
  cv::imwrite(dir + "/bottle/view_02_mask.png", cv::Mat(5, 5, CV_8UC1, cv::Scalar(255)));
  try {
    db.load("bottle", true);
    ADD_FAILURE() << "a mask of another size was loaded";
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("view_02_mask.png: the mask is not its view's size"), std::string::npos) << e.what();
  }
  fs::remove(dir + "/bottle/view_02_mask.png");
  EXPECT_THROW(db.load("bottle", true), DatabaseError);
  EXPECT_NO_THROW(db.load("bottle")) << "the features alone need no picture";
  fs::remove_all(dir);
}

TEST(ObjectDatabase, StoringANameAgainReplacesTheObjectWhole) {
  const std::string dir = fresh_folder("replace");
  const ObjectDatabase db(dir);
  db.store(small_model("cup", 4, 1));
  const ObjectModel second = small_model("cup", 2, 2);
  db.store(second);
  expect_same(second, db.load("cup"));
  EXPECT_EQ(entries(dir), std::vector<std::string>{"cup"});  // no old copy, no temporary left
  EXPECT_FALSE(fs::exists(dir + "/cup/view_03.png"));
  fs::remove_all(dir);
}

TEST(ObjectDatabase, AFailedWriteLeavesThePreviousDatabaseIntact) {
  const std::string dir = fresh_folder("failing");
  const ObjectModel first = small_model("cup", 3, 1);
  ObjectDatabase(dir).store(first);
  ObjectDatabase(dir).store(small_model("mug", 2, 3));
  int files = 0;
  const ObjectDatabase failing(dir, [&files](const std::string& path, const std::string& bytes) {
    if (++files == 3) {  // part of the way: two images written, the third fails half-written
      std::ofstream(path, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
      throw std::runtime_error("cannot write " + path + ": injected failure");
    }
    write_file_durably(path, bytes);
  });
  try {
    failing.store(small_model("cup", 5, 2));
    FAIL() << "the store should have failed";
  } catch (const DatabaseError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot store object cup"), std::string::npos) << what;
    EXPECT_NE(what.find("view_02.png: injected failure"), std::string::npos) << what;
  }
  files = 0;
  EXPECT_THROW(failing.store(small_model("bowl", 4, 4)), DatabaseError);
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"cup", "mug"}));  // no bowl, no temporaries
  const LoadReport report = ObjectDatabase(dir).load_all();
  EXPECT_TRUE(report.errors.empty());
  ASSERT_EQ(report.models.size(), 2u);
  expect_same(first, *report.models[0]);
  fs::remove_all(dir);
}

TEST(ObjectDatabase, AnUnfinishedWriteFromACrashIsNotAnObject) {
  const std::string dir = fresh_folder("crash");
  const ObjectDatabase db(dir);
  db.store(small_model("cup", 2, 1));
  fs::create_directory(dir + "/.mug.tmp.4242.0");  // what a crash mid-store leaves
  overwrite(dir + "/.mug.tmp.4242.0/view_00.png", "half a PNG");
  EXPECT_EQ(db.names(), std::vector<std::string>{"cup"});
  const LoadReport report = db.load_all();
  EXPECT_EQ(report.models.size(), 1u);
  EXPECT_TRUE(report.errors.empty());
  fs::remove_all(dir);
}

TEST(ObjectDatabase, ACorruptOrNewerObjectIsRefusedNamingItsFileTheRestLoad) {
  const std::string dir = fresh_folder("corrupt");
  const ObjectDatabase db(dir);
  for (const char* name : {"bottle", "cup", "mug", "vase"}) db.store(small_model(name, 2, name[0]));
  // bottle: one flipped bit in its descriptors.
  std::string bytes = read(dir + "/bottle/features.bin");
  bytes[bytes.size() / 2] ^= 0x10;
  overwrite(dir + "/bottle/features.bin", bytes);
  // cup: metadata cut short.
  const std::string json = read(dir + "/cup/object.json");
  overwrite(dir + "/cup/object.json", json.substr(0, json.size() / 2));
  // mug: written by a newer program.
  std::string newer = read(dir + "/mug/object.json");
  const std::string now = "\"format_version\": " + std::to_string(kDatabaseFormatVersion);
  newer.replace(newer.find(now), now.size(), "\"format_version\": " + std::to_string(kDatabaseFormatVersion + 1));
  overwrite(dir + "/mug/object.json", newer);
  const LoadReport report = db.load_all();
  ASSERT_EQ(report.models.size(), 1u);
  EXPECT_EQ(report.models[0]->info.name, "vase");
  ASSERT_EQ(report.errors.size(), 3u);
  EXPECT_NE(report.errors[0].find(dir + "/bottle/features.bin: checksum mismatch"), std::string::npos) << report.errors[0];
  EXPECT_NE(report.errors[1].find(dir + "/cup/object.json"), std::string::npos) << report.errors[1];
  EXPECT_NE(report.errors[2].find(dir + "/mug/object.json: format version " + std::to_string(kDatabaseFormatVersion + 1) +
                                  " is newer"),
            std::string::npos)
      << report.errors[2];
  // A missing training image is named when the pictures are asked for.
  fs::remove(dir + "/vase/view_01.png");
  EXPECT_NO_THROW(db.load("vase"));
  try {
    db.load("vase", true);
    FAIL();
  } catch (const DatabaseError& e) {
    EXPECT_NE(std::string(e.what()).find("vase/view_01.png"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(ObjectDatabase, RefusesNamesThatAreNotFolderNames) {
  const std::string dir = fresh_folder("names");
  const ObjectDatabase db(dir);
  for (const char* bad : {"", ".hidden", "../escape", "a/b", "sp ace"}) {
    EXPECT_FALSE(valid_object_name(bad)) << bad;
    EXPECT_THROW(db.store(small_model(bad, 1, 1)), DatabaseError) << bad;
  }
  EXPECT_TRUE(valid_object_name("run-7_attempt.03"));
  EXPECT_TRUE(entries(dir).empty());
  EXPECT_THROW(ObjectDatabase("/proc/nudge_no_such_db"), DatabaseError);
  fs::remove_all(dir);
}

// A real full disk: a 256 KiB tmpfs mounted in a private mount namespace of a child process, so
// nothing outside it sees the mount. Needs root (CAP_SYS_ADMIN); skipped otherwise.
TEST(ObjectDatabase, AFullDiskMidWriteLeavesThePreviousDatabaseIntact) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root for a private mount namespace";
  const std::string dir = fresh_folder("tmpfs");
  fs::create_directories(dir);
  const ObjectModel small = small_model("cup", 2, 1, {96, 72});
  const ObjectModel big = small_model("cup", 12, 2, {400, 300});  // far more than 256 KiB of PNG
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto fail = [](const std::string& why) {
      std::cerr << "tmpfs child: " << why << std::endl;
      ::_exit(1);
    };
    if (::unshare(CLONE_NEWNS) != 0) ::_exit(77);
    if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) fail("cannot make / private");
    if (::mount("tmpfs", dir.c_str(), "tmpfs", 0, "size=256k") != 0) ::_exit(77);
    const ObjectDatabase db(dir);
    db.store(small);
    try {
      db.store(big);
      fail("storing 12 large views on a 256 KiB disk did not fail");
    } catch (const DatabaseError& e) {
      const std::string what = e.what();
      if (what.find("No space left on device") == std::string::npos) fail("unclear error: " + what);
      std::cerr << "tmpfs child: " << what << std::endl;
    }
    if (entries(dir) != std::vector<std::string>{"cup"}) fail("temporary folders left behind");
    const LoadReport report = db.load_all(true);
    if (!report.errors.empty() || report.models.size() != 1) fail("the previous database does not load");
    if (report.models[0]->views.size() != 2 || report.models[0]->info.run_id != small.info.run_id)
      fail("the previous object changed");
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  fs::remove_all(dir);
  ASSERT_TRUE(WIFEXITED(status));
  if (WEXITSTATUS(status) == 77) GTEST_SKIP() << "no mount namespaces here";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "see the child's message above";
}
