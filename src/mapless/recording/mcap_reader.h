// Reading MCAP files (mcap_format.h): every record in file order, with chunks opened (the
// conformance "streamed" order), or the messages with their channels and schemas. A file cut short
// (a recording killed before it closed) is read up to its last whole record, and cut() says so.
// The file is mapped read-only (io::MappedFile: a file cut while it is read is an error naming it,
// not a SIGBUS); nothing in it is trusted (bounded sizes, checked CRCs).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include "mapless/io/mapped_file.h"
#include "mapless/recording/mcap_format.h"

namespace mapless::recording {

class McapReader {
 public:
  // Throws InputError naming `path` when it cannot be read or does not start with the magic.
  explicit McapReader(const std::string& path);
  // Bytes held in memory (tests, fuzzing); `name` stands for the path in errors.
  static std::unique_ptr<McapReader> FromBytes(std::string bytes, const std::string& name);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  // Every record from the header to the footer, in file order; a chunk's records in its place
  // (the chunk itself is not passed). `offset`: the record's byte offset in the file (for records
  // inside a chunk, the chunk's). Throws InputError on a malformed record, a bad CRC or data after
  // the footer that is not the closing magic.
  using RecordFn =
      std::function<void(std::uint8_t op, std::string_view body, std::uint64_t offset)>;
  void ForEachRecord(const RecordFn& fn);

  // The messages in file order, from log time `start_ns` on (chunks that end before it are
  // skipped without opening them), each with its channel and schema (nullptr for schema id 0).
  using MessageFn = std::function<void(const McapChannel&, const McapSchema*, const McapMessage&)>;
  void ForEachMessage(const MessageFn& fn, std::uint64_t start_ns = 0);

  bool cut() const { return cut_; }  // the file ended before its footer (after a read)
  void set_cut(bool cut) { cut_ = cut; }
  const std::string& path() const { return path_; }
  std::string_view bytes() const { return bytes_; }
  // Throws InputError when the file shrank under the mapping while it was read (another file
  // copied over it): what was read from the cut on is zeros, not the recording.
  void ThrowIfChanged() const;

 private:
  McapReader() = default;
  void CheckMagic();
  void Walk(const RecordFn& fn, std::uint64_t skip_chunks_before_ns);

  std::string path_;
  std::string_view bytes_;
  std::string owned_;  // FromBytes
  std::unique_ptr<io::MappedFile> file_;
  bool cut_ = false;
};

// The messages of a reader one at a time, in file order, with their channels and schemas (what
// ForEachMessage does, pulled: a recording played as a camera). A chunk is opened when its first
// message is asked for. Throws InputError as ForEachRecord does; a cut file ends at its cut.
class McapMessageStream {
 public:
  // `reader` must outlive the stream. Messages before log time `start_ns` are skipped (whole
  // chunks that end before it are not opened).
  explicit McapMessageStream(McapReader& reader, std::uint64_t start_ns = 0);

  struct Item {
    const McapChannel* channel = nullptr;
    const McapSchema* schema = nullptr;  // nullptr for schema id 0
    McapMessage message;
  };
  // The next message; false at the end of the file or at its cut.
  bool Next(Item* item);

 private:
  // A record outside a chunk or inside one; true when it was a message to return.
  bool Handle(std::uint8_t op, std::string_view body, std::uint64_t offset, Item* item);

  McapReader& reader_;
  std::uint64_t start_ns_;
  McapRecordCursor outer_;
  std::string chunk_records_;
  std::unique_ptr<McapRecordCursor> inner_;
  std::uint64_t chunk_offset_ = 0;
  bool done_ = false;
  std::map<std::uint16_t, McapSchema> schemas_;
  std::map<std::uint16_t, McapChannel> channels_;
};

}  // namespace mapless::recording
