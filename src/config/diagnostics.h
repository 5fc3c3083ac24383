// SPDX-License-Identifier: Apache-2.0
// Error messages of the configuration parser: FILE:LINE: error: ..., all of them, in
// line order, capped.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "config/public/outline.h"

namespace ccomm {
namespace config_detail {

// Beyond this many messages the rest are usually consequences of the first ones.
constexpr size_t kMaxReportedErrors = 50;

class Diagnostics {
 public:
  Diagnostics(std::string path, const char* begin, size_t size)
      : path_(std::move(path)), begin_(begin), size_(size) {
    line_starts_.push_back(0);
    for (size_t i = 0; i < size; ++i)
      if (begin[i] == '\n') line_starts_.push_back(i + 1);
  }

  // 1-based line of a pointer into the text; 0 if it does not point into it.
  int LineOf(const char* p) const {
    if (p == nullptr || p < begin_ || p > begin_ + size_) return 0;
    size_t off = static_cast<size_t>(p - begin_);
    auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), off);
    return static_cast<int>(it - line_starts_.begin());
  }

  void Error(int line, std::string message) {
    entries_.push_back({line, std::move(message)});
    // Only the first kMaxReportedErrors by line are reported, but cross-reference errors
    // arrive after the walk and may belong before stored ones: trim now and then to the
    // lowest lines seen so far instead of dropping late arrivals.
    if (entries_.size() >= 20 * kMaxReportedErrors) Trim();
  }

  bool empty() const { return entries_.empty(); }

  // Messages in line order (cross-reference checks run after the walk), capped.
  std::string Render() {
    Trim();
    std::string out;
    size_t n = std::min(entries_.size(), kMaxReportedErrors);
    for (size_t i = 0; i < n; ++i) {
      if (i) out += '\n';
      out += Prefix(entries_[i].line) + entries_[i].message;
    }
    if (overflow_) {
      out += '\n';
      out += Prefix(0) + "too many errors; stopped after " + std::to_string(kMaxReportedErrors);
    }
    return out;
  }

 private:
  struct Entry {
    int line;
    std::string message;
  };
  // Sorts by line (stable: equal lines keep the order they were found in) and keeps the
  // first kMaxReportedErrors.
  void Trim() {
    std::stable_sort(entries_.begin(), entries_.end(),
                     [](const Entry& a, const Entry& b) { return a.line < b.line; });
    if (entries_.size() > kMaxReportedErrors) {
      entries_.resize(kMaxReportedErrors);
      overflow_ = true;
    }
  }
  std::string Prefix(int line) const { return ConfigError(path_, line, ""); }

  std::string path_;
  const char* begin_;
  size_t size_;
  std::vector<size_t> line_starts_;
  std::vector<Entry> entries_;
  bool overflow_ = false;
};

}  // namespace config_detail
}  // namespace ccomm
