// A minimal streaming JSON writer for --json (objects, arrays, strings, numbers, booleans).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace surftrack::cli {

class JsonWriter {
 public:
  JsonWriter& beginObject() { return open('{'); }
  JsonWriter& endObject() { return close('}'); }
  JsonWriter& beginArray() { return open('['); }
  JsonWriter& endArray() { return close(']'); }

  /// The key of the next value inside an object.
  JsonWriter& key(const std::string& k) {
    separator();
    quote(k);
    out_ += ": ";
    afterKey_ = true;
    return *this;
  }

  JsonWriter& value(const std::string& s) {
    separator();
    quote(s);
    return *this;
  }
  JsonWriter& value(const char* s) { return value(std::string(s)); }
  JsonWriter& value(bool b) {
    separator();
    out_ += b ? "true" : "false";
    return *this;
  }
  JsonWriter& value(double d) {
    separator();
    if (!std::isfinite(d)) {
      out_ += "null";
    } else if (d == std::floor(d) && std::abs(d) < 1e15) {
      out_ += std::to_string((long long)d);
    } else {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.10g", d);
      out_ += buf;
    }
    return *this;
  }
  JsonWriter& value(int v) { return integer((long long)v); }
  JsonWriter& value(long v) { return integer((long long)v); }
  JsonWriter& value(long long v) { return integer(v); }
  JsonWriter& value(unsigned v) { return integer((long long)v); }
  JsonWriter& value(unsigned long v) { return integer((long long)v); }
  JsonWriter& value(unsigned long long v) { return integer((long long)v); }
  JsonWriter& null() {
    separator();
    out_ += "null";
    return *this;
  }

  template <class Container>
  JsonWriter& array(const Container& values) {
    beginArray();
    for (const auto& v : values) value(v);
    return endArray();
  }

  const std::string& str() const { return out_; }

 private:
  JsonWriter& integer(long long v) {
    separator();
    out_ += std::to_string(v);
    return *this;
  }
  JsonWriter& open(char ch) {
    separator();
    out_ += ch;
    first_.push_back(true);
    return *this;
  }
  JsonWriter& close(char ch) {
    const bool empty = first_.back();
    first_.pop_back();
    if (!empty) newline();
    out_ += ch;
    return *this;
  }
  void separator() {
    if (afterKey_) {
      afterKey_ = false;
      return;
    }
    if (first_.empty()) return;
    if (!first_.back()) out_ += ',';
    first_.back() = false;
    newline();
  }
  void newline() {
    out_ += '\n';
    out_.append(2 * first_.size(), ' ');
  }
  void quote(const std::string& s) {
    out_ += '"';
    for (unsigned char ch : s) {
      switch (ch) {
        case '"': out_ += "\\\""; break;
        case '\\': out_ += "\\\\"; break;
        case '\n': out_ += "\\n"; break;
        case '\r': out_ += "\\r"; break;
        case '\t': out_ += "\\t"; break;
        default:
          if (ch < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", ch);
            out_ += buf;
          } else {
            out_ += char(ch);
          }
      }
    }
    out_ += '"';
  }

  std::string out_;
  std::vector<bool> first_;
  bool afterKey_ = false;
};

}  // namespace surftrack::cli
