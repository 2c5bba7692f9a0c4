#pragma once
// A progress bar on stderr, drawn only when stderr is a terminal.
#include <chrono>
#include <string>

namespace pyrolume {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  void update(double done, double total);  // redraws at most ~10 times a second
  void finish();                           // clears the line

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace pyrolume
