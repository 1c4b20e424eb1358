#include "io/store/store_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace pvtwin {

StoreLock::~StoreLock() {
  if (fd_ >= 0) ::close(fd_);
}

bool StoreLock::Acquire(const std::string& path, std::string* error) {
  path_ = path;
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    *error = path + ": cannot open to lock it: " + std::strerror(errno);
    return false;
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    *error = path + (e == EWOULDBLOCK ? ": in use by another pvtwin run (two daemons on one "
                                        "store would overwrite each other's forecasts)"
                                      : std::string(": cannot lock: ") + std::strerror(e));
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  struct stat st {};
  ::fstat(fd_, &st);
  dev_ = st.st_dev;
  ino_ = st.st_ino;
  return true;
}

bool StoreLock::StillAtPath(std::string* why) const {
  if (fd_ < 0) return true;
  struct stat held {};
  if (::fstat(fd_, &held) == 0 && held.st_nlink == 0) {
    *why = "deleted";
    return false;
  }
  struct stat named {};
  if (::stat(path_.c_str(), &named) != 0) {
    *why = std::string("gone from its path (") + std::strerror(errno) + ")";
    return false;
  }
  if (named.st_dev != dev_ || named.st_ino != ino_) {
    *why = "replaced by another file";
    return false;
  }
  return true;
}

}  // namespace pvtwin
