#include "host/util/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace dem {

std::string format_duration(double s) {
  char buf[32];
  const long t = static_cast<long>(s + 0.5);
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  return buf;
}

Progress::Progress(std::string what, long total, long first)
    : what_(std::move(what)), total_(total), first_(first), tty_(isatty(fileno(stdout)) != 0),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

bool Progress::due(int decile) {
  const auto now = std::chrono::steady_clock::now();
  // A terminal line is rewritten twice a second; a log gets a line per tenth of the work, and at least one
  // every 30 s so that a long stage (a settling layer) still shows its state.
  const double since = std::chrono::duration<double>(now - last_).count();
  if (tty_ ? since < 0.5 : decile == last_decile_ && since < 30) return false;
  last_ = now;
  last_decile_ = decile;
  return true;
}

void Progress::settling(const std::string& extra) {
  // Its own "tenth" (-2: update's are 0 and up, the first -1): the first settling line is due at once, as the line
  // before it promised an ETA that no longer holds, and a log then gets one every 30 s.
  if (!due(-2)) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::printf("%s%s %ld/%ld (100%%) elapsed %s, no ETA: %s%s", tty_ ? "\r" : "", what_.c_str(), total_, total_,
              format_duration(elapsed).c_str(), extra.c_str(), tty_ ? "   " : "\n");
  std::fflush(stdout);
}

void Progress::update(long done, const std::string& extra) {
  const double frac = total_ > 0 ? static_cast<double>(done) / total_ : 1.0;
  if (!due(static_cast<int>(frac * 10))) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (done > total_) {  // past the plan (a search that widens its range): no ETA to give, but the line goes on
    std::printf("%s%s %ld, beyond the %ld planned; elapsed %s %s%s", tty_ ? "\r" : "", what_.c_str(), done, total_,
                format_duration(elapsed).c_str(), extra.c_str(), tty_ ? "   " : "\n");
    std::fflush(stdout);
    return;
  }
  const long run = done - first_;  // done by this run, at the elapsed time's rate
  // Nothing done yet gives no rate: the line says when an ETA will come, not a false 0m00s.
  const std::string eta = run > 0 ? format_duration(elapsed * static_cast<double>(total_ - done) / run)
                                  : std::string("after the first");
  std::printf("%s%s %ld/%ld (%3.0f%%) elapsed %s ETA %s %s%s", tty_ ? "\r" : "", what_.c_str(), done, total_,
              100 * frac, format_duration(elapsed).c_str(), eta.c_str(), extra.c_str(), tty_ ? "   " : "\n");
  std::fflush(stdout);
}

void Progress::finish(const std::string& extra) {
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::printf("%s%s done in %s %s\n", tty_ ? "\r" : "", what_.c_str(), format_duration(elapsed).c_str(),
              extra.c_str());
  std::fflush(stdout);
}

}  // namespace dem
