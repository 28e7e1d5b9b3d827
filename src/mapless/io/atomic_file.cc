#include "mapless/io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/lazy_libraries.h"

namespace mapless::io {

namespace {

// Writes all of `bytes` to `fd`; false on an error (errno set).
bool WriteAll(int fd, std::string_view bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

OutputKind KindOfOutput(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return OutputKind::kNewOrRegular;  // follows links
  if (S_ISDIR(st.st_mode)) throw InputError(path + ": is a directory; name a file");
  return S_ISREG(st.st_mode) ? OutputKind::kNewOrRegular : OutputKind::kStream;
}

void WriteFileAtomic(const std::string& path, std::string_view bytes, bool sync) {
  if (KindOfOutput(path) == OutputKind::kStream) {
    // A device or a pipe (/dev/stdout, /dev/null): written to, never replaced by a file.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0 || !WriteAll(fd, bytes)) {
      const std::string why = std::strerror(errno);
      if (fd >= 0) ::close(fd);
      throw InputError(path + ": cannot write: " + why);
    }
    ::close(fd);
    return;
  }
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
  if (!WriteAll(fd, bytes)) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    ::unlink(tmp.c_str());
    throw InputError(path + ": cannot write: " + why);
  }
  if ((sync && ::fsync(fd) != 0) || ::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw InputError(path + ": cannot write: " + why);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw InputError(path + ": cannot write: " + why);
  }
}

void WriteNewFile(const std::string& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0 || !WriteAll(fd, bytes) || ::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    throw InputError(path + ": cannot write: " + why);
  }
}

void SyncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw InputError(path + ": cannot flush to disk: " + why);
  }
  ::close(fd);
}

std::string EncodeImage(const cv::Mat& image, const std::string& ext, const std::string& name,
                        const std::vector<int>& params) {
  std::vector<uchar> buffer;
  bool ok = false;
  try {
    ok = lazy::ImEncode(ext, image, &buffer, params);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw InputError(name + ": cannot encode an image as '" + ext + "'");
  return std::string(reinterpret_cast<const char*>(buffer.data()), buffer.size());
}

void SyncFiles(const std::vector<std::string>& paths) {
  if (paths.size() <= 4) {
    for (const std::string& path : paths) SyncFile(path);
    return;
  }
  const int fd = ::open(paths.front().c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::syncfs(fd) != 0) {
    const std::string why = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw InputError(paths.front() + ": cannot flush to disk: " + why);
  }
  ::close(fd);
}

void WriteImageAtomic(const std::string& path, const cv::Mat& image) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext.empty()) throw InputError(path + ": image file name needs an extension such as .png");
  WriteFileAtomic(path, EncodeImage(image, ext, path));
}

int OpenRegularFile(const std::string& path, std::uint64_t* size) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; regular files ignore it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) throw InputError(path + ": cannot open file: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw InputError(path + ": not a regular file (a directory, a device or a pipe)");
  }
  *size = static_cast<std::uint64_t>(st.st_size);
  return fd;
}

std::string ReadFile(const std::string& path, std::size_t max_bytes) {
  std::uint64_t size = 0;
  const int fd = OpenRegularFile(path, &size);
  if (size > max_bytes) {
    ::close(fd);
    throw InputError(path + ": " + std::to_string(size) +
                     " bytes; the limit for this kind "
                     "of file is " +
                     std::to_string(max_bytes) + " bytes");
  }
  // Read at most max_bytes + 1: a file that grows while it is read is still caught.
  std::string bytes(static_cast<std::size_t>(size), '\0');
  std::size_t done = 0;
  while (true) {
    if (done == bytes.size()) {
      if (bytes.size() > max_bytes) break;
      bytes.resize(std::min(max_bytes + 1, bytes.size() + 65536));
    }
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const std::string why = std::strerror(errno);
      ::close(fd);
      throw InputError(path + ": cannot read: " + why);
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (done > max_bytes) {
    throw InputError(path + ": more than " + std::to_string(max_bytes) +
                     " bytes; the limit for this kind of file");
  }
  bytes.resize(done);
  return bytes;
}

void MakeDirectories(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) throw InputError(path + ": cannot create directory: " + ec.message());
}

}  // namespace mapless::io
