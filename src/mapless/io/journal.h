// Append-only record files for what is recorded while a run goes on (decision logs, frame lists,
// trajectories). Each record is one line, written with a single write(2) to a file opened with
// O_APPEND, so a process killed at any moment leaves every record it had finished, whole, and
// nothing half-written (files written once at the end use WriteFileAtomic instead).
#pragma once

#include <string>
#include <string_view>

namespace mapless::io {

class JournalFile {
 public:
  // Creates (or truncates) `path`; throws InputError naming it when it cannot be written.
  explicit JournalFile(const std::string& path);
  ~JournalFile();
  JournalFile(const JournalFile&) = delete;
  JournalFile& operator=(const JournalFile&) = delete;

  // Appends one record; a trailing newline is added when missing. Throws InputError on failure.
  void Append(std::string_view record);
  // Flushes the records to the disk (fsync): for power loss; a killed process loses nothing
  // appended without it.
  void Sync();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace mapless::io
