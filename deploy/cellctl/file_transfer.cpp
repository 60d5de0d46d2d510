#include "deploy/cellctl/file_transfer.hpp"

#include <fstream>
#include <sstream>
#include <thread>

#include <openssl/evp.h>

namespace cellctl {

namespace fs = std::filesystem;

std::string sha256_hex(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

std::string bad_file_name(const std::string& name) {
  if (name.empty()) return "a file without a name";
  if (name.size() > 1024) return "a file name longer than 1024 characters";
  const fs::path p(name);
  if (p.is_absolute()) return "an absolute file name (" + name + ")";
  for (const auto& part : p) {
    if (part == "..") return "a file name that leaves the product's folder (" + name + ")";
  }
  if (name.find('\0') != std::string::npos || name.find('\\') != std::string::npos) return "a file name with \\0 or \\";
  return "";
}

bool send_file(ChunkWriter& writer, const std::string& submission, const std::string& name, const std::string& bytes,
               std::chrono::steady_clock::time_point deadline) {
  cell::FileChunk chunk;
  chunk.submission(submission);
  chunk.name(name);
  chunk.size(bytes.size());
  std::uint64_t offset = 0;
  do {  // an empty file is one empty chunk
    const std::size_t n = std::min<std::size_t>(cell::MAX_CHUNK, bytes.size() - offset);
    chunk.offset(offset);
    chunk.data().assign(bytes.begin() + static_cast<std::ptrdiff_t>(offset),
                        bytes.begin() + static_cast<std::ptrdiff_t>(offset + n));
    while (!writer.write(chunk)) {  // 64 chunks wait for a reader already: it takes them at its pace
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    offset += n;
  } while (offset < bytes.size());
  return true;
}

std::string read_file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string FileAssembly::add(const cell::FileChunk& chunk) {
  const std::string name = chunk.name().to_string();
  if (const std::string bad = bad_file_name(name); !bad.empty()) return bad;
  const std::uint64_t offset = chunk.offset(), size = chunk.size(), n = chunk.data().size();
  if (offset > size || n > size - offset) return "a chunk of " + name + " outside its size";
  auto it = data_.find(name);
  if (it == data_.end()) {
    if (data_.size() >= static_cast<std::size_t>(cell::MAX_ORDER_FILES)) return "more than 256 files";
    if (size > max_bytes_ - bytes_) return "the order's files pass the desk's limit of " + std::to_string(max_bytes_) + " bytes (max_order_mb)";
    bytes_ += size;
    it = data_.emplace(name, std::string(size, '\0')).first;
    received_[name] = 0;
  }
  if (it->second.size() != size) return "two sizes for " + name;
  std::copy(chunk.data().begin(), chunk.data().end(), it->second.begin() + static_cast<std::ptrdiff_t>(offset));
  // One writer, reliable and in order: chunks come once each, in order; a repeat or a gap is
  // a sender's error the digest catches.
  received_[name] = std::max(received_[name], offset + n);
  return "";
}

const std::string* FileAssembly::complete(const std::string& name) const {
  const auto it = data_.find(name);
  if (it == data_.end() || received_.at(name) < it->second.size()) return nullptr;
  return &it->second;
}

std::size_t FileAssembly::complete_files() const {
  std::size_t n = 0;
  for (const auto& [name, bytes] : data_) n += complete(name) != nullptr;
  return n;
}

}  // namespace cellctl
