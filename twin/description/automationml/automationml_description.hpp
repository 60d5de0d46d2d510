#pragma once
// ProductDescription for AutomationML (CAEX 2.15 and 3.0, IEC 62424). The conventions it
// reads are in docs/automationml.md.

#include <filesystem>
#include <string>
#include <vector>

#include "twin/description/product_description.hpp"

namespace twin {

class AutomationMLDescription : public ProductDescription {
 public:
  // Reads and checks the whole file; throws DescriptionError on bad input.
  explicit AutomationMLDescription(const std::filesystem::path& file);

  std::string product_name() const override { return product_name_; }
  std::filesystem::path source() const override { return source_; }
  std::vector<DescriptionItem> items() const override { return items_; }

  const std::string& schema_version() const { return schema_version_; }
  // Elements holding other elements (products, sub-assemblies); not parts themselves.
  std::size_t group_count() const { return group_count_; }

 private:
  friend class CaexReader;
  std::filesystem::path source_;
  std::string product_name_;
  std::string schema_version_;
  std::size_t group_count_ = 0;
  std::vector<DescriptionItem> items_;
};

}  // namespace twin
