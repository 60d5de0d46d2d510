#pragma once

#include <filesystem>

namespace products {

void write_cranfield(const std::filesystem::path& dir);
void write_lego_tower(const std::filesystem::path& dir);

}  // namespace products
