#include "deploy/cellctl/product_archive.hpp"

#include <unzip.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace cellctl {
namespace fs = std::filesystem;
namespace {

// minizip reads the archive from memory through these (ioapi.h): the upload is never a file
// the cell did not write itself.
struct Memory {
  std::string_view bytes;
  std::uint64_t at = 0;
};

voidpf memory_open(voidpf opaque, const void*, int) { return opaque; }
uLong memory_read(voidpf, voidpf stream, void* buf, uLong size) {
  auto& m = *static_cast<Memory*>(stream);
  const std::uint64_t n = std::min<std::uint64_t>(size, m.at < m.bytes.size() ? m.bytes.size() - m.at : 0);
  std::copy_n(m.bytes.data() + m.at, n, static_cast<char*>(buf));
  m.at += n;
  return static_cast<uLong>(n);
}
uLong memory_write(voidpf, voidpf, const void*, uLong) { return 0; }
ZPOS64_T memory_tell(voidpf, voidpf stream) { return static_cast<Memory*>(stream)->at; }
long memory_seek(voidpf, voidpf stream, ZPOS64_T offset, int origin) {
  auto& m = *static_cast<Memory*>(stream);
  const std::uint64_t base = origin == ZLIB_FILEFUNC_SEEK_SET ? 0 : origin == ZLIB_FILEFUNC_SEEK_CUR ? m.at : m.bytes.size();
  if (offset > m.bytes.size() || base > m.bytes.size() - offset) return -1;
  m.at = base + offset;
  return 0;
}
int memory_close(voidpf, voidpf) { return 0; }
int memory_error(voidpf, voidpf) { return 0; }

class Archive {
 public:
  explicit Archive(std::string_view bytes) : memory_{bytes} {
    zlib_filefunc64_def io{memory_open, memory_read, memory_write, memory_tell, memory_seek, memory_close, memory_error,
                           &memory_};
    zip_ = unzOpen2_64("upload", &io);
    if (!zip_) throw ArchiveError("the upload is not a zip archive");
  }
  ~Archive() { unzClose(zip_); }
  Archive(const Archive&) = delete;
  Archive& operator=(const Archive&) = delete;
  unzFile get() const { return zip_; }

 private:
  Memory memory_;
  unzFile zip_ = nullptr;
};

struct Entry {
  std::string name;
  bool folder = false;
};

// Why an entry's name cannot be unpacked into the product's folder; "" when it can.
std::string unsafe(const std::string& name) {
  if (name.empty() || name.size() > 255) return "its name is empty or longer than 255 characters";
  if (name.front() == '/') return "its path is absolute";
  if (name.find('\\') != std::string::npos) return "its name holds a backslash";
  for (unsigned char c : name) {
    if (c < 0x20 || c == 0x7f) return "its name holds a control character";
  }
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    const std::string part = name.substr(start, end - start);
    if (part == "..") return "its path leaves the product's folder (..)";
    if ((part.empty() || part == ".") && end != name.size()) return "its path has an empty or '.' part";
    start = end + 1;
  }
  return "";
}

bool is_link(const unz_file_info64& info) {
  const unsigned made_by = info.version >> 8;  // 3: Unix, where the high half holds the mode
  return made_by == 3 && ((info.external_fa >> 16) & 0170000) == 0120000;
}

