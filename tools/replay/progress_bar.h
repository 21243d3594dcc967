// A one-line progress bar on stderr when it is a terminal; silent otherwise.
#pragma once

#include <chrono>
#include <string>

namespace swarmlio::tools {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  /// Redraws at most 10 times a second; `fraction` in [0, 1].
  void Update(double fraction, const std::string& detail);
  /// Ends the line (when something was drawn).
  void Finish();
  bool enabled() const { return enabled_; }

 private:
  std::string label_;
  bool enabled_ = false;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace swarmlio::tools
