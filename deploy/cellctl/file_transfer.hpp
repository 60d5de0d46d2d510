#pragma once
// Files over DDS in chunks (idl/desk.idl FileChunk), both ways between the order desk and a
// remote client: the product's files to the desk, the results back. Every chunk is checked
// before it takes memory: a safe relative name, an offset and size that fit, a total bound.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "desk.h"
#include "deskPubSubTypes.h"
#include "services/dds/endpoints.hpp"

namespace cellctl {

using ChunkWriter = dds::Writer<cell::FileChunk, cell::FileChunkPubSubType>;

// cell/desk/KIND/CLIENT: the desk's topics of one client (idl/desk.idl).
inline std::string desk_topic(const std::string& kind, const std::string& client) { return "cell/desk/" + kind + "/" + client; }

// Chunks of up to 64 kB: 64 of them queued at most (4 MB) before the sender waits.
inline dds::QosSettings chunk_qos() {
  dds::QosSettings s;
  s.max_queued = 64;
  return s;
}

// Hex SHA-256 of `bytes`.
std::string sha256_hex(const std::string& bytes);

// Why `name` may not name a file of an order (absolute, "..", empty, too long); "" when it may.
std::string bad_file_name(const std::string& name);

// Writes `bytes` as chunks of `submission`'s file `name`. A chunk the readers have no room for
// yet is written again until `deadline`; false when it passed.
bool send_file(ChunkWriter& writer, const std::string& submission, const std::string& name, const std::string& bytes,
               std::chrono::steady_clock::time_point deadline);

std::string read_file_bytes(const std::filesystem::path& file);

// The files of one submission as their chunks come, at most `max_bytes` in all.
class FileAssembly {
 public:
  explicit FileAssembly(std::uint64_t max_bytes) : max_bytes_(max_bytes) {}
  // Takes the chunk; why not ("" when taken).
  std::string add(const cell::FileChunk& chunk);
  // The whole file, or null while chunks are missing.
  const std::string* complete(const std::string& name) const;
  std::size_t complete_files() const;
  std::uint64_t bytes() const { return bytes_; }
  const std::map<std::string, std::string>& files() const { return data_; }

 private:
  std::uint64_t max_bytes_, bytes_ = 0;
  std::map<std::string, std::string> data_;         // name -> its bytes (sized at the first chunk)
  std::map<std::string, std::uint64_t> received_;   // name -> bytes received
};

}  // namespace cellctl
