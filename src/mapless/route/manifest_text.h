// A route manifest written one entry at a time: the document as nlohmann's dump(1) writes it, with
// its array of entries given as their texts, each made once (EntryText). The same bytes as dumping
// the whole document, without writing every entry's JSON again at each new one: a follower appends
// one keyframe or route image at a time, and that grew with the route (issue 41).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace mapless::route {

// An entry (a JSON object) as it stands in the array of a dump(1) document.
std::string EntryText(const nlohmann::json& entry);

// `head` (every field but the array `key`) dumped with the array `key` made of `entries`
// (EntryText's), then a newline.
std::string ManifestText(nlohmann::json head, const std::string& key,
                         const std::vector<std::string>& entries);

}  // namespace mapless::route
