#pragma once
// What the OEM's side of quotes trusts of a cell's answer (docs/quotes.md).

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace cellctl {

// A quote.json as a cell wrote it came over the network: the result is a copy of the fields
// this command knows, each checked (kind, finite numbers >= 0, nesting at most 8 deep, the
// order id this request was given); anything else in the file is left out. Null, with the
// reason in `why`, when it does not pass.
nlohmann::json read_quote(const std::filesystem::path& file, const std::string& order, std::string& why);

// A submission id the desk takes (1 to 64 of A-Za-z0-9._-) from the product's file name,
// with a random part: two runs in one second differ.
std::string quote_submission_id(const std::string& product);

}  // namespace cellctl
