#include "mapless/fleet/curve.h"

#include <sys/stat.h>
#include <zmq.h>

#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/yaml_reader.h"

namespace mapless::fleet {

namespace {

std::string CheckedKey(const io::YamlMap& map, const char* field, const std::string& path) {
  const std::string key = map.GetString(field);
  std::uint8_t decoded[32];
  if (key.size() != 40 || zmq_z85_decode(decoded, key.c_str()) == nullptr)
    throw InputError(path + ": " + field + ": not a CURVE key (40 Z85 characters)");
  return key;
}

}  // namespace

bool CurveAvailable() { return zmq_has("curve") != 0; }

CurveKey LoadCurveKey(const std::string& path, bool need_secret) {
  return io::WithYamlErrors(path, [&] {
    const io::YamlMap map = io::YamlMap::LoadFile(path);
    CurveKey key;
    key.public_key = CheckedKey(map, "public_key", path);
    if (need_secret) {
      if (!map.Has("secret_key"))
        throw InputError(path +
                         ": secret_key: missing (this is a public key file; give the file "
                         "`mapless fleet keygen` wrote without .pub)");
      key.secret_key = CheckedKey(map, "secret_key", path);
      char derived[41];
      if (zmq_curve_public(derived, key.secret_key.c_str()) != 0 || key.public_key != derived)
        throw InputError(path + ": public_key does not belong to secret_key");
    }
    return key;
  });
}

CurveKey GenerateCurveKey(const std::string& path) {
  if (!CurveAvailable()) throw InputError("this libzmq was built without CURVE (libsodium)");
  // Neither file may be there already (a public key handed out, or a dangling link, is never
  // replaced): both are checked before either is written.
  for (const std::string& file : {path, path + ".pub"}) {
    std::error_code ec;
    if (std::filesystem::symlink_status(file, ec).type() != std::filesystem::file_type::not_found)
      throw InputError(file + ": exists; choose another name (keys are never overwritten)");
  }
  char pub[41];
  char sec[41];
  if (zmq_curve_keypair(pub, sec) != 0) throw InputError("cannot make a CURVE key pair");
  const std::string head = "# mapless fleet key (CurveZMQ, Z85)\n";
  const std::string pub_line = std::string("public_key: \"") + pub + "\"\n";
  // The secret file is created 0600 before anything is written to it.
  const mode_t old = ::umask(077);
  try {
    io::WriteFileAtomic(path, head + pub_line + "secret_key: \"" + sec + "\"\n");
  } catch (...) {
    ::umask(old);
    throw;
  }
  ::umask(old);
  io::WriteFileAtomic(path + ".pub", head + pub_line);
  return CurveKey{pub, sec};
}

LeaderSecurity LoadLeaderSecurity(const std::string& key, const std::vector<std::string>& allow) {
  LeaderSecurity security;
  if (key.empty()) {
    if (!allow.empty()) throw InputError("--curve-allow needs --curve-key (the leader's key)");
    return security;
  }
  security.key = LoadCurveKey(key, true);
  for (const std::string& file : allow)
    security.allowed_public.push_back(LoadCurveKey(file, false).public_key);
  return security;
}

}  // namespace mapless::fleet
