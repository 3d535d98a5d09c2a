#pragma once
/// A one-line progress report with ETA for long runs: rewritten in place on a terminal, a fresh
/// line every 10% (and at least every 30 s) otherwise, so logs stay short.
#include <chrono>
#include <string>

namespace dem {

class Progress {
 public:
  /// `first`: work already done before this run (a resumed run), left out of the rate behind the ETA.
  Progress(std::string what, long total, long first = 0);
  /// Reports `done` of `total`; `extra` is appended (e.g. current unbalanced-force ratio). Past `total` the line
  /// says so, without an ETA.
  void update(long done, const std::string& extra = "");
  /// The planned work is done, but the stage goes on until a condition holds (a layer settling): the line shows
  /// the time so far and `extra` (what it waits for, and any bound), with no ETA.
  void settling(const std::string& extra);
  void finish(const std::string& extra = "");

 private:
  std::string what_;
  long total_, first_;
  bool tty_;
  int last_decile_ = -1;
  /// Whether a line is due now (twice a second on a terminal; in a log, at a new tenth of the work or after 30 s).
  bool due(int decile);
  std::chrono::steady_clock::time_point start_, last_;
};

std::string format_duration(double seconds);

/// Wall-clock seconds from t0 to now.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace dem
