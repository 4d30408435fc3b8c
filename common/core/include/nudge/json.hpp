#pragma once
// A minimal streaming JSON writer for tool output and result files (no parsing).
//   JsonWriter j; j.begin_object(); j.key("a").value(1.5); j.end_object(); j.str();
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace nudge {

class JsonWriter {
 public:
  explicit JsonWriter(int precision = 6) { out_.precision(precision); }

  JsonWriter& begin_object() { separate(); out_ << '{'; first_.push_back(true); return *this; }
  JsonWriter& end_object() { out_ << '}'; first_.pop_back(); return *this; }
  JsonWriter& begin_array() { separate(); out_ << '['; first_.push_back(true); return *this; }
  JsonWriter& end_array() { out_ << ']'; first_.pop_back(); return *this; }
  JsonWriter& key(const std::string& k) {
    separate();
    write_string(k);
    out_ << ':';
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(double v) {
    separate();
    if (std::isfinite(v)) out_ << v;
    else out_ << "null";  // JSON has no NaN/inf
    return *this;
  }
  JsonWriter& value(int v) { separate(); out_ << v; return *this; }
  JsonWriter& value(long v) { separate(); out_ << v; return *this; }
  JsonWriter& value(long long v) { separate(); out_ << v; return *this; }
  JsonWriter& value(bool v) { separate(); out_ << (v ? "true" : "false"); return *this; }
  JsonWriter& value(const std::string& v) { separate(); write_string(v); return *this; }
  JsonWriter& value(const char* v) { return value(std::string(v)); }
  // A value that is already JSON (e.g. another writer's str()).
  JsonWriter& raw(const std::string& json) { separate(); out_ << json; return *this; }
  template <typename T>
  JsonWriter& field(const std::string& k, const T& v) { key(k); return value(v); }

  std::string str() const { return out_.str(); }

 private:
  void separate() {
    if (after_key_) { after_key_ = false; return; }
    if (!first_.empty()) {
      if (!first_.back()) out_ << ',';
      first_.back() = false;
    }
  }
  void write_string(const std::string& s) {
    out_ << '"';
    for (unsigned char c : s) {
      switch (c) {
        case '"': out_ << "\\\""; break;
        case '\\': out_ << "\\\\"; break;
        case '\n': out_ << "\\n"; break;
        case '\t': out_ << "\\t"; break;
        case '\r': out_ << "\\r"; break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out_ << buf;
          } else {
            out_ << c;
          }
      }
    }
    out_ << '"';
  }
  std::ostringstream out_;
  std::vector<bool> first_;
  bool after_key_ = false;
};

}  // namespace nudge
