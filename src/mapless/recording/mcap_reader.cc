#include "mapless/recording/mcap_reader.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/recording/compression.h"

namespace mapless::recording {

McapReader::McapReader(const std::string& path) : path_(path) {
  std::uint64_t size = 0;
  const int fd = io::OpenRegularFile(path, &size);
  map_size_ = static_cast<std::size_t>(size);
  if (map_size_ > 0) {
    map_ = ::mmap(nullptr, map_size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (map_ == MAP_FAILED) {
      map_ = nullptr;
      const std::string why = std::strerror(errno);
      ::close(fd);
      throw InputError(path + ": cannot map file: " + why);
    }
    bytes_ = std::string_view(static_cast<const char*>(map_), map_size_);
  }
  ::close(fd);
  try {
    CheckMagic();
  } catch (...) {
    if (map_) ::munmap(map_, map_size_);
    throw;
  }
}

std::unique_ptr<McapReader> McapReader::FromBytes(std::string bytes, const std::string& name) {
  std::unique_ptr<McapReader> r(new McapReader());
  r->path_ = name;
  r->owned_ = std::move(bytes);
  r->bytes_ = r->owned_;
  r->CheckMagic();
  return r;
}

void McapReader::CheckMagic() {
  if (bytes_.size() < kMcapMagic.size() || bytes_.substr(0, kMcapMagic.size()) != kMcapMagic)
    throw InputError(path_ + ": not an MCAP file (it does not start with the MCAP magic)");
}

McapReader::~McapReader() {
  if (map_) ::munmap(map_, map_size_);
}

void McapReader::Walk(const RecordFn& fn, std::uint64_t skip_chunks_before_ns) {
  cut_ = false;
  const std::string_view rest = bytes_.substr(kMcapMagic.size());
  McapRecordCursor cursor(rest, kMcapMagic.size(), /*tolerate_cut=*/true);
  std::uint8_t op = 0;
  std::string_view body;
  bool footer = false;
  try {
    while (true) {
      const std::uint64_t offset = cursor.offset();
      if (!cursor.Next(&op, &body)) break;
      if (op == static_cast<std::uint8_t>(McapOp::kChunk)) {
        const McapChunk chunk = ParseMcapChunk(body);
        if (chunk.message_end_time < skip_chunks_before_ns) continue;
        const std::string what = "chunk at byte " + std::to_string(offset);
        const std::string records =
            Decompress(chunk.compression, chunk.records, chunk.uncompressed_size, what);
        if (chunk.uncompressed_crc != 0)
          MAPLESS_CHECK(McapCrc32(records) == chunk.uncompressed_crc,
                        what << ": its records do not match their CRC");
        McapRecordCursor inner(records, 0);
        std::uint8_t inner_op = 0;
        std::string_view inner_body;
        while (inner.Next(&inner_op, &inner_body)) fn(inner_op, inner_body, offset);
        continue;
      }
      fn(op, body, offset);
      if (op == static_cast<std::uint8_t>(McapOp::kFooter)) {
        footer = true;
        break;
      }
    }
  } catch (const InputError& e) {
    throw InputError(path_ + ": " + e.what());
  }
  if (!footer) {
    cut_ = true;  // killed before it closed: every whole record up to the cut was read
    return;
  }
  const std::string_view tail = rest.substr(cursor.offset() - kMcapMagic.size());
  MAPLESS_CHECK(tail == kMcapMagic, path_ << ": " << tail.size()
                                          << " bytes after the footer are not the closing magic");
}

void McapReader::ForEachRecord(const RecordFn& fn) { Walk(fn, 0); }

void McapReader::ForEachMessage(const MessageFn& fn, std::uint64_t start_ns) {
  McapMessageStream stream(*this, start_ns);
  McapMessageStream::Item item;
  while (stream.Next(&item)) fn(*item.channel, item.schema, item.message);
}

McapMessageStream::McapMessageStream(McapReader& reader, std::uint64_t start_ns)
    : reader_(reader),
      start_ns_(start_ns),
      outer_(reader.bytes().substr(kMcapMagic.size()), kMcapMagic.size(), /*tolerate_cut=*/true) {
  reader_.set_cut(false);
}

bool McapMessageStream::Next(Item* item) {
  try {
    while (true) {
      std::uint8_t op = 0;
      std::string_view body;
      if (inner_) {
        if (inner_->Next(&op, &body)) {
          if (Handle(op, body, chunk_offset_, item)) return true;
          continue;
        }
        inner_.reset();
      }
      if (done_) return false;
      const std::uint64_t offset = outer_.offset();
      if (!outer_.Next(&op, &body)) {
        done_ = true;
        reader_.set_cut(
            true);  // killed before it closed: every whole record up to the cut was read
        return false;
      }
      if (op == static_cast<std::uint8_t>(McapOp::kChunk)) {
        const McapChunk chunk = ParseMcapChunk(body);
        if (chunk.message_end_time < start_ns_) continue;
        const std::string what = "chunk at byte " + std::to_string(offset);
        chunk_records_ =
            Decompress(chunk.compression, chunk.records, chunk.uncompressed_size, what);
        if (chunk.uncompressed_crc != 0)
          MAPLESS_CHECK(McapCrc32(chunk_records_) == chunk.uncompressed_crc,
                        what << ": its records do not match their CRC");
        inner_ = std::make_unique<McapRecordCursor>(chunk_records_, 0);
        chunk_offset_ = offset;
        continue;
      }
      if (op == static_cast<std::uint8_t>(McapOp::kFooter)) {
        done_ = true;
        const std::string_view rest = reader_.bytes().substr(kMcapMagic.size());
        const std::string_view tail = rest.substr(outer_.offset() - kMcapMagic.size());
        MAPLESS_CHECK(tail == kMcapMagic,
                      tail.size() << " bytes after the footer are not the closing magic");
        return false;
      }
      if (Handle(op, body, offset, item)) return true;
    }
  } catch (const InputError& e) {
    done_ = true;
    inner_.reset();
    throw InputError(reader_.path() + ": " + e.what());
  }
}

bool McapMessageStream::Handle(std::uint8_t op, std::string_view body, std::uint64_t offset,
                               Item* item) {
  if (op == static_cast<std::uint8_t>(McapOp::kSchema)) {
    McapSchema s = ParseMcapSchema(body);
    MAPLESS_CHECK(s.id != 0, "Schema record at byte " << offset << ": id 0 is reserved");
    schemas_[s.id] = std::move(s);
  } else if (op == static_cast<std::uint8_t>(McapOp::kChannel)) {
    McapChannel c = ParseMcapChannel(body);
    MAPLESS_CHECK(c.schema_id == 0 || schemas_.count(c.schema_id),
                  "Channel " << c.id << " at byte " << offset << ": schema " << c.schema_id
                             << " was not defined before it");
    channels_[c.id] = std::move(c);
  } else if (op == static_cast<std::uint8_t>(McapOp::kMessage)) {
    McapMessage m = ParseMcapMessage(body);
    if (m.log_time < start_ns_) return false;
    const auto c = channels_.find(m.channel_id);
    MAPLESS_CHECK(c != channels_.end(), "Message at byte " << offset << ": channel " << m.channel_id
                                                           << " was not defined before it");
    const auto sc = schemas_.find(c->second.schema_id);
    item->channel = &c->second;
    item->schema = sc == schemas_.end() ? nullptr : &sc->second;
    item->message = std::move(m);
    return true;
  }
  return false;
}

}  // namespace mapless::recording
