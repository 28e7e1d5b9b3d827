#include "mapless/io/journal.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::io {

JournalFile::JournalFile(const std::string& path, Mode mode) : path_(path), write_path_(path) {
  // A device or a pipe (/dev/stdout) is appended to directly: never replaced by a file.
  if (mode == Mode::kReplaceAtClose && KindOfOutput(path) == OutputKind::kNewOrRegular) {
    write_path_ = path + ".partial";
  }
  // Opened without truncating, locked, then emptied: a second run writing the same file is
  // refused before it destroys what the first has written.
  fd_ = ::open(write_path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
  const bool regular = KindOfOutput(write_path_) == OutputKind::kNewOrRegular;
  if (regular && ::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd_);
    fd_ = -1;
    throw InputError(path + ": another mapless process is writing this file (locked)");
  }
  if (regular && ::ftruncate(fd_, 0) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    fd_ = -1;
    throw InputError(path + ": cannot write: " + why);
  }
}

JournalFile::~JournalFile() {
  try {
    Close();
  } catch (const InputError&) {
    // Destruction during unwinding: the records written so far stay where they are.
  }
}

void JournalFile::Close() {
  if (fd_ < 0) return;
  // fsync on a pipe or a device says EINVAL: there is nothing to flush to a disk.
  const bool synced = ::fsync(fd_) == 0 || errno == EINVAL;
  ::close(fd_);
  fd_ = -1;
  if (!synced) throw InputError(path_ + ": cannot write: " + std::strerror(errno));
  if (write_path_ != path_ && std::rename(write_path_.c_str(), path_.c_str()) != 0) {
    throw InputError(path_ + ": cannot write: " + std::strerror(errno));
  }
}

void JournalFile::Append(std::string_view record) {
  std::string line(record);
  if (line.empty() || line.back() != '\n') line.push_back('\n');
  // One write for the whole line; a short write (a full disk) is finished, or reported.
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(path_ + ": cannot write: " + std::strerror(errno));
    }
    done += static_cast<std::size_t>(n);
  }
}

void JournalFile::Sync() {
  if (::fsync(fd_) != 0 && errno != EINVAL) {
    throw InputError(path_ + ": cannot write: " + std::strerror(errno));
  }
}

}  // namespace mapless::io
