#include "host/util/folder_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <stdexcept>
#include <utility>

namespace dem::io {

namespace {

std::string holder_of(int fd) {
  char buf[512] = {};
  const ssize_t n = pread(fd, buf, sizeof(buf) - 1, 0);
  std::string s = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("an unknown process");
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

std::string this_holder() {
  char host[256] = {};
  gethostname(host, sizeof(host) - 1);
  char when[64] = {};
  const std::time_t now = std::time(nullptr);
  std::strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S", std::localtime(&now));
  return "pid " + std::to_string(getpid()) + " on " + host + ", started " + when + "\n";
}

}  // namespace

FolderLock::FolderLock(const std::string& folder)
    : FolderLock(folder, (std::filesystem::path(folder) / ".triaxdem.lock").string(), "output folder '" + folder + "'") {}

FolderLock FolderLock::of_file(const std::string& file) {
  const std::filesystem::path p(file);
  const std::filesystem::path folder = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
  return FolderLock(folder.string(), (folder / ("." + p.filename().string() + ".lock")).string(),
                    "output file '" + file + "'");
}

FolderLock::FolderLock(const std::string& folder, std::string lock, const std::string& subject) : path_(std::move(lock)) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw std::runtime_error("output folder '" + folder + "': cannot be created (" + ec.message() + ")");
  // A holder removes the file before it lets go, so a lock taken on a file that is no longer at the path is
  // taken again on the path's new file: two runs can never hold locks on two different files.
  for (;;) {
    const int fd = open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw std::runtime_error(subject + ": cannot make its lock file (" + std::strerror(errno) + ")");
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::string who = holder_of(fd);
      close(fd);
      if (err == EWOULDBLOCK)
        throw std::runtime_error(subject + " is in use by another run (" + who +
                                 "): wait for it to end, or choose another with -o");
      throw std::runtime_error(subject + ": cannot lock " + path_ + " (" + std::strerror(err) + ")");
    }
    struct stat at_path {}, held {};
    if (stat(path_.c_str(), &at_path) == 0 && fstat(fd, &held) == 0 && at_path.st_ino == held.st_ino &&
        at_path.st_dev == held.st_dev) {
      fd_ = fd;
      break;
    }
    close(fd);
  }
  const std::string me = this_holder();
  if (ftruncate(fd_, 0) != 0 || pwrite(fd_, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size())) {
    release();
    throw std::runtime_error(subject + ": cannot write its lock file " + path_);
  }
}

FolderLock::FolderLock(FolderLock&& o) noexcept : fd_(std::exchange(o.fd_, -1)), path_(std::move(o.path_)) {}

FolderLock& FolderLock::operator=(FolderLock&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = std::exchange(o.fd_, -1);
    path_ = std::move(o.path_);
  }
  return *this;
}

FolderLock::~FolderLock() { release(); }

void FolderLock::release() {
  if (fd_ < 0) return;
  unlink(path_.c_str());
  close(fd_);
  fd_ = -1;
}

}  // namespace dem::io
