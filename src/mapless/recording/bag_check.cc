#include "mapless/recording/bag_check.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <set>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::recording {
namespace {

using Fields = std::map<std::string, std::string>;

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint64_t kMagicBytes = sizeof(kMagic) - 1;
constexpr std::uint32_t kMaxHeaderBytes = 1u << 20;  // a record's header (not its data)
// The ops of bag format 2.0.
constexpr std::uint8_t kOpMessageDefinition = 0x01, kOpMessageData = 0x02, kOpBagHeader = 0x03,
                       kOpIndexData = 0x04, kOpChunk = 0x05, kOpChunkInfo = 0x06,
                       kOpConnection = 0x07;

struct Record {
  std::uint64_t pos = 0;  // of its header length
  std::uint8_t op = 0;
  Fields fields;
  std::uint64_t data_pos = 0;
  std::uint32_t data_len = 0;
  std::uint64_t end() const { return data_pos + data_len; }
};

std::uint32_t U32(const char* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);  // bags are little-endian, as is every machine mapless builds for
  return v;
}

// A ROS 1 header: fields of a 4-byte length and "name=value", exactly filling `len` bytes (as
// ros::Header::parse needs: it reads a length without checking that four bytes remain).
bool ParseFields(const char* p, std::uint64_t len, Fields* out, std::string* why) {
  out->clear();
  std::uint64_t at = 0;
  while (at < len) {
    if (len - at < 4) return *why = "a header field's length is cut", false;
    const std::uint32_t n = U32(p + at);
    at += 4;
    if (n > len - at) return *why = "a header field runs past its header", false;
    const std::string field(p + at, n);
    at += n;
    const auto eq = field.find('=');
    if (eq == std::string::npos) return *why = "a header field without '='", false;
    (*out)[field.substr(0, eq)] = field.substr(eq + 1);
  }
  return true;
}

class BagChecker {
 public:
  explicit BagChecker(const std::string& path) : path_(path) {
    fd_ = io::OpenRegularFile(path, &size_);
  }
  ~BagChecker() { ::close(fd_); }
  BagChecker(const BagChecker&) = delete;
  BagChecker& operator=(const BagChecker&) = delete;

  void Run() {
    std::string magic(kMagicBytes, '\0');
    if (size_ < kMagicBytes || !Read(0, magic.data(), kMagicBytes) || magic != kMagic)
      Fail(0, "not a ROS 1 bag of format 2.0 (no \"#ROSBAG V2.0\" line)");
    WalkTopLevel();
    const Record& header = records_.front();
    if (header.op != kOpBagHeader) Fail(header.pos, "the first record is not the bag header");
    if (header.fields.count("encryptor") && header.fields.at("encryptor") != "rosbag/NoEncryptor")
      Fail(header.pos, "an encrypted bag (encryptor " + header.fields.at("encryptor") + ")");
    const auto index_pos = Field<std::uint64_t>(header, "index_pos");
    const auto conn_count = Field<std::uint32_t>(header, "conn_count");
    const auto chunk_count = Field<std::uint32_t>(header, "chunk_count");
    const auto at = starts_.find(index_pos);
    if (at == starts_.end() && index_pos != size_)  // at the end: an empty index
      Fail(header.pos, "the index position " + std::to_string(index_pos) +
                           " is not the start of a record (an unindexed bag: rosbag reindex)");
    std::size_t i = at == starts_.end() ? records_.size() : at->second;
    if (records_.size() - i < std::uint64_t{conn_count} + chunk_count)
      Fail(index_pos, "fewer index records than the bag header's counts");
    for (std::uint32_t k = 0; k < conn_count; ++k) Connection(records_[i++]);
    for (std::uint32_t k = 0; k < chunk_count; ++k) ChunkInfo(records_[i++]);
  }

 private:
  [[noreturn]] void Fail(std::uint64_t pos, const std::string& what) const {
    throw InputError(path_ + ": not a readable ROS 1 bag: at byte " + std::to_string(pos) + ": " +
                     what);
  }

  bool Read(std::uint64_t pos, char* out, std::uint64_t n) const {
    if (pos > size_ || n > size_ - pos) return false;
    while (n > 0) {
      const ssize_t got = ::pread(fd_, out, n, static_cast<off_t>(pos));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return false;
      out += got;
      pos += static_cast<std::uint64_t>(got);
      n -= static_cast<std::uint64_t>(got);
    }
    return true;
  }

