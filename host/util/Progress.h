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
  // A line in the bar's place until the first update (the scene loading): the
  // time and the share done then are the start the estimate counts from.
  void status(const std::string& text);
  void finish();                           // clears the line

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  bool restart_ = false;  // status() was shown: the next update starts the clock
  double done0_ = 0.0;    // the share done when the clock started
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace pyrolume
