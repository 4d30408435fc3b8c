#include "learner/handlers.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/learn_result_t.hpp"
#include "nudge/log.hpp"
#include "nudge/recognition_t.hpp"
#include "nudge/timing.hpp"

namespace nudge::learner_service {

namespace {

std::string describe(const std::string& run_id, const std::string& object_key) {
  return "run '" + run_id + "' object '" + object_key + "'";
}

cv::Rect rect_of(const int32_t r[4]) { return cv::Rect(r[0], r[1], r[2], r[3]); }

// The name an object is stored under when the supervisor names none: run and key, with anything a
// folder name cannot hold replaced.
std::string default_name(const std::string& run_id, const std::string& object_key) {
  std::string name = run_id + "_" + object_key;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  while (!name.empty() && name[0] == '.') name.erase(0, 1);
  return name;
}

// The model without its training images: the recognizer needs only features, the database keeps
// the pictures (loaded again for a match picture).
std::shared_ptr<const learning::ObjectModel> without_images(learning::ObjectModel model) {
  for (auto& view : model.views) view.image.release();
  return std::make_shared<const learning::ObjectModel>(std::move(model));
}

}  // namespace

Handlers::Handlers(bus::Service& service, const Options& options)
    : service_(service), options_(options), db_(options.db_dir), recognizer_(options.recognize) {
  learning::LoadReport loaded = db_.load_all();
  for (const std::string& error : loaded.errors) report("skipped: " + error);
  for (auto& model : loaded.models) {
    // Still known, but its matches will be fewer: said once, at load, naming the object.
    if (model->info.sift_recorded) {
      const std::string difference = learning::sift_settings_difference(model->info.sift, options.recognize.sift);
      if (!difference.empty())
        report("object " + model->info.name + " was learned with other SIFT settings than this learner's (" + difference +
               "): it will match less well; learn it again or start the learner with its settings");
    }
    recognizer_.add(model);
  }
  recognizer_.build_index();  // once for the whole database, not on the first request
  log::info() << "object database " << db_.root() << ": " << recognizer_.size() << " objects";
  auto& subs = service_.subscriptions();
  subs.subscribe<learn_view_t>(bus::channel::LEARN_VIEW, [this](const learn_view_t& m, const std::string&) { on_view(m); });
  subs.subscribe<learn_commit_t>(bus::channel::LEARN_COMMIT,
                                 [this](const learn_commit_t& m, const std::string&) { on_commit(m); });
  subs.subscribe<recognize_request_t>(bus::channel::RECOGNIZE_REQUEST,
                                      [this](const recognize_request_t& m, const std::string&) { on_recognize(m); });
}

void Handlers::report(const std::string& what) {
  log::warn() << what;
  ++service_.counters().errors;
}

void Handlers::expire(int64_t now_utime) {
  const auto expiry = static_cast<int64_t>(options_.view_expiry_s * 1e6);
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (now_utime - it->second.last_utime > expiry) {
      report("LEARN_VIEW: " + describe(it->first.first, it->first.second) + ": " +
             std::to_string(it->second.views.size()) + " views never committed within " +
             std::to_string(options_.view_expiry_s) + " s; dropped");
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
}

void Handlers::on_view(const learn_view_t& msg) {
  expire(msg.utime);
  const Key key(msg.run_id, msg.object_key);
  const bool scene = msg.kind == learn_view_t::KIND_SCENE;
  const std::string what =
      "LEARN_VIEW " + describe(msg.run_id, msg.object_key) + (scene ? " scene still" : " view " + std::to_string(msg.view_index));
  if (!pending_.count(key) && static_cast<int>(pending_.size()) >= options_.max_pending_objects) {
    auto oldest = std::min_element(pending_.begin(), pending_.end(), [](const auto& a, const auto& b) {
      return a.second.last_utime < b.second.last_utime;
    });
    report("LEARN_VIEW: more than " + std::to_string(options_.max_pending_objects) + " objects uncommitted; dropped " +
           describe(oldest->first.first, oldest->first.second));
    pending_.erase(oldest);
  }
  Pending& pending = pending_[key];
  pending.last_utime = std::max(pending.last_utime, msg.utime);
  auto refuse = [&](const std::string& why) {
    pending.bad_views += (pending.bad_views.empty() ? "" : "; ") +
                         ((scene ? std::string("scene still") : "view " + std::to_string(msg.view_index)) + ": " + why);
    report(what + ": " + why);
  };
  if (msg.kind != learn_view_t::KIND_VIEW && !scene)
    return refuse("kind " + std::to_string(msg.kind) + " is neither KIND_VIEW (0) nor KIND_SCENE (1)");
  if (!scene && (msg.view_index < 0 || msg.view_index >= options_.max_views))
    return refuse("view_index outside 0.." + std::to_string(options_.max_views - 1));
  learning::TrainingImage view;
  try {
    view.image = bus::to_mat(msg.image);
  } catch (const bus::ImageError& e) {
    return refuse(std::string("undecodable image: ") + e.what());
  }
  if (scene) {
    pending.scene = std::move(view.image);
    return;
  }
  const cv::Rect box = rect_of(msg.box);
  if (box.width > 0 && (box.height <= 0 || (box & cv::Rect(cv::Point(0, 0), view.image.size())).empty()))
    return refuse("box lies outside the image");
  view.box = box.width > 0 ? box : cv::Rect();
  view.wrist_angle = msg.wrist_angle;
  if (msg.mask.width > 0) {
    try {
      view.mask = bus::to_mat(msg.mask);
    } catch (const bus::ImageError& e) {
      return refuse(std::string("undecodable mask: ") + e.what());
    }
    if (view.mask.channels() == 3) cv::cvtColor(view.mask, view.mask, cv::COLOR_BGR2GRAY);
    if (view.mask.type() != CV_8UC1 || view.mask.size() != view.image.size())
      return refuse("mask is not 8-bit grey of the image's size (" + std::to_string(view.mask.cols) + "x" +
                    std::to_string(view.mask.rows) + " against " + std::to_string(view.image.cols) + "x" +
                    std::to_string(view.image.rows) + ")");
  }
  pending.views[msg.view_index] = std::move(view);
}

void Handlers::on_commit(const learn_commit_t& msg) {
  expire(msg.utime);
  learn_result_t out{};  // value-initialised: LCM leaves numbers unset
  out.utime = msg.utime;
  out.seq = msg.seq;
  out.run_id = msg.run_id;
  out.object_key = msg.object_key;
  out.object_name = msg.object_name.empty() ? default_name(msg.run_id, msg.object_key) : msg.object_name;
  out.ok = false;
  out.views_used = out.descriptors = out.descriptors_pruned = 0;
  const std::string what = "LEARN_COMMIT " + describe(msg.run_id, msg.object_key);
  auto fail = [&](const std::string& why) {
    out.reason = why;
    report(what + ": " + why);
    service_.publish(bus::channel::LEARNED, out);
  };
  const auto it = pending_.find({msg.run_id, msg.object_key});
  if (worker_.busy() && it != pending_.end() && !it->second.views.empty())
    // A queue of one: the views stay, the same commit sent again after that LEARNED is learned.
    return fail("busy " + worker_.status() + ": LEARN_COMMIT refused, its views kept; send it again after that LEARNED");
  if (it == pending_.end() || it->second.views.empty()) {
    const std::string bad = it == pending_.end() ? "" : " (" + it->second.bad_views + ")";
    if (it != pending_.end()) pending_.erase(it);
    return fail("no usable views received for " + describe(msg.run_id, msg.object_key) + bad);
  }
  if (!learning::valid_object_name(out.object_name)) {
    pending_.erase(it);
    return fail("object name '" + out.object_name + "' is not usable as a folder name ([A-Za-z0-9_.-])");
  }
  Pending pending = std::move(it->second);
  pending_.erase(it);
  auto images = std::make_shared<std::vector<learning::TrainingImage>>();
  for (auto& [index, view] : pending.views) images->push_back(std::move(view));
  // A scene still that cannot serve is left out, not the object: the across-views rule still prunes.
  cv::Mat scene = pending.scene;
  if (!scene.empty() && (scene.size() != images->front().image.size() || scene.depth() != CV_8U)) {
    log::warn() << what << ": the scene still (" << scene.cols << "x" << scene.rows
                << ") is not the views' size or not 8-bit: learned without it";
    scene.release();
  }
  if (static_cast<int>(images->size()) != msg.num_views)
    log::warn() << what << ": " << images->size() << " of " << msg.num_views << " views arrived"
                << (pending.bad_views.empty() ? "" : " (" + pending.bad_views + ")");
  learning::ObjectInfo info;
  info.name = out.object_name;
  info.run_id = msg.run_id;
  info.object_key = msg.object_key;
  info.learned_utime = msg.utime;
  info.height = msg.height;
  info.radius = msg.radius;
  out.views_used = static_cast<int32_t>(images->size());
  job_ = Job{out, {}, {}};
  // The worker learns and stores (the database write is atomic: nothing half-written if it fails);
  // the recognizer is only touched on this thread, in poll().
  worker_.submit(msg.object_key, [this, info, images, scene](const LearnWorker::Progress& progress) {
    job_.model = learning::learn_object(info, *images, options_.learn, &job_.stats, progress, scene);
    db_.store(job_.model);
  });
  service_.set_status(worker_.status());
}

void Handlers::poll() {
  if (const auto ended = worker_.take_ended()) learned(*ended);
  service_.set_status(worker_.status());
}

void Handlers::finish_learning() {
  worker_.wait_until_ended();
  poll();
}

void Handlers::learned(const LearnWorker::Ended& ended) {
  learn_result_t out = std::move(job_.answer);
  learning::ObjectModel model = std::move(job_.model);
  const learning::LearnStats stats = job_.stats;
  job_ = Job{};
  if (ended.error.empty()) {
    try {
      recognizer_.add(without_images(std::move(model)));
      recognizer_.build_index();  // the new object is found from the next request on
    } catch (const std::exception& e) {
      out.reason = e.what();
    }
  } else {
    out.reason = ended.error;  // a bad view or the database refusing: reported, nothing half-stored
  }
  if (!out.reason.empty()) {
    out.views_used = 0;
    report("LEARN_COMMIT " + describe(out.run_id, out.object_key) + ": " + out.reason);
    service_.publish(bus::channel::LEARNED, out);
    return;
  }
  out.ok = true;
  out.descriptors = stats.kept;
  out.descriptors_pruned = stats.outside_box + stats.outside_mask + stats.background;
  out.descriptors_pruned += stats.scene;
  log::info() << "learned " << out.object_name << " from " << out.views_used << " views: " << stats.kept
              << " descriptors kept, " << stats.outside_box << " outside the box, " << stats.outside_mask
              << " off a mask, " << stats.background
              << " background, " << stats.scene << " in place in the scene still";
  service_.publish(bus::channel::LEARNED, out);
}

void Handlers::on_recognize(const recognize_request_t& msg) {
  Stopwatch watch;
  recognition_t out{};  // match_picture stays empty (size 0) unless asked for
  out.utime = msg.utime;
  out.seq = msg.seq;
  out.best_view = -1;
  out.learned_utime = 0;
  out.num_objects = 0;
  out.elapsed_ms = 0;
  const std::string what = "RECOGNIZE_REQUEST seq " + std::to_string(msg.seq);
  auto fail = [&](const std::string& why) {
    out.reason = why;
    report(what + ": " + why);
    out.elapsed_ms = watch.elapsed_ms();
    service_.publish(bus::channel::RECOGNITION, out);
  };
  cv::Mat image;
  try {
    image = bus::to_mat(msg.image);
  } catch (const bus::ImageError& e) {
    return fail(std::string("undecodable image: ") + e.what());
  }
  const cv::Rect roi = msg.roi[2] > 0 ? rect_of(msg.roi) : cv::Rect();
  if (roi.width > 0 && (roi.height <= 0 || (roi & cv::Rect(cv::Point(0, 0), image.size())).empty()))
    return fail("roi lies outside the image");
  const learning::Recognition result = recognizer_.recognize(image, roi);
  for (const auto& score : result.scores) {
    out.names.push_back(score.name);
    out.matches.push_back(score.verified_matches);
  }
  out.num_objects = static_cast<int32_t>(out.names.size());
  out.reason = result.reason;
  if (const learning::ObjectScore* best = result.best_score()) {
    out.label = best->name;
    out.best_view = best->best_view;
    const learning::ObjectModel& model = recognizer_.model(result.best);
    out.learned_utime = model.info.learned_utime;
    if (msg.want_match_picture) {
      try {
        const cv::Mat training = db_.load_view_image(best->name, best->best_view);
        const cv::Mat picture =
            learning::draw_match_picture(image, training, model.views[best->best_view].features, result);
        out.match_picture = bus::to_message(picture, image_t::FORMAT_PNG, msg.utime, 0, "match");
      } catch (const std::exception& e) {
        report(what + ": no match picture: " + e.what());
      }
    }
  }
  out.elapsed_ms = watch.elapsed_ms();
  service_.publish(bus::channel::RECOGNITION, out);
}

}  // namespace nudge::learner_service