  template <typename T>
  T Field(const Record& r, const char* name) const {
    const auto it = r.fields.find(name);
    if (it == r.fields.end() || it->second.size() != sizeof(T))
      Fail(r.pos, std::string("no ") + std::to_string(sizeof(T)) + "-byte '" + name + "' field");
    T v;
    std::memcpy(&v, it->second.data(), sizeof(T));
    return v;
  }

  // A record's header and data length, read from `bytes` (a chunk) or from the file.
  Record ParseRecord(std::uint64_t pos, std::uint64_t limit, const std::string* bytes) const {
    Record r;
    r.pos = pos;
    char len[4];
    const auto get = [&](std::uint64_t p, char* out, std::uint64_t n) {
      if (p > limit || n > limit - p) return false;
      if (!bytes) return Read(p, out, n);
      std::memcpy(out, bytes->data() + p, n);
      return true;
    };
    if (!get(pos, len, 4)) Fail(pos, "a record's header length runs past the end");
    const std::uint32_t header_len = U32(len);
    if (header_len > kMaxHeaderBytes)
      Fail(pos, "a record header of " + std::to_string(header_len) + " bytes (at most " +
                    std::to_string(kMaxHeaderBytes) + ")");
    std::string header(header_len, '\0');
    if (!get(pos + 4, header.data(), header_len) || !get(pos + 4 + header_len, len, 4))
      Fail(pos, "a record header of " + std::to_string(header_len) + " bytes runs past the end");
    std::string why;
    if (!ParseFields(header.data(), header_len, &r.fields, &why)) Fail(pos, why);
    r.data_pos = pos + 8 + header_len;
    r.data_len = U32(len);
    if (r.data_len > limit - r.data_pos)
      Fail(pos, "a record's data of " + std::to_string(r.data_len) + " bytes runs past the end");
    r.op = Field<std::uint8_t>(r, "op");
    return r;
  }

  void WalkTopLevel() {
    for (std::uint64_t pos = kMagicBytes; pos < size_;) {
      records_.push_back(ParseRecord(pos, size_, nullptr));
      starts_[pos] = records_.size() - 1;
      pos = records_.back().end();
    }
    if (records_.empty()) Fail(kMagicBytes, "no records");
  }

  void Connection(const Record& r) {
    if (r.op != kOpConnection) Fail(r.pos, "expected a connection record");
    const auto conn = Field<std::uint32_t>(r, "conn");
    if (!r.fields.count("topic") || r.fields.at("topic").empty()) Fail(r.pos, "no topic");
    std::string data(r.data_len, '\0');
    Fields header;
    std::string why;
    if (!Read(r.data_pos, data.data(), r.data_len) ||
        !ParseFields(data.data(), r.data_len, &header, &why))
      Fail(r.pos, "a connection header: " + why);
    if (!header.count("type") || header.at("type").empty()) Fail(r.pos, "a connection's type");
    connections_.insert(conn);
  }

