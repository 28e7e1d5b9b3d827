// CURVE keys for the fleet link (ZeroMQ's CurveZMQ: authentication and encryption, libsodium).
//
// A key file (`mapless fleet keygen FILE` writes FILE with both keys, mode 0600, and FILE.pub with
// the public key alone):
//   # mapless fleet key (CurveZMQ, Z85)
//   public_key: "<40 characters>"
//   secret_key: "<40 characters>"     (absent from FILE.pub)
// The leader holds its key file and, optionally, the public keys of the followers it admits; a
// follower holds its own key file and the leader's public key. Without the leader's public key a
// follower cannot even complete the handshake; without an admitted key it is refused.
#pragma once

#include <string>
#include <vector>

namespace mapless::fleet {

struct CurveKey {
  std::string public_key;  // Z85, 40 characters
  std::string secret_key;  // Z85, 40 characters; empty for a public key file
};

// Throws InputError naming the file and the field.
CurveKey LoadCurveKey(const std::string& path, bool need_secret);
// Writes PATH (both keys, 0600) and PATH.pub; throws InputError when PATH exists.
CurveKey GenerateCurveKey(const std::string& path);
bool CurveAvailable();  // libzmq was built with CURVE

struct LeaderSecurity {
  CurveKey key;                             // empty public_key: no CURVE
  std::vector<std::string> allowed_public;  // empty: any follower that knows the leader's key
  bool enabled() const { return !key.public_key.empty(); }
};
// A leader's security from its key file (`key`; empty: no CURVE) and the public key files of the
// followers it admits (empty: any that knows the leader's key); InputError naming a bad file, or
// followers given without the leader's key (--curve-allow needs --curve-key).
LeaderSecurity LoadLeaderSecurity(const std::string& key, const std::vector<std::string>& allow);

struct FollowerSecurity {
  CurveKey key;  // empty: no CURVE
  std::string leader_public;
  bool enabled() const { return !key.public_key.empty(); }
};

}  // namespace mapless::fleet
