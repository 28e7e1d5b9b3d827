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
  enum class Mode {
    kInPlace,  // create (or truncate) `path` and append to it
    // Append to `path`.partial and rename it over `path` on Close() or destruction: a file that was
    // at `path` stays whole until the new one is done; a process killed mid-run leaves the records
    // it finished in `path`.partial. For files the user names (decision logs).
    kReplaceAtClose,
  };
  // Throws InputError naming the file when it cannot be written.
  explicit JournalFile(const std::string& path, Mode mode = Mode::kInPlace);
  ~JournalFile();
  JournalFile(const JournalFile&) = delete;
  JournalFile& operator=(const JournalFile&) = delete;

  // Appends one record; a trailing newline is added when missing. Throws InputError on failure.
  void Append(std::string_view record);
  // Flushes the records to the disk (fsync): for power loss; a killed process loses nothing
  // appended without it.
  void Sync();
  // Syncs, closes and (kReplaceAtClose) puts the file in place. Throws InputError on failure.
  void Close();
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string write_path_;
  int fd_ = -1;
};

}  // namespace mapless::io
