// The daemon's hold on its SQLite file: an exclusive lock, so that a second
// `pvtwin run` on the same store stops at start instead of overwriting the
// first one's forecasts, and a check that the file it writes is still the
// one at its path (deleting or replacing the file while the daemon runs
// would otherwise send every later sample into an unlinked inode, silently).
//
// The lock is flock(2) on a read-only descriptor of the database file.
// SQLite's own locks are POSIX record locks, which Linux keeps apart from
// flock locks; since closing any descriptor of the file drops a process's
// POSIX locks, the descriptor is held until the Store is closed (declare the
// StoreLock before the Store it guards).
#pragma once

#include <sys/types.h>

#include <string>

namespace pvtwin {

class StoreLock {
 public:
  StoreLock() = default;
  ~StoreLock();
  StoreLock(const StoreLock&) = delete;
  StoreLock& operator=(const StoreLock&) = delete;

  // Takes the lock on the existing file at path. False, with the reason,
  // when the file cannot be opened or another process holds the lock.
  bool Acquire(const std::string& path, std::string* error);

  // True while the locked file still has a name and that name still refers
  // to it; otherwise false with what happened ("deleted", "replaced").
  bool StillAtPath(std::string* why) const;

 private:
  std::string path_;
  int fd_ = -1;
  dev_t dev_ = 0;
  ino_t ino_ = 0;
};

}  // namespace pvtwin
