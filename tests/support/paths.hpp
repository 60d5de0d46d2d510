#pragma once
// Where the tests' data and the example products are (set by tests/CMakeLists.txt).

#include <filesystem>
#include <string>

namespace test {

inline std::filesystem::path data(const std::string& relative) { return std::filesystem::path(TEST_DATA_DIR) / relative; }
inline std::filesystem::path product(const std::string& relative) { return std::filesystem::path(PRODUCTS_DIR) / relative; }

}  // namespace test
