// Reads YAML mappings into options structs with errors a user can act on: every error names the
// file, the line and column, and the dotted path of the field, e.g.
//   scenarios/room.yaml:12:7: world.objects[3].size: expected a list of 3 numbers
// Unknown keys are errors too (a misspelt option must not be silently ignored).
#pragma once

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>
#include <vector>

#include "mapless/core/check.h"

namespace mapless::io {

class YamlMap {
 public:
  // Parses a file; throws InputError "FILE:LINE:COL: ..." for unreadable or malformed YAML.
  static YamlMap LoadFile(const std::string& path);
  // Parses text; `name` stands in for the file name in errors.
  static YamlMap LoadString(const std::string& text, const std::string& name);

  YamlMap(YAML::Node node, std::string file, std::string path);

  bool Has(const std::string& key) const;
  const YAML::Node& node() const { return node_; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

  // Required fields (missing: error naming the field).
  double GetDouble(const std::string& key) const;
  int GetInt(const std::string& key) const;
  std::string GetString(const std::string& key) const;
  // Optional fields with a default.
  double GetDouble(const std::string& key, double fallback) const;
  int GetInt(const std::string& key, int fallback) const;
  bool GetBool(const std::string& key, bool fallback) const;
  std::string GetString(const std::string& key, const std::string& fallback) const;
  // A list of exactly `n` numbers (n < 0: any length).
  std::vector<double> GetDoubles(const std::string& key, int n) const;
  std::vector<std::string> GetStrings(const std::string& key) const;

  YamlMap GetMap(const std::string& key) const;
  // Each element of a list of mappings.
  std::vector<YamlMap> GetMapList(const std::string& key) const;
  // Elements of a list, any node type (for mixed lists such as waypoints).
  std::vector<YamlMap> GetList(const std::string& key) const;

  // This node itself as a list of exactly `n` finite numbers (for list elements such as [x, y]).
  std::vector<double> AsDoubles(int n) const;
  // The keys of this mapping (a key that is not a plain scalar is an error).
  std::vector<std::string> Keys() const;

  // Throws on any key not in `known`.
  void CheckKnownKeys(std::initializer_list<const char*> known) const;

  // Throws InputError "FILE:LINE:COL: PATH.key: message" at the position of `key` (or of this map).
  [[noreturn]] void Fail(const std::string& key, const std::string& message) const;
  // The dotted path of a child key.
  std::string ChildPath(const std::string& key) const;

 private:
  YAML::Node Child(const std::string& key) const;
  std::string Where(const YAML::Node& at) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
};

// Runs `parse`, turning any yaml-cpp exception that escapes the checked getters into an InputError
// "NAME:LINE:COL: message" (defence in depth: bad input must never surface as another exception).
template <typename F>
auto WithYamlErrors(const std::string& name, F&& parse) -> decltype(parse()) {
  try {
    return parse();
  } catch (const YAML::Exception& e) {
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                     std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

}  // namespace mapless::io
