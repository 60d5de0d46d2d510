#include "twin/model/source_ref.hpp"

namespace twin {

std::string SourceRef::to_string() const {
  std::string text = file.empty() ? "<input>" : file;
  if (line > 0) text += ":" + std::to_string(line);
  if (!element.empty()) text += ": " + element;
  return text;
}

DescriptionError::DescriptionError(SourceRef where, const std::string& message)
    : std::runtime_error(where.to_string() + ": " + message),
      where_(std::move(where)),
      message_(message) {}

}  // namespace twin
