#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/recording/compression.h"
#include "mapless/recording/mcap_reader.h"
#include "mapless/recording/mcap_writer.h"

namespace mapless::recording {
namespace {

namespace fs = std::filesystem;

std::string FreshPath(const std::string& name) {
  const std::string path = ::testing::TempDir() + "mapless_mcap_" + name + ".mcap";
  fs::remove(path);
  return path;
}

struct Written {
  std::string topic;
  std::uint64_t log_time;
  std::string data;
};

// Two channels, 300 messages of 0-2 KB over 3 s of log time (so several chunks of 1 s).
std::vector<Written> WriteRun(const std::string& path, const McapWriterOptions& options,
                              bool close) {
  McapWriter w(path, options);
  const std::uint16_t twist = w.AddSchema("geometry_msgs/msg/Twist", "ros2msg", "Vector3 linear");
  const std::uint16_t cmd = w.AddChannel(twist, "/cmd_vel", "cdr", {{"offered_qos_profiles", ""}});
  const std::uint16_t decision = w.AddChannel(0, "/mapless/decision", "json");
  std::vector<Written> out;
  for (int i = 0; i < 300; ++i) {
    const std::uint64_t t = 1'000'000'000ull + 10'000'000ull * static_cast<std::uint64_t>(i);
    std::string data(static_cast<std::size_t>((i * 37) % 2048), static_cast<char>('a' + i % 26));
    const bool is_cmd = i % 3 != 0;
    w.Write(is_cmd ? cmd : decision, t, t, data);
    out.push_back({is_cmd ? "/cmd_vel" : "/mapless/decision", t, data});
  }
  if (close) w.Close();
  return out;
}

std::vector<Written> ReadRun(McapReader& r) {
  std::vector<Written> out;
  r.ForEachMessage([&](const McapChannel& c, const McapSchema* s, const McapMessage& m) {
    if (c.topic == "/cmd_vel") {
      EXPECT_NE(s, nullptr);
      if (s) {
        EXPECT_EQ(s->name, "geometry_msgs/msg/Twist");
      }
    } else {
      EXPECT_EQ(s, nullptr);
    }
    out.push_back({c.topic, m.log_time, m.data});
  });
  return out;
}

bool operator==(const Written& a, const Written& b) {
  return a.topic == b.topic && a.log_time == b.log_time && a.data == b.data;
}

TEST(Mcap, WritesAndReadsBackEveryMessageWithEachCompression) {
  for (const std::string compression : {"", "zstd", "lz4"}) {
    SCOPED_TRACE("compression '" + compression + "'");
    const std::string path = FreshPath("round_trip_" + compression);
    McapWriterOptions options;
    options.compression = compression;
    const std::vector<Written> written = WriteRun(path, options, true);
    McapReader reader(path);
    EXPECT_EQ(ReadRun(reader), written);
    EXPECT_FALSE(reader.cut());
    // The summary: statistics and one chunk index per chunk, found through the summary offsets.
    std::size_t chunks = 0, indexes = 0, offsets = 0;
    McapStatistics stats;
    reader.ForEachRecord([&](std::uint8_t op, std::string_view body, std::uint64_t) {
      if (op == static_cast<std::uint8_t>(McapOp::kChunkIndex)) {
        const McapChunkIndex c = ParseMcapChunkIndex(body);
        EXPECT_EQ(c.compression, compression);
        // The index points at a chunk record.
        EXPECT_EQ(static_cast<std::uint8_t>(reader.bytes()[c.chunk_start_offset]),
                  static_cast<std::uint8_t>(McapOp::kChunk));
        ++indexes;
      } else if (op == static_cast<std::uint8_t>(McapOp::kStatistics)) {
        stats = ParseMcapStatistics(body);
      } else if (op == static_cast<std::uint8_t>(McapOp::kSummaryOffset)) {
        ++offsets;
      } else if (op == static_cast<std::uint8_t>(McapOp::kMessageIndex)) {
        ++chunks;  // one message index per channel per chunk
      }
    });
    EXPECT_EQ(stats.message_count, 300u);
    EXPECT_EQ(stats.channel_count, 2u);
    EXPECT_EQ(stats.chunk_count, indexes);
    EXPECT_GE(indexes, 3u);  // 3 s of messages, chunks of at most 1 s
    EXPECT_EQ(chunks, 2 * indexes);
    EXPECT_EQ(offsets, 4u);  // schemas, channels, statistics, chunk indexes
    EXPECT_EQ(stats.message_start_time, written.front().log_time);
    EXPECT_EQ(stats.message_end_time, written.back().log_time);
  }
}

TEST(Mcap, ReadingFromAStartTimeSkipsEarlierMessages) {
  const std::string path = FreshPath("start");
  const std::vector<Written> written = WriteRun(path, McapWriterOptions{}, true);
  McapReader reader(path);
  std::vector<std::uint64_t> times;
  reader.ForEachMessage([&](const McapChannel&, const McapSchema*,
                            const McapMessage& m) { times.push_back(m.log_time); },
                        2'500'000'000ull);
  ASSERT_FALSE(times.empty());
  EXPECT_EQ(times.front(), 2'500'000'000ull);
  EXPECT_EQ(times.size(), 150u);
}

// Issue 40: a recording truncated while it is read (a new file copied over it) was a SIGBUS; it is
// an error naming the file.
TEST(Mcap, AFileCutWhileItIsReadIsAnErrorNotACrash) {
  const std::string path = FreshPath("cut_under_reader");
  McapWriterOptions options;
  options.chunk_ns = 200'000'000;
  options.compression = "";  // 300 KB: the cut leaves most of it unread
  WriteRun(path, options, true);
  ASSERT_GT(fs::file_size(path), 64u * 1024u);
  McapReader reader(path);
  McapMessageStream stream(reader);
  McapMessageStream::Item item;
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(stream.Next(&item));
  fs::resize_file(path, 4096);  // what `cp new.mcap old.mcap` does first
  try {
    while (stream.Next(&item)) {
    }
    FAIL() << "read to the end of a file cut under it";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": the file changed while it was read"),
              std::string::npos)
        << e.what();
  }
}

// Issue 40: a record length corrupted to 2^62 was taken as the end of a cut recording (exit 0,
// half the frames); it is an error.
TEST(Mcap, ARecordLengthBeyondAnyRecordIsCorruptNotACut) {
  const std::string whole = FreshPath("length_whole");
  McapWriterOptions options;
  options.chunk_ns = 200'000'000;
  WriteRun(whole, options, true);
  std::string bytes = io::ReadFile(whole, 1 << 26);
  // The second record after the magic (the first chunk; the first record is the header).
  McapRecordCursor cursor(std::string_view(bytes).substr(kMcapMagic.size()), kMcapMagic.size());
  std::uint8_t op = 0;
  std::string_view body;
  ASSERT_TRUE(cursor.Next(&op, &body));
  const std::size_t at = static_cast<std::size_t>(cursor.offset());
  const std::uint64_t huge = std::uint64_t{1} << 62;
  for (int b = 0; b < 8; ++b) bytes[at + 1 + b] = static_cast<char>((huge >> (8 * b)) & 0xff);
  const std::string path = FreshPath("length_corrupt");
  std::ofstream(path, std::ios::binary) << bytes;
  McapReader reader(path);
  try {
    ReadRun(reader);
    FAIL() << "a length of 2^62 was read as a cut";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a record length"), std::string::npos) << e.what();
  }
}

// A recording killed mid-way: every whole chunk up to the cut is read, and cut() says so.
TEST(Mcap, ARecordingCutAnywhereKeepsEveryWholeChunkBeforeTheCut) {
  const std::string whole = FreshPath("whole");
  McapWriterOptions options;
  options.chunk_ns = 200'000'000;  // chunks of 0.2 s
  const std::vector<Written> written = WriteRun(whole, options, true);
  const std::string bytes = io::ReadFile(whole, 1 << 26);
  std::size_t last = 0;
  for (std::size_t cut = 8; cut < bytes.size(); cut += 997) {
    const std::string path = FreshPath("cut");
    std::ofstream(path, std::ios::binary) << bytes.substr(0, cut);
    McapReader reader(path);
    const std::vector<Written> read = ReadRun(reader);
    EXPECT_TRUE(reader.cut()) << cut;
    ASSERT_LE(read.size(), written.size());
    EXPECT_TRUE(std::equal(read.begin(), read.end(), written.begin())) << cut;
    EXPECT_GE(read.size(), last) << "a longer prefix gave fewer messages at " << cut;
    last = read.size();
  }
  EXPECT_EQ(last, written.size());  // the last cut is in the summary: every message is there
  // Killed before Close(): the chunks written so far are read (the writer's destructor is not run
  // on a kill; the test writes without closing and copies the file while the writer is open).
  {
    const std::string path = FreshPath("unclosed");
    McapWriter w(path, options);
    const std::uint16_t c = w.AddChannel(0, "/x", "json");
    for (int i = 0; i < 100; ++i)
      w.Write(c, 10'000'000ull * static_cast<std::uint64_t>(i), 0, "{}");
    const std::string copy = FreshPath("unclosed_copy");
    fs::copy_file(path, copy);
    McapReader reader(copy);
    std::size_t n = 0;
    reader.ForEachMessage([&](const McapChannel&, const McapSchema*, const McapMessage&) { ++n; });
    EXPECT_TRUE(reader.cut());
    EXPECT_GE(n, 80u);  // all but the open chunk (at most 0.2 s: 21 messages)
    EXPECT_LT(n, 100u);
  }
}

TEST(Mcap, BadBytesGiveOneErrorNamingTheFileAndRecord) {
  const std::string path = FreshPath("bad_source");
  WriteRun(path, McapWriterOptions{}, true);
  const std::string bytes = io::ReadFile(path, 1 << 26);
  const auto read_error = [](const std::string& content) {
    const std::string p = FreshPath("bad");
    std::ofstream(p, std::ios::binary) << content;
    try {
      McapReader reader(p);
      reader.ForEachMessage([](const McapChannel&, const McapSchema*, const McapMessage&) {});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(read_error("hello").find("not an MCAP file"), std::string::npos);
  std::string bad_crc = bytes;
  // The first chunk's records: flip a byte well inside its compressed data.
  const std::size_t chunk = bad_crc.find('\x06', 8);
  ASSERT_NE(chunk, std::string::npos);
  bad_crc[chunk + 200] = static_cast<char>(bad_crc[chunk + 200] ^ 0x5A);
  const std::string e = read_error(bad_crc);
  EXPECT_NE(e.find(FreshPath("bad")), std::string::npos) << e;
  EXPECT_NE(e.find("chunk at byte"), std::string::npos) << e;
  // A chunk declaring 1 TB uncompressed is refused before anything is allocated.
  EXPECT_THROW(Decompress("zstd", "xx", 1ull << 40, "chunk"), InputError);
  EXPECT_THROW(Decompress("brotli", "xx", 2, "chunk"), InputError);
  EXPECT_THROW(McapWriter(path, McapWriterOptions{}), InputError);  // exists: never overwritten
}

}  // namespace
}  // namespace mapless::recording
