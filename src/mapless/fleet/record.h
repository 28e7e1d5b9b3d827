// The records a leader serves to its followers (the route as an append-only log, issue 19).
//
// A route is a log of records with sequence numbers: 0 the route header, 1..n the route's elements
// in order (funnel-lane keyframes or eigenspace route images), n+1 the end of the route, then the
// views of its places that repeats learned (issue 45; funnel routes; route_log.h). The
// sequence number of a record follows from the route on disk, so a leader that restarts and
// reloads its route serves the same numbers. A record carries the bytes the route store writes
// (the keyframe's YAML and PNG, the route image's PNG), so a follower's copy can be compared with
// the leader's byte for byte.
//
// Wire format (little-endian), one ZeroMQ message per record or control message:
//   magic "MLFR" | version u8 (1) | type u8 | reserved u16 (0) | sequence u64 | written_ns i64 |
//   parts u32 | per part: length u32, bytes
// written_ns is the leader's wall clock when it appended the record (latency measurement only).
// A follower's control message, "from sequence n" (also its heartbeat):
//   magic "MLFC" | version u8 (1) | type u8 (1) | reserved u16 | from u64
// A follower's learned view, offered to the leader (route_log.h: ShareViewRecord): a record of
// type kView, sequence 0, as below.
// A leader's heartbeat when it has nothing to send: a record of type kHeartbeat whose sequence is
// the number of records in the log and whose single part is "1" when the route is complete.
//
// The decoders take untrusted bytes from the network: every size is checked against the message
// and against the limits below, and bad input throws InputError with one line saying what is wrong
// (fuzzed by fuzz/ harness FleetRecord).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace mapless::fleet {

inline constexpr std::uint8_t kWireVersion = 1;
inline constexpr std::size_t kMaxMessageBytes = 32u << 20;  // also the sockets' ZMQ_MAXMSGSIZE
inline constexpr std::size_t kMaxParts = 4;
inline constexpr std::uint64_t kMaxSequence = 1u << 24;  // far above io::kMaxKeyframes + 2

enum class RecordType : std::uint8_t {
  kHeader = 1,     // part 0: the route header as JSON (route kind, image sizes, detector)
  kKeyframe = 2,   // part 0: keyframes/NNNNNN.yml, part 1: keyframes/NNNNNN.png
  kImage = 3,      // part 0: the manifest entry as JSON, part 1: images/NNNNNN.png
  kEnd = 4,        // the route is complete (no parts)
  kHeartbeat = 5,  // not in the log; see above
  kView =
      6,  // part 0: {"keyframe", "offset_px", "learned_at", "last_used"}, part 1: the view's file
};
const char* RecordTypeName(RecordType type);

struct Record {
  RecordType type = RecordType::kHeader;
  std::uint64_t sequence = 0;
  std::int64_t written_ns = 0;
  std::vector<std::string> parts;
  bool operator==(const Record& other) const {
    return type == other.type && sequence == other.sequence && parts == other.parts;
  }
};

// The wall clock in nanoseconds since the epoch (written_ns; latency between processes on one
// machine, or machines whose clocks are synchronised).
std::int64_t WallClockNs();

std::string EncodeRecord(const Record& record);
// Throws InputError (one line: what is wrong, at which byte) on anything but a well-formed record.
Record DecodeRecord(std::string_view bytes);

// "Send me the records from `from` on."
std::string EncodeSubscribe(std::uint64_t from);
std::uint64_t DecodeSubscribe(std::string_view bytes);

}  // namespace mapless::fleet
