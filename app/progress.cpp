#include "progress.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <unistd.h>

namespace skinmesh::app {
namespace {

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ProgressLine::ProgressLine(bool enabled, double log_interval)
    : enabled_(enabled), terminal_(::isatty(::fileno(stderr)) == 1), log_interval_(log_interval),
      started_(steady_seconds()) {}

double ProgressLine::now() const { return steady_seconds() - started_; }

void ProgressLine::note(const std::string& text) {
  if (!enabled_) return;
  finish();
  std::fprintf(stderr, "skinmesh: %s\n", text.c_str());
  std::fflush(stderr);
}

void ProgressLine::update(const std::string& text, bool last) {
  if (!enabled_) return;
  if (terminal_) {
    std::fprintf(stderr, "\rskinmesh: %-72s", text.c_str());
    open_ = true;
  } else {
    const double t = now();
    if (!last && t - last_logged_ < log_interval_) return;
    last_logged_ = t;
    std::fprintf(stderr, "skinmesh: %s\n", text.c_str());
  }
  std::fflush(stderr);
}

void ProgressLine::finish() {
  if (!enabled_ || !open_) return;
  std::fprintf(stderr, "\n");
  std::fflush(stderr);
  open_ = false;
}

PaceEstimate::PaceEstimate(size_t total) : total_(total), stamps_{steady_seconds()} {}

void PaceEstimate::done_one() { stamps_.push_back(steady_seconds()); }

double PaceEstimate::seconds_left() const {
  const size_t n = done();
  if (n == 0) return -1;
  // The mean of the last fifth of the items (at least three, or all there are).
  const size_t recent = std::min(n, std::max<size_t>(3, n / 5));
  const double per_item = (stamps_.back() - stamps_[n - recent]) / static_cast<double>(recent);
  return per_item * static_cast<double>(total_ > n ? total_ - n : 0);
}

}  // namespace skinmesh::app
