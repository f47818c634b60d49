#include "common/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace roamlab {
namespace {

double SteadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

bool IsTerminal(const std::ostream& out) {
  if (&out == &std::cout) return isatty(STDOUT_FILENO) == 1;
  if (&out == &std::cerr || &out == &std::clog) return isatty(STDERR_FILENO) == 1;
  return false;
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  const long s = std::lround(seconds);
  char text[32];
  if (s < 60)
    std::snprintf(text, sizeof text, "%lds", s);
  else if (s < 3600)
    std::snprintf(text, sizeof text, "%ldm%02lds", s / 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%ldh%02ldm", s / 3600, s / 60 % 60);
  return text;
}

double SecondsLeft(double seconds, double fraction) {
  if (!(fraction > 0.0)) return std::nan("");
  return fraction >= 1.0 ? 0.0 : seconds * (1.0 - fraction) / fraction;
}

std::string ElapsedAndLeft(double elapsed_s, double left_s) {
  std::string text = ", " + FormatDuration(elapsed_s) + " elapsed";
  if (std::isfinite(left_s) && left_s > 0.0) text += ", about " + FormatDuration(left_s) + " left";
  return text;
}

ProgressMeter::ProgressMeter(std::string label, std::ostream* out)
    : ProgressMeter(std::move(label), out, IsTerminal(*out), SteadySeconds) {}

ProgressMeter::ProgressMeter(std::string label, std::ostream* out, bool terminal, std::function<double()> clock_s)
    : label_(std::move(label)), out_(out), terminal_(terminal), clock_s_(std::move(clock_s)), start_s_(clock_s_()) {}

ProgressMeter::~ProgressMeter() { Finish(); }

double ProgressMeter::ElapsedSeconds() const { return clock_s_() - start_s_; }

void ProgressMeter::Update(int done, int total) {
  const double fraction = total > 0 ? static_cast<double>(done) / total : 1.0;
  Draw(fraction, " " + std::to_string(done) + "/" + std::to_string(total));
}

void ProgressMeter::Update(double fraction) { Draw(fraction, ""); }

void ProgressMeter::Draw(double fraction, const std::string& counts) {
  std::lock_guard<std::mutex> lock(mutex_);
  fraction = std::min(1.0, std::max(0.0, fraction));
  const int step = static_cast<int>(std::floor(fraction / kLogStep + 1e-9));
  if (!terminal_ && step <= logged_steps_) return;
  logged_steps_ = step;
  char percent[16];
  std::snprintf(percent, sizeof percent, "%s%.0f%%", counts.empty() ? " " : " (", 100.0 * fraction);
  if (first_fraction_ < 0.0) {
    first_fraction_ = fraction;
    first_s_ = clock_s_();
  }
  // The time left at the rate since the first update.
  const double progressed = first_fraction_ < 1.0 ? (fraction - first_fraction_) / (1.0 - first_fraction_) : 1.0;
  const double left_s = SecondsLeft(clock_s_() - first_s_, progressed);
  const std::string line =
      label_ + ":" + counts + percent + (counts.empty() ? "" : ")") + ElapsedAndLeft(ElapsedSeconds(), left_s);
  if (terminal_) {
    // Padding clears what a longer earlier line left.
    *out_ << "\r" << line << "   " << std::flush;
    line_open_ = true;
  } else {
    *out_ << line << "\n" << std::flush;
  }
}

void ProgressMeter::Note(const std::string& line) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (line_open_) *out_ << "\r\033[K";
  line_open_ = false;
  *out_ << label_ << ": " << line << " (" << FormatDuration(ElapsedSeconds()) << ")\n" << std::flush;
}

void ProgressMeter::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (line_open_) *out_ << "\n" << std::flush;
  line_open_ = false;
}

}  // namespace roamlab
