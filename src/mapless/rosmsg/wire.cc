#include "mapless/rosmsg/wire.h"

#include <cstring>

#include "mapless/core/check.h"

namespace mapless::rosmsg {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "CdrWriter writes the host order as little-endian");

namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

}  // namespace

WireReader::WireReader(std::string_view bytes, Wire wire, std::string what)
    : bytes_(bytes), wire_(wire), what_(std::move(what)) {
  if (wire_ != Wire::kCdr) return;
  if (bytes_.size() < 4) Fail("encapsulation", "fewer than 4 bytes");
  const auto b0 = static_cast<unsigned char>(bytes_[0]);
  const auto b1 = static_cast<unsigned char>(bytes_[1]);
  if (b0 != 0 || (b1 != 0 && b1 != 1))
    Fail("encapsulation", "not plain CDR (kind " + std::to_string(b0 * 256 + b1) + ")");
  swap_ = b1 == 0;  // CDR_BE
  pos_ = origin_ = 4;
}

void WireReader::Fail(const char* field, const std::string& why) const {
  throw InputError(what_ + "." + field + ": " + why + " (byte " + std::to_string(pos_) + " of " +
                   std::to_string(bytes_.size()) + ")");
}

void WireReader::Align(std::size_t n) {
  if (wire_ != Wire::kCdr) return;
  const std::size_t offset = (pos_ - origin_) % n;
  if (offset != 0) pos_ = std::min(bytes_.size(), pos_ + (n - offset));
}

const char* WireReader::Take(std::size_t n, const char* field) {
  if (n > remaining()) Fail(field, "the message ends early");
  const char* p = bytes_.data() + pos_;
  pos_ += n;
  return p;
}

std::uint8_t WireReader::U8(const char* field) {
  return static_cast<std::uint8_t>(*Take(1, field));
}

std::uint32_t WireReader::U32(const char* field) {
  Align(4);
  std::uint32_t v = 0;
  std::memcpy(&v, Take(4, field), 4);
  return swap_ ? __builtin_bswap32(v) : v;
}

double WireReader::F64(const char* field) {
  Align(8);
  std::uint64_t bits = 0;
  std::memcpy(&bits, Take(8, field), 8);
  if (swap_) bits = __builtin_bswap64(bits);
  double v = 0.0;
  std::memcpy(&v, &bits, 8);
  return v;
}

std::string WireReader::String(const char* field) {
  const std::uint32_t n = U32(field);
  if (n > remaining()) Fail(field, "a string of " + std::to_string(n) + " bytes does not fit");
  std::string_view s(Take(n, field), n);
  if (wire_ == Wire::kCdr) {
    if (n == 0 || s.back() != '\0') Fail(field, "a CDR string without its NUL");
    s.remove_suffix(1);
  }
  return std::string(s);
}

std::string_view WireReader::Bytes(const char* field) {
  const std::uint32_t n = U32(field);
  if (n > remaining()) Fail(field, std::to_string(n) + " bytes do not fit");
  return {Take(n, field), n};
}

std::vector<double> WireReader::F64Sequence(const char* field, std::uint32_t max_count) {
  const std::uint32_t n = U32(field);
  if (n > max_count)
    Fail(field, std::to_string(n) + " values, at most " + std::to_string(max_count));
  std::vector<double> v(n);
  for (double& x : v) x = F64(field);
  return v;
}

Timestamp WireReader::Time(const char* field) {
  const std::uint32_t sec = U32(field);
  const std::uint32_t nsec = U32(field);
  if (nsec >= kNsPerSecond) Fail(field, "nanoseconds " + std::to_string(nsec) + " >= 1e9");
  const std::int64_t s =
      wire_ == Wire::kCdr ? static_cast<std::int32_t>(sec) : static_cast<std::int64_t>(sec);
  return s * kNsPerSecond + nsec;
}

CdrWriter::CdrWriter() : bytes_{0, 1, 0, 0} {}

void CdrWriter::Align(std::size_t n) {
  while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
}

void CdrWriter::Raw(const void* p, std::size_t n) {
  const auto* b = static_cast<const std::uint8_t*>(p);
  bytes_.insert(bytes_.end(), b, b + n);
}

void CdrWriter::U32(std::uint32_t v) {
  Align(4);
  Raw(&v, 4);  // little-endian hosts only (x86_64, aarch64)
}

void CdrWriter::F64(double v) {
  Align(8);
  Raw(&v, 8);
}

void CdrWriter::String(std::string_view s) {
  U32(static_cast<std::uint32_t>(s.size() + 1));
  Raw(s.data(), s.size());
  U8(0);
}

void CdrWriter::Bytes(std::string_view data) {
  U32(static_cast<std::uint32_t>(data.size()));
  Raw(data.data(), data.size());
}

void CdrWriter::F64Sequence(const std::vector<double>& values) {
  U32(static_cast<std::uint32_t>(values.size()));
  for (double v : values) F64(v);
}

void CdrWriter::Time(Timestamp t_ns) {
  std::int64_t sec = t_ns / kNsPerSecond;
  std::int64_t nsec = t_ns % kNsPerSecond;
  if (nsec < 0) {
    nsec += kNsPerSecond;
    --sec;
  }
  I32(static_cast<std::int32_t>(sec));
  U32(static_cast<std::uint32_t>(nsec));
}

}  // namespace mapless::rosmsg
