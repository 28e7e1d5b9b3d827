// A file mapped read-only into memory that survives being cut while it is read.
//
// A mapped file that another program truncates (a new recording copied over the one playing)
// makes every read past its new end a SIGBUS, which would kill the process without a word. Each
// MappedFile registers its range with a SIGBUS handler (installed once): a fault inside a
// registered range puts zero pages over the rest of the range and marks it changed, and the
// read goes on with zeros. The reader checks changed() after each record and stops with an
// error naming the file; a fault anywhere else keeps the default action.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace mapless::io {

class MappedFile {
 public:
  // Throws InputError naming `path` when it cannot be opened (a regular file only) or mapped.
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view bytes() const { return bytes_; }
  // True once a read faulted because the file shrank under the mapping: bytes() from the fault on
  // read as zeros.
  bool changed() const;

 private:
  std::string_view bytes_;
  void* map_ = nullptr;
  std::size_t size_ = 0;
  int slot_ = -1;  // in the handler's table (-1: not registered, e.g. an empty file)
};

}  // namespace mapless::io
