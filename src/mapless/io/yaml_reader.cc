#include "mapless/io/yaml_reader.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"

namespace mapless::io {
namespace {

std::string ShortValue(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

// A mapping that names a key twice is refused (yaml-cpp keeps both and a lookup finds one: a robot
// file's second `cmd_vel` would be silently ignored, or used). Walks the whole document.
void RefuseDuplicateKeys(const YAML::Node& node, const std::string& name, int depth = 0) {
  if (depth > 64) return;  // yaml-cpp refuses deeper documents itself
  if (node.IsSequence()) {
    for (const auto& item : node) RefuseDuplicateKeys(item, name, depth + 1);
  } else if (node.IsMap()) {
    std::vector<std::string> keys;
    for (const auto& kv : node) {
      if (kv.first.IsScalar()) {
        const std::string& key = kv.first.Scalar();
        if (std::find(keys.begin(), keys.end(), key) != keys.end()) {
          std::ostringstream out;
          out << name << ":" << kv.first.Mark().line + 1 << ":" << kv.first.Mark().column + 1
              << ": duplicate key '" << key << "'";
          throw InputError(out.str());
        }
        keys.push_back(key);
      }
      RefuseDuplicateKeys(kv.second, name, depth + 1);
    }
  }
}

// Counts the nodes of a document as its readers see it, every alias expanded, from the parser's
// events (each anchored node's expanded size is kept, so this is linear in the text whatever the
// aliases do), and refuses a document that expands past kMaxYamlExpandedNodes. yaml-cpp shares an
// aliased node instead of copying it, so a 1 KB file of nested aliases (the "billion laughs"
// shape) loads at once; it is every walk over it (the duplicate-key check, a reader's loop) that
// would take ten to the tenth steps.
class ExpansionCounter : public YAML::EventHandler {
 public:
  explicit ExpansionCounter(std::string name) : name_(std::move(name)) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { Leaf(mark, anchor); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    // An alias inside the very node it names makes the document a cycle: every walk of it (the
    // duplicate-key check, a reader's loop) would go round for ever (found by fuzz_config).
    for (const Open& o : open_)
      if (o.anchor != YAML::NullAnchor && o.anchor == anchor) {
        std::ostringstream out;
        out << name_ << ":" << mark.line + 1 << ":" << mark.column + 1
            << ": an alias inside the node it names (the document would be a cycle)";
        throw InputError(out.str());
      }
    const auto it = sizes_.find(anchor);
    Add(mark, it == sizes_.end() ? 1 : it->second);
  }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                const std::string&) override {
    Leaf(mark, anchor);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open_.push_back({mark, anchor, 1});
  }
  void OnSequenceEnd() override { Close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    open_.push_back({mark, anchor, 1});
  }
  void OnMapEnd() override { Close(); }

 private:
  struct Open {
    YAML::Mark mark;
    YAML::anchor_t anchor;
    std::uint64_t size;
  };
  void Leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    if (anchor != YAML::NullAnchor) sizes_[anchor] = 1;
    Add(mark, 1);
  }
  void Close() {
    if (open_.empty()) return;
    const Open done = open_.back();
    open_.pop_back();
    if (done.anchor != YAML::NullAnchor) sizes_[done.anchor] = done.size;
    if (!open_.empty()) open_.back().size += done.size;
  }
  void Add(const YAML::Mark& mark, std::uint64_t size) {
    if (!open_.empty()) open_.back().size += size;
    total_ += size;
    if (total_ > kMaxYamlExpandedNodes) {
      std::ostringstream out;
      out << name_ << ":" << mark.line + 1 << ":" << mark.column + 1
          << ": the document expands to more than " << kMaxYamlExpandedNodes
          << " values with its aliases (nested aliases: refused before it is read)";
      throw InputError(out.str());
    }
  }

  std::string name_;
  std::vector<Open> open_;
  std::unordered_map<YAML::anchor_t, std::uint64_t> sizes_;
  std::uint64_t total_ = 0;  // the expanded size so far (every alias counted as its copy)
};

void RefuseExpandingDocument(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  ExpansionCounter counter(name);
  parser.HandleNextDocument(counter);
}

}  // namespace

YamlMap YamlMap::LoadFile(const std::string& path) {
  return LoadString(ReadFile(path, kMaxYamlFileBytes), path);
}

YamlMap YamlMap::LoadString(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    RefuseExpandingDocument(text, name);
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    std::ostringstream out;
    out << name << ":" << e.mark.line + 1 << ":" << e.mark.column + 1
        << ": malformed YAML: " << e.msg;
    throw InputError(out.str());
  }
  if (!root.IsMap()) throw InputError(name + ":1:1: expected a YAML mapping at the top level");
  RefuseDuplicateKeys(root, name);
  return YamlMap(root, name, "");
}

