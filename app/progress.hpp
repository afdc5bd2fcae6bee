// Progress on stderr. On a terminal one line is rewritten in place; when
// stderr is a file or a pipe (a log, a batch system), plain lines are
// written instead, at most one per `log_interval` seconds, so that a log
// holds no carriage returns and does not grow with every update.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace skinmesh::app {

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled, double log_interval = 10.0);
  bool enabled() const { return enabled_; }
  // A line of its own: a stage begins ("preparing the morph ...").
  void note(const std::string& text);
  // The current state; `last` forces it out in a log too (the final update).
  void update(const std::string& text, bool last = false);
  // Ends a rewritten line before other output.
  void finish();

 private:
  bool enabled_ = false, terminal_ = false, open_ = false;
  double log_interval_ = 10.0;
  double last_logged_ = -1e300;  // seconds since construction
  double started_ = 0;           // steady clock, seconds
  double now() const;
};

// The time left of a job of `total` items done one after another, from the
// pace of the most recent ones (a morph's frames can grow: the mean over all
// frames so far would say too little late in the run).
class PaceEstimate {
 public:
  explicit PaceEstimate(size_t total);
  void done_one();               // call when an item is done
  double seconds_left() const;   // -1 until one item is done
  size_t done() const { return stamps_.size() - 1; }

 private:
  size_t total_;
  std::vector<double> stamps_;  // steady clock at the start and after each item
};

}  // namespace skinmesh::app
