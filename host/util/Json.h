#pragma once
// JSON parsing for files a user writes (scenes) or a tool reads back
// (checkpoint headers): nlohmann::json keeps the last of two equal keys in an
// object silently, so a second "media" would replace the first; here a
// repeated key is an error naming it.
#include <string>

#include <nlohmann/json.hpp>

namespace pyrolume {

// nlohmann::json::parse, plus: a key repeated within one object throws
// InputError "FILE: PATH.KEY: duplicate key ..." (PATH as the scene format
// names keys: media[1].emission.scale). Malformed JSON still throws
// nlohmann::json::exception, for the caller to phrase.
nlohmann::json parse_json_unique_keys(const std::string& text, const std::string& file);

}  // namespace pyrolume
