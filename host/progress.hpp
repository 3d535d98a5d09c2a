#pragma once
/// A one-line progress report with ETA for long runs: rewritten in place on a terminal, a fresh
/// line every 10% (and at least every 30 s) otherwise, so logs stay short.
#include <chrono>
#include <string>

namespace dem {

class Progress {
 public:
  Progress(std::string what, long total);
  /// Reports `done` of `total`; `extra` is appended (e.g. current unbalanced-force ratio).
  void update(long done, const std::string& extra = "");
  void finish(const std::string& extra = "");

 private:
  std::string what_;
  long total_;
  bool tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_;
};

std::string format_duration(double seconds);

}  // namespace dem
