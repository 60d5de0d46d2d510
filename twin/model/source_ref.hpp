#pragma once
// Where something came from in a product description, and the error that names it.

#include <stdexcept>
#include <string>

namespace twin {

// A place in a description file: "cranfield.aml:42 <InternalLink Name="L1">".
struct SourceRef {
  std::string file;
  int line = 0;         // 1-based; 0 when unknown
  std::string element;  // e.g. InternalElement "peg1"

  std::string to_string() const;
};

// Bad input: the description cannot become a product. what() reads
// "file:line: element: message" so a designer can go straight to the spot.
class DescriptionError : public std::runtime_error {
 public:
  DescriptionError(SourceRef where, const std::string& message);

  const SourceRef& where() const { return where_; }
  const std::string& message() const { return message_; }

 private:
  SourceRef where_;
  std::string message_;
};

}  // namespace twin
