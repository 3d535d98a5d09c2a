#pragma once
/// An exclusive claim on an output folder for the life of a run, so that two runs started into one folder cannot
/// mix their files: the second is refused before it writes anything, naming the first.
#include <string>

namespace dem::io {

/// Holds flock(LOCK_EX) on FOLDER/.triaxdem.lock, which names the holder (pid, host, start time). The kernel drops
/// the lock when the holder exits, however it exits, so a lock file left by a killed run is taken over, never
/// waited for. Moves; does not copy.
class FolderLock {
 public:
  FolderLock() = default;
  /// Creates the folder if needed and takes its lock. Throws std::runtime_error naming the folder and the run
  /// that holds it, or why the lock file cannot be made.
  explicit FolderLock(const std::string& folder);
  /// The same claim on one output file (synth -o): FOLDER/.NAME.lock beside it.
  static FolderLock of_file(const std::string& file);
  FolderLock(FolderLock&& o) noexcept;
  FolderLock& operator=(FolderLock&& o) noexcept;
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();

  bool held() const { return fd_ >= 0; }

 private:
  FolderLock(const std::string& folder, std::string lock, const std::string& subject);
  int fd_ = -1;
  std::string path_;
  void release();
};

}  // namespace dem::io
