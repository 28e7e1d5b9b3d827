#include "mapless/ros2/type_hash.h"

#include <sodium.h>

namespace mapless::ros2 {

std::string TypeHash(const std::string& type) {
  const std::string json = TypeDescriptionJson(type);
  unsigned char digest[crypto_hash_sha256_BYTES];
  crypto_hash_sha256(digest, reinterpret_cast<const unsigned char*>(json.data()), json.size());
  static const char* kHex = "0123456789abcdef";
  std::string hex = "RIHS01_";
  for (unsigned char c : digest) {
    hex += kHex[c >> 4];
    hex += kHex[c & 15];
  }
  return hex;
}

}  // namespace mapless::ros2
