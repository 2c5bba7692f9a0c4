#include "util/Progress.h"

#include <unistd.h>

#include <cstdio>

namespace pyrolume {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()), last_() {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double done, double total) {
  if (!enabled_ || total <= 0) return;
  auto now = std::chrono::steady_clock::now();
  double frac = done / total;
  if (frac > 1) frac = 1;
  if (restart_) {  // the first pass after loading: the rate is measured from here
    restart_ = false;
    start_ = now;
    done0_ = frac;
  } else if (drawn_ && done < total && now - last_ < std::chrono::milliseconds(100)) {
    return;
  }
  last_ = now;
  const int width = 30;
  int filled = static_cast<int>(frac * width);
  double elapsed = std::chrono::duration<double>(now - start_).count();
  double eta = frac > done0_ && elapsed > 0 ? elapsed * (1 - frac) / (frac - done0_) : 0;
  std::string bar(filled, '#');
  bar.append(width - filled, '.');
  std::fprintf(stderr, "\r\033[K%s [%s] %5.1f%%  %.1fs elapsed, ~%.1fs left", label_.c_str(), bar.c_str(), 100 * frac,
               elapsed, eta);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::status(const std::string& text) {
  if (!enabled_) return;
  std::fprintf(stderr, "\r\033[K%s: %s", label_.c_str(), text.c_str());
  std::fflush(stderr);
  drawn_ = true;
  restart_ = true;
}

void ProgressBar::finish() {
  if (enabled_ && drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  drawn_ = false;
}

}  // namespace pyrolume
