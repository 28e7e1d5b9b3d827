// The two serializations of ROS messages, field by field: ROS 1's (little-endian, packed, strings
// and arrays with a uint32 length) and ROS 2's CDR (XCDR1 with a 4-byte encapsulation header, each
// primitive aligned to its size from the end of the header, strings with their NUL). The reader
// takes untrusted bytes: every length is checked against what is left before anything is read.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::rosmsg {

enum class Wire { kRos1, kCdr };

class WireReader {
 public:
  // `what` names the message in errors ("sensor_msgs/msg/Image"). For CDR the encapsulation header
  // is read here: little- or big-endian plain CDR. Throws InputError.
  WireReader(std::string_view bytes, Wire wire, std::string what);

  std::uint8_t U8(const char* field);
  bool Bool(const char* field) { return U8(field) != 0; }
  std::uint32_t U32(const char* field);
  std::int32_t I32(const char* field) { return static_cast<std::int32_t>(U32(field)); }
  double F64(const char* field);
  std::string String(const char* field);
  // uint8[]: the count, then the bytes (a view into the message).
  std::string_view Bytes(const char* field);
  // float64[]: the count, then the values (at most `max_count`).
  std::vector<double> F64Sequence(const char* field, std::uint32_t max_count);
  // builtin_interfaces/Time (ROS 2: int32 sec, uint32 nanosec) or ROS 1 time (uint32, uint32).
  Timestamp Time(const char* field);
  std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  void Align(std::size_t n);
  const char* Take(std::size_t n, const char* field);
  [[noreturn]] void Fail(const char* field, const std::string& why) const;

  std::string_view bytes_;
  Wire wire_;
  std::string what_;
  std::size_t pos_ = 0;
  std::size_t origin_ = 0;  // where CDR alignment counts from
  bool swap_ = false;       // big-endian CDR
};

// ROS 2 CDR, little-endian (encapsulation 00 01 00 00), as rmw implementations write it.
class CdrWriter {
 public:
  CdrWriter();
  void U8(std::uint8_t v) { bytes_.push_back(v); }
  void Bool(bool v) { U8(v ? 1 : 0); }
  void U32(std::uint32_t v);
  void I32(std::int32_t v) { U32(static_cast<std::uint32_t>(v)); }
  void F64(double v);
  void String(std::string_view s);
  void Bytes(std::string_view data);
  void F64Sequence(const std::vector<double>& values);
  void Time(Timestamp t_ns);
  std::vector<std::uint8_t> Take() { return std::move(bytes_); }

 private:
  void Align(std::size_t n);
  void Raw(const void* p, std::size_t n);
  std::vector<std::uint8_t> bytes_;
};

}  // namespace mapless::rosmsg