std::vector<Entry> entries_of(unzFile zip, const ArchiveLimits& limits) {
  std::vector<Entry> entries;
  std::set<std::string> names;
  for (int at = unzGoToFirstFile(zip); at != UNZ_END_OF_LIST_OF_FILE; at = unzGoToNextFile(zip)) {
    if (at != UNZ_OK) throw ArchiveError("the zip archive's directory is damaged (entry " + std::to_string(entries.size() + 1) + ")");
    if (entries.size() == limits.max_entries) {
      throw ArchiveError("the archive holds more than " + std::to_string(limits.max_entries) + " entries");
    }
    unz_file_info64 info{};
    char name[512];
    if (unzGetCurrentFileInfo64(zip, &info, name, sizeof name, nullptr, 0, nullptr, 0) != UNZ_OK) {
      throw ArchiveError("the zip archive's directory is damaged (entry " + std::to_string(entries.size() + 1) + ")");
    }
    Entry e{std::string(name, std::min<std::size_t>(info.size_filename, sizeof name - 1)), false};
    if (info.size_filename >= sizeof name) throw ArchiveError("an entry's name is longer than 255 characters");
    e.folder = !e.name.empty() && e.name.back() == '/';
    if (e.folder) e.name.pop_back();
    if (const std::string why = unsafe(e.name); !why.empty()) throw ArchiveError("entry \"" + e.name + "\": " + why);
    if (info.flag & 1) throw ArchiveError("entry \"" + e.name + "\" is encrypted");
    if (is_link(info)) throw ArchiveError("entry \"" + e.name + "\" is a symbolic link");
    if (info.compression_method != 0 && info.compression_method != Z_DEFLATED) {
      throw ArchiveError("entry \"" + e.name + "\" is compressed by method " + std::to_string(info.compression_method) +
                         " (only stored and deflated entries are read)");
    }
    if (!names.insert(e.name).second) throw ArchiveError("entry \"" + e.name + "\" is in the archive twice");
    entries.push_back(std::move(e));
  }
  return entries;
}

// Writes the current entry to `path`, counting its bytes into `total`.
void unpack_entry(unzFile zip, const Entry& entry, const fs::path& path, std::uint64_t& total, const ArchiveLimits& limits) {
  if (unzOpenCurrentFile(zip) != UNZ_OK) throw ArchiveError("entry \"" + entry.name + "\" cannot be read");
  std::ofstream out(path, std::ios::binary);
  char buffer[1 << 16];
  int n = 0;
  while ((n = unzReadCurrentFile(zip, buffer, sizeof buffer)) > 0) {
    total += static_cast<std::uint64_t>(n);
    if (total > limits.max_bytes) {
      unzCloseCurrentFile(zip);
      throw ArchiveError("the archive unpacks to more than " + std::to_string(limits.max_bytes / 1'000'000) +
                         " MB (at entry \"" + entry.name + "\"), the desk's limit (desk: max_order_mb)");
    }
    out.write(buffer, n);
  }
  const int closed = unzCloseCurrentFile(zip);
  if (n < 0 || closed != UNZ_OK) {
    throw ArchiveError("entry \"" + entry.name + "\" is damaged" + (closed == UNZ_CRCERROR ? " (its checksum is wrong)" : ""));
  }
  if (!out.flush()) throw ArchiveError("cannot write " + path.string());
}

bool is_description(const std::string& name) {
  if (name.size() < 4) return false;
  std::string ext = name.substr(name.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".aml";
}

}  // namespace

fs::path unpack_product(std::string_view zip, const fs::path& folder, const ArchiveLimits& limits) {
  Archive archive(zip);
  const std::vector<Entry> entries = entries_of(archive.get(), limits);
  std::vector<std::string> descriptions;
  for (const auto& e : entries) {
    if (!e.folder && is_description(e.name)) descriptions.push_back(e.name);
  }
  if (descriptions.size() != 1) {
    throw ArchiveError(descriptions.empty() ? "the archive holds no AutomationML description (.aml)"
                                            : "the archive holds " + std::to_string(descriptions.size()) +
                                                  " AutomationML descriptions (.aml), among them \"" + descriptions[0] +
                                                  "\" and \"" + descriptions[1] + "\"; send one product per archive");
  }
  if (fs::exists(folder)) throw ArchiveError("cannot unpack into " + folder.string() + ": it exists");
  fs::create_directories(folder);
  try {
    std::uint64_t total = 0;
    std::size_t index = 0;
    for (int at = unzGoToFirstFile(archive.get()); at == UNZ_OK; at = unzGoToNextFile(archive.get()), ++index) {
      const Entry& e = entries.at(index);
      const fs::path path = folder / e.name;
      std::error_code error;
      fs::create_directories(e.folder ? path : path.parent_path(), error);
      if (error || (!e.folder && fs::is_directory(path))) {
        throw ArchiveError("entry \"" + e.name + "\" cannot be unpacked: a file and a folder of the archive share a name");
      }
      if (!e.folder) unpack_entry(archive.get(), e, path, total, limits);
    }
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(folder, ignored);
    throw;
  }
  return folder / descriptions.front();
}

}  // namespace cellctl
