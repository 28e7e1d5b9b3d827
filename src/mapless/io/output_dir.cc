#include "mapless/io/output_dir.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "mapless/core/check.h"

namespace mapless::io {
namespace fs = std::filesystem;

DirectoryLock::DirectoryLock(const std::string& dir) {
  // The lock is on the directory itself: nothing is added to it.
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw InputError(dir + ": cannot open the directory: " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(dir + ": another mapless process is writing to this directory (locked)");
  }
}

DirectoryLock::~DirectoryLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

bool IsEmptyOrMissing(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return true;
  if (!fs::is_directory(dir, ec)) return false;
  return fs::directory_iterator(dir, ec) == fs::directory_iterator() && !ec;
}

OutputDirectory::OutputDirectory(std::string target, bool replace, std::string what,
                                 std::string marker)
    : target_(std::move(target)) {
  std::error_code ec;
  while (target_.size() > 1 && target_.back() == '/') target_.pop_back();
  if (target_.empty()) throw InputError("the output directory name is empty");
  if (fs::exists(target_, ec) && !fs::is_directory(target_, ec)) {
    throw InputError(target_ + ": is a file, not a directory; choose a directory for the " + what);
  }
  if (IsEmptyOrMissing(target_)) {
    created_ = !fs::exists(target_, ec);
    std::error_code mk;
    fs::create_directories(target_, mk);
    if (mk) throw InputError(target_ + ": cannot create directory: " + mk.message());
    lock_ = std::make_unique<DirectoryLock>(target_);
    if (!IsEmptyOrMissing(target_)) {  // another process filled it between the two looks
      throw InputError(target_ + ": another process wrote to this directory meanwhile");
    }
    path_ = target_;
    return;
  }
  const bool ours = fs::is_regular_file(fs::path(target_) / marker, ec);
  if (!replace) {
    throw InputError(target_ + ": not empty; choose a new or empty directory for the " + what +
                     (ours ? ", or --overwrite to replace the " + what + " there" : ""));
  }
  if (!ours) {
    throw InputError(target_ + ": holds something else than a " + what + " (no " + marker +
                     "), so --overwrite will not replace it; choose a new or empty directory");
  }
  lock_ = std::make_unique<DirectoryLock>(target_);
  path_ = target_ + ".partial-" + std::to_string(::getpid());
  fs::remove_all(path_, ec);
  fs::create_directories(path_, ec);
  if (ec) throw InputError(path_ + ": cannot create directory: " + ec.message());
}

void OutputDirectory::Discard() {
  if (committed_) return;
  std::error_code ec;
  if (staged()) {
    fs::remove_all(path_, ec);
    return;
  }
  // Written in place: the directory was new or empty, so all in it is this run's.
  for (const fs::directory_entry& e : fs::directory_iterator(target_, ec)) fs::remove_all(e, ec);
  if (created_) fs::remove(target_, ec);
}

OutputDirectory::~OutputDirectory() {
  if (committed_ || !staged()) return;
  std::error_code ec;
  fs::remove_all(path_, ec);
}

void OutputDirectory::Commit() {
  if (committed_) return;
  committed_ = true;
  if (!staged()) return;
  const std::string old = target_ + ".old-" + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(old, ec);
  fs::rename(target_, old, ec);
  if (ec) throw InputError(target_ + ": cannot move the old content aside: " + ec.message());
  fs::rename(path_, target_, ec);
  if (ec) {
    std::error_code back;
    fs::rename(old, target_, back);
    throw InputError(target_ + ": cannot put the new content in place: " + ec.message());
  }
  fs::remove_all(old, ec);
}

}  // namespace mapless::io