  void ChunkInfo(const Record& r) {
    if (r.op != kOpChunkInfo) Fail(r.pos, "expected a chunk-info record");
    if (Field<std::uint32_t>(r, "ver") != 1) Fail(r.pos, "a chunk-info version other than 1");
    const auto chunk_pos = Field<std::uint64_t>(r, "chunk_pos");
    Field<std::uint64_t>(r, "start_time");
    Field<std::uint64_t>(r, "end_time");
    const auto count = Field<std::uint32_t>(r, "count");
    if (std::uint64_t{count} * 8 != r.data_len)
      Fail(r.pos, "a chunk-info of " + std::to_string(count) + " connections in " +
                      std::to_string(r.data_len) + " bytes");
    std::string data(r.data_len, '\0');
    if (!Read(r.data_pos, data.data(), r.data_len)) Fail(r.pos, "a chunk-info's data");
    std::set<std::uint32_t> conns;
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint32_t conn = U32(data.data() + 8 * k);
      if (!connections_.count(conn)) Fail(r.pos, "a chunk-info names an unknown connection");
      conns.insert(conn);
    }
    const auto at = starts_.find(chunk_pos);
    if (at == starts_.end() || records_[at->second].op != kOpChunk)
      Fail(r.pos, "a chunk-info points at " + std::to_string(chunk_pos) + ", not at a chunk");
    Chunk(at->second, conns.size());
  }

  // The chunk record at records_[i], then the `indexes` index records that follow it.
  void Chunk(std::size_t i, std::size_t indexes) {
    const Record& r = records_[i];
    const std::string chunk = Decompress(r);
    // The records inside the chunk, and whether each leads to a message (rosbag skips connection
    // records from an index offset until it finds one).
    std::map<std::uint32_t, std::size_t> starts;
    std::vector<Record> inner;
    for (std::uint64_t pos = 0; pos < chunk.size();) {
      Record m = ParseRecord(pos, chunk.size(), &chunk);
      m.pos = r.data_pos;  // errors inside a chunk name the chunk's data
      if (m.op == kOpMessageData) {
        if (!connections_.count(Field<std::uint32_t>(m, "conn")))
          Fail(r.pos, "a message of an unknown connection in the chunk");
        Field<std::uint64_t>(m, "time");
      } else if (m.op != kOpConnection && m.op != kOpMessageDefinition) {
        Fail(r.pos, "a record of op " + std::to_string(m.op) + " in the chunk");
      }
      starts[static_cast<std::uint32_t>(pos)] = inner.size();
      pos = m.end();
      inner.push_back(std::move(m));
    }
    std::vector<bool> leads(inner.size() + 1, false);
    for (std::size_t k = inner.size(); k-- > 0;)
      leads[k] = inner[k].op == kOpMessageData || leads[k + 1];
    if (records_.size() - i - 1 < indexes) Fail(r.pos, "a chunk without its index records");
    for (std::size_t k = 1; k <= indexes; ++k) {
      const Record& index = records_[i + k];
      if (index.op != kOpIndexData) Fail(index.pos, "expected an index record after a chunk");
      if (Field<std::uint32_t>(index, "ver") != 1) Fail(index.pos, "an index version other than 1");
      if (!connections_.count(Field<std::uint32_t>(index, "conn")))
        Fail(index.pos, "an index of an unknown connection");
      const auto count = Field<std::uint32_t>(index, "count");
      if (std::uint64_t{count} * 12 != index.data_len)
        Fail(index.pos, "an index of " + std::to_string(count) + " entries in " +
                            std::to_string(index.data_len) + " bytes");
      std::string data(index.data_len, '\0');
      if (!Read(index.data_pos, data.data(), index.data_len)) Fail(index.pos, "an index's data");
      for (std::uint32_t e = 0; e < count; ++e) {
        const auto at = starts.find(U32(data.data() + 12 * e + 8));
        if (at == starts.end() || !leads[at->second])
          Fail(index.pos, "an index entry that does not point at a message in its chunk");
      }
    }
  }

  std::string Decompress(const Record& r) const {
    const auto it = r.fields.find("compression");
    const std::string compression = it == r.fields.end() ? "" : it->second;
    const auto size = Field<std::uint32_t>(r, "size");
    if (size > kMaxBagChunkBytes)
      Fail(r.pos, "a chunk of " + std::to_string(size) + " bytes (at most " +
                      std::to_string(kMaxBagChunkBytes) + ")");
    if (compression == "none" && r.data_len != size)
      Fail(r.pos, "an uncompressed chunk whose size is not its length");
    if (r.data_len > 2ull * kMaxBagChunkBytes) Fail(r.pos, "a chunk's data is too long");
    std::string data(r.data_len, '\0');
    if (!Read(r.data_pos, data.data(), r.data_len)) Fail(r.pos, "a chunk's data");
    if (compression == "none") return data;
    std::string out(size, '\0');
    unsigned int got = size;
    if (compression == "lz4") {
      if (roslz4_buffToBuffDecompress(data.data(), r.data_len, out.data(), &got) != 0 ||
          got != size)
        Fail(r.pos, "an lz4 chunk that does not decompress to its size");
    } else if (compression == "bz2") {
      if (BZ2_bzBuffToBuffDecompress(out.data(), &got, data.data(), r.data_len, 0, 0) != BZ_OK ||
          got != size)
        Fail(r.pos, "a bz2 chunk that does not decompress to its size");
    } else {
      Fail(r.pos, "a chunk compressed with '" + compression + "' (none, bz2 or lz4)");
    }
    return out;
  }

  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::vector<Record> records_;                  // top level, in file order
  std::map<std::uint64_t, std::size_t> starts_;  // record position -> index in records_
  std::set<std::uint32_t> connections_;
};

}  // namespace

void CheckBagStructure(const std::string& path) { BagChecker(path).Run(); }

}  // namespace mapless::recording
