// The dashboard's uploads: a product's zip unpacks into its folder, and a hostile one
// (escaping names, links, encryption, a bomb, damage) is refused with the reason and leaves
// nothing behind.
#include <catch2/catch.hpp>
#include <zip.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "deploy/cellctl/product_archive.hpp"

namespace fs = std::filesystem;
using cellctl::ArchiveError;
using cellctl::ArchiveLimits;
using cellctl::unpack_product;

namespace {

struct ZipEntry {
  std::string name;
  std::string bytes;
  unsigned long unix_mode = 0100644;  // in the high half of the external attributes
  const char* password = nullptr;
};

// A zip as minizip writes it (made by Unix, deflated), read back whole.
std::string zip_of(const std::vector<ZipEntry>& entries) {
  const fs::path file = fs::temp_directory_path() / ("cell-test-" + std::to_string(::getpid()) + ".zip");
  zipFile zip = zipOpen64(file.c_str(), APPEND_STATUS_CREATE);
  REQUIRE(zip);
  for (const auto& e : entries) {
    zip_fileinfo info{};
    info.external_fa = e.unix_mode << 16;
    REQUIRE(zipOpenNewFileInZip4_64(zip, e.name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr, Z_DEFLATED, 9, 0, -MAX_WBITS,
                                    8, Z_DEFAULT_STRATEGY, e.password, 0, 3 << 8, 0, 0) == ZIP_OK);
    REQUIRE(zipWriteInFileInZip(zip, e.bytes.data(), static_cast<unsigned>(e.bytes.size())) == ZIP_OK);
    REQUIRE(zipCloseFileInZip(zip) == ZIP_OK);
  }
  REQUIRE(zipClose(zip, nullptr) == ZIP_OK);
  std::ifstream in(file, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  fs::remove(file);
  return bytes.str();
}

struct Folder {
  fs::path path = fs::temp_directory_path() / ("cell-test-unpack-" + std::to_string(::getpid()));
  Folder() { fs::remove_all(path); }
  ~Folder() { fs::remove_all(path); }
};

// The refusal's text; fails the test when the archive is taken or something stays behind.
std::string refusal(const std::string& zip, const ArchiveLimits& limits = {}) {
  Folder folder;
  try {
    unpack_product(zip, folder.path / "product", limits);
  } catch (const ArchiveError& e) {
    CHECK_FALSE(fs::exists(folder.path / "product"));
    return e.what();
  }
  FAIL("the archive was taken");
  return "";
}

}  // namespace

TEST_CASE("product archive: the description and its meshes unpack into the product's folder") {
  Folder folder;
  const std::string zip = zip_of({{"tower/tower.aml", "<CAEXFile/>"}, {"tower/meshes/", ""}, {"tower/meshes/brick.stl", "solid b"}});
  const fs::path aml = unpack_product(zip, folder.path / "product", {});
  CHECK(aml == folder.path / "product" / "tower" / "tower.aml");
  std::ifstream mesh(folder.path / "product" / "tower" / "meshes" / "brick.stl");
  std::string text;
  std::getline(mesh, text);
  CHECK(text == "solid b");
}

TEST_CASE("product archive: names that leave the folder, links and encryption are refused, nothing kept") {
  CHECK_THAT(refusal(zip_of({{"a.aml", "x"}, {"../evil.stl", "x"}})), Catch::Contains("\"../evil.stl\"") && Catch::Contains(".."));
  CHECK_THAT(refusal(zip_of({{"a.aml", "x"}, {"m/../../evil.stl", "x"}})), Catch::Contains("leaves the product's folder"));
  CHECK_THAT(refusal(zip_of({{"/etc/a.aml", "x"}})), Catch::Contains("absolute"));
  CHECK_THAT(refusal(zip_of({{"a.aml", "x"}, {"m\\..\\..\\evil.stl", "x"}})), Catch::Contains("backslash"));
  CHECK_THAT(refusal(zip_of({{"a.aml", "x"}, {"link.stl", "/etc/passwd", 0120777}})), Catch::Contains("symbolic link"));
  CHECK_THAT(refusal(zip_of({{"a.aml", "x", 0100644, "secret"}})), Catch::Contains("encrypted"));
  CHECK_THAT(refusal(zip_of({{"a.aml", "x"}, {"a.aml", "y"}})), Catch::Contains("twice"));
  CHECK_THAT(refusal(zip_of({{"m", "x"}, {"m/a.aml", "y"}})), Catch::Contains("share a name"));
}

TEST_CASE("product archive: one description, no more, no less") {
  CHECK_THAT(refusal(zip_of({{"brick.stl", "x"}})), Catch::Contains("no AutomationML description"));
  CHECK_THAT(refusal(zip_of({{"a.aml", "x"}, {"b.AML", "y"}})), Catch::Contains("2 AutomationML descriptions"));
}

TEST_CASE("product archive: a bomb stops at the limit, whatever its headers say") {
  // 50 MB of zeros deflate to about 50 kB; the limit here is 1 MB.
  const std::string zip = zip_of({{"a.aml", "x"}, {"bomb.stl", std::string(50'000'000, '\0')}});
  REQUIRE(zip.size() < 200'000);
  CHECK_THAT(refusal(zip, {1'000'000, 100}), Catch::Contains("more than 1 MB") && Catch::Contains("bomb.stl"));
  std::vector<ZipEntry> many{{"a.aml", "x"}};
  for (int i = 0; i < 101; ++i) many.push_back({"m" + std::to_string(i) + ".stl", "x"});
  CHECK_THAT(refusal(zip_of(many), {1'000'000, 100}), Catch::Contains("more than 100 entries"));
}

TEST_CASE("product archive: what is not a whole zip is refused") {
  CHECK_THAT(refusal(""), Catch::Contains("not a zip archive"));
  CHECK_THAT(refusal("PK\x03\x04 hello"), Catch::Contains("not a zip archive"));
  std::string zip = zip_of({{"a.aml", std::string(10000, 'a')}});
  // A byte of the deflated data changed: its checksum (or its inflation) fails.
  zip[40] = static_cast<char>(zip[40] ^ 0x55);
  CHECK_THAT(refusal(zip), Catch::Contains("damaged"));
  CHECK_THAT(refusal(zip.substr(0, zip.size() - 30)), Catch::Contains("not a zip archive"));
}
