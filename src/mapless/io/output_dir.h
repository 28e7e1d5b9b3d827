// Where a run writes a directory of results (a route, a recording) without losing what was there:
//
// - a new or empty directory is written in place, so that a run killed at any moment keeps every
//   file it finished (the route store and the journals are crash-safe on their own);
// - a directory that already holds something is replaced only when the caller was asked to
//   (`--overwrite`), and then as a whole: the run writes into a staging directory beside it and
//   Commit() swaps the two when the run is done. A run that fails or is interrupted before
//   Commit() leaves the old directory as it was and removes its staging directory;
// - a directory is locked (flock on DIR/.mapless.lock) while a run writes it: a second process
//   writing the same directory is refused, naming the directory.
#pragma once

#include <memory>
#include <string>

namespace mapless::io {

// An exclusive advisory lock on a directory, held while the object lives.
class DirectoryLock {
 public:
  // Throws InputError naming `dir` when another process holds the lock. `dir` must exist.
  explicit DirectoryLock(const std::string& dir);
  ~DirectoryLock();
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

 private:
  int fd_ = -1;
};

// True when `dir` does not exist or is an empty directory.
bool IsEmptyOrMissing(const std::string& dir);

class OutputDirectory {
 public:
  // `target` must be new, empty, or `replace` must be set and `target` must hold what this kind of
  // run writes: the file `marker` (relative to `target`, e.g. "manifest.json" for a route), so
  // that no other directory (a home directory, a folder of photos) is ever replaced. `what` names
  // the content in errors ("route", "recording"). Throws InputError naming `target` otherwise, or
  // when it is a file.
  OutputDirectory(std::string target, bool replace, std::string what, std::string marker);
  ~OutputDirectory();  // not committed: removes the staging directory (never the target)
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  // Where to write: the target itself, or the staging directory when replacing.
  const std::string& path() const { return path_; }
  const std::string& target() const { return target_; }
  bool staged() const { return path_ != target_; }
  // Puts the written directory in place (a no-op when written in place). The old one is renamed
  // aside first and removed after the swap, so that a kill leaves one of the two whole.
  void Commit();
  // Undoes a run that failed before it made anything usable: written in place, the directory is
  // emptied again (removed when the run created it); staged, the staging directory goes (as on
  // destruction). The target is never touched when it held something before.
  void Discard();

 private:
  std::string target_;
  std::string path_;
  bool committed_ = false;
  bool created_ = false;  // the target did not exist before
  std::unique_ptr<DirectoryLock> lock_;
};

}  // namespace mapless::io