YamlMap::YamlMap(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

std::string YamlMap::ChildPath(const std::string& key) const {
  if (path_.empty()) return key;
  if (!key.empty() && key[0] == '[') return path_ + key;
  return path_ + "." + key;
}

std::string YamlMap::Where(const YAML::Node& at) const {
  std::ostringstream out;
  out << file_;
  const YAML::Mark mark = at.Mark();
  if (mark.line >= 0) out << ":" << mark.line + 1 << ":" << mark.column + 1;
  return out.str();
}

void YamlMap::Fail(const std::string& key, const std::string& message) const {
  YAML::Node at = node_;
  if (!key.empty() && node_.IsMap() && node_[key]) at = node_[key];
  const std::string field = key.empty() ? path_ : ChildPath(key);
  throw InputError(Where(at) + ": " + (field.empty() ? "" : field + ": ") + message);
}

bool YamlMap::Has(const std::string& key) const {
  return node_.IsMap() && node_[key] && !node_[key].IsNull();
}

YAML::Node YamlMap::Child(const std::string& key) const {
  if (!node_.IsMap()) Fail("", "expected a mapping, got " + ShortValue(node_));
  if (!Has(key)) Fail("", "missing required field '" + ChildPath(key) + "'");
  return node_[key];
}

double YamlMap::GetDouble(const std::string& key) const {
  const YAML::Node n = Child(key);
  double value = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, value) || !std::isfinite(value)) {
    Fail(key, "expected a number, got " + ShortValue(n));
  }
  return value;
}

int YamlMap::GetInt(const std::string& key) const {
  const YAML::Node n = Child(key);
  int value = 0;
  if (!n.IsScalar() || !YAML::convert<int>::decode(n, value)) {
    Fail(key, "expected an integer, got " + ShortValue(n));
  }
  return value;
}

std::string YamlMap::GetString(const std::string& key) const {
  const YAML::Node n = Child(key);
  if (!n.IsScalar()) Fail(key, "expected a string, got " + ShortValue(n));
  return n.Scalar();
}

double YamlMap::GetDouble(const std::string& key, double fallback) const {
  return Has(key) ? GetDouble(key) : fallback;
}
int YamlMap::GetInt(const std::string& key, int fallback) const {
  return Has(key) ? GetInt(key) : fallback;
}
bool YamlMap::GetBool(const std::string& key, bool fallback) const {
  if (!Has(key)) return fallback;
  const YAML::Node n = node_[key];
  bool value = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, value)) {
    Fail(key, "expected true or false, got " + ShortValue(n));
  }
  return value;
}
std::string YamlMap::GetString(const std::string& key, const std::string& fallback) const {
  return Has(key) ? GetString(key) : fallback;
}

std::vector<double> YamlMap::GetDoubles(const std::string& key, int n) const {
  const YAML::Node list = Child(key);
  const std::string expected =
      n < 0 ? "a list of numbers" : "a list of " + std::to_string(n) + " numbers";
  if (!list.IsSequence() || (n >= 0 && static_cast<int>(list.size()) != n)) {
    Fail(key, "expected " + expected + ", got " + ShortValue(list));
  }
  std::vector<double> out;
  for (const auto& item : list) {
    double value = 0.0;
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, value) || !std::isfinite(value)) {
      Fail(key, "expected " + expected + ", got element " + ShortValue(item));
    }
    out.push_back(value);
  }
  return out;
}

std::vector<std::string> YamlMap::GetStrings(const std::string& key) const {
  const YAML::Node list = Child(key);
  if (!list.IsSequence()) Fail(key, "expected a list of strings, got " + ShortValue(list));
  std::vector<std::string> out;
  for (const auto& item : list) {
    if (!item.IsScalar()) Fail(key, "expected a list of strings, got element " + ShortValue(item));
    out.push_back(item.Scalar());
  }
  return out;
}

YamlMap YamlMap::GetMap(const std::string& key) const {
  const YAML::Node n = Child(key);
  if (!n.IsMap()) Fail(key, "expected a mapping, got " + ShortValue(n));
  return YamlMap(n, file_, ChildPath(key));
}

std::vector<YamlMap> YamlMap::GetList(const std::string& key) const {
  const YAML::Node list = Child(key);
  if (!list.IsSequence()) Fail(key, "expected a list, got " + ShortValue(list));
  std::vector<YamlMap> out;
  for (std::size_t i = 0; i < list.size(); ++i) {
    out.emplace_back(list[i], file_, ChildPath(key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

std::vector<YamlMap> YamlMap::GetMapList(const std::string& key) const {
  std::vector<YamlMap> out = GetList(key);
  for (const auto& item : out) {
    if (!item.node().IsMap()) item.Fail("", "expected a mapping, got " + ShortValue(item.node()));
  }
  return out;
}

std::vector<double> YamlMap::AsDoubles(int n) const {
  const std::string expected = "expected a list of " + std::to_string(n) + " numbers";
  if (!node_.IsSequence() || static_cast<int>(node_.size()) != n) {
    Fail("", expected + ", got " + ShortValue(node_));
  }
  std::vector<double> out;
  for (const auto& item : node_) {
    double value = 0.0;
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, value) || !std::isfinite(value)) {
      Fail("", expected + ", got element " + ShortValue(item));
    }
    out.push_back(value);
  }
  return out;
}

std::vector<std::string> YamlMap::Keys() const {
  if (!node_.IsMap()) Fail("", "expected a mapping, got " + ShortValue(node_));
  std::vector<std::string> keys;
  for (const auto& kv : node_) {
    if (!kv.first.IsScalar()) {
      throw InputError(Where(kv.first) + ": " + (path_.empty() ? "" : path_ + ": ") +
                       "expected a plain key, got " + ShortValue(kv.first));
    }
    keys.push_back(kv.first.Scalar());
  }
  return keys;
}

void YamlMap::CheckKnownKeys(std::initializer_list<const char*> known) const {
  for (const std::string& key : Keys()) {
    const bool ok =
        std::any_of(known.begin(), known.end(), [&](const char* k) { return key == k; });
    if (!ok) {
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      Fail(key, "unknown field (known: " + list + ")");
    }
  }
}

}  // namespace mapless::io
