#pragma once
// A product sent as one zip (its AutomationML description and the meshes it names), as the
// dashboard's operator uploads it. The archive is untrusted: every entry's name must stay
// inside the product's folder (no absolute path, no "..", no backslash, no link), nothing is
// encrypted, and what it unpacks to is counted as it inflates, so a zip bomb stops at the
// limit, whatever its headers claim. Refused archives leave nothing behind.

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace cellctl {

struct ArchiveLimits {
  std::uint64_t max_bytes = 64'000'000;  // all entries unpacked, together
  std::size_t max_entries = 4096;
};

class ArchiveError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Unpacks `zip` into `folder` (made here; it must not exist) and returns the path of the one
// .aml file it holds. Throws ArchiveError with the reason (and the entry it concerns), after
// removing whatever it wrote.
std::filesystem::path unpack_product(std::string_view zip, const std::filesystem::path& folder,
                                     const ArchiveLimits& limits);

}  // namespace cellctl
