#include "mapless/route/manifest_text.h"

#include "mapless/core/check.h"

namespace mapless::route {

std::string EntryText(const nlohmann::json& entry) {
  const std::string dumped = entry.dump(1);
  std::string text = "  ";
  text.reserve(dumped.size() + 32);
  for (const char c : dumped) {
    text += c;
    if (c == '\n') text += "  ";
  }
  return text;
}

std::string ManifestText(nlohmann::json head, const std::string& key,
                         const std::vector<std::string>& entries) {
  head[key] = nlohmann::json::array();
  std::string text = head.dump(1);
  if (!entries.empty()) {
    std::string array = "[\n";
    for (std::size_t k = 0; k < entries.size(); ++k) {
      array += entries[k];
      array += k + 1 < entries.size() ? ",\n" : "\n";
    }
    array += " ]";
    const std::string empty = "\"" + key + "\": []";
    const std::size_t at = text.find(empty);
    MAPLESS_CHECK(at != std::string::npos, "ManifestText: no array " << key);
    text.replace(at + empty.size() - 2, 2, array);
  }
  return text + "\n";
}

}  // namespace mapless::route
