#include "mapless/recording/mcap_reader.h"

#include <cerrno>
#include <cstring>

#include "mapless/core/check.h"
#include "mapless/core/warning.h"
#include "mapless/io/atomic_file.h"
#include "mapless/recording/compression.h"

namespace mapless::recording {

McapReader::McapReader(const std::string& path)
    : path_(path), file_(std::make_unique<io::MappedFile>(path)) {
  bytes_ = file_->bytes();
  CheckMagic();
}

void McapReader::ThrowIfChanged() const {
  if (file_ && file_->changed())
    throw InputError(path_ +
                     ": the file changed while it was read (cut, or another file copied over "
                     "it); stopped there");
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

McapReader::~McapReader() = default;

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
      const bool more = cursor.Next(&op, &body);
      ThrowIfChanged();
      if (!more) break;
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
        ThrowIfChanged();
        continue;
      }
      fn(op, body, offset);
      if (op == static_cast<std::uint8_t>(McapOp::kFooter)) {
        footer = true;
        break;
      }
    }
  } catch (const InputError& e) {
    ThrowIfChanged();  // zeros read after a cut: that is the error to name
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
      const bool more = outer_.Next(&op, &body);
      reader_.ThrowIfChanged();
      if (!more) {
        done_ = true;
        // Killed before it closed: every whole record up to the cut was read; said, since the
        // frames after it are missing.
        reader_.set_cut(true);
        Warn(reader_.path() + ": ends at byte " + std::to_string(outer_.offset()) +
             " inside a record, before its footer (the recording's writer stopped, or the file "
             "was cut): every frame before was played");
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
        reader_.ThrowIfChanged();  // the chunk was read whole before it was cut
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
    if (std::string(e.what()).rfind(reader_.path() + ": ", 0) == 0) throw;
    reader_.ThrowIfChanged();  // zeros read after a cut: that is the error to name
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
