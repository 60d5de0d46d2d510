#pragma once
// The paper's ProductDescription (Fig. 2 and 3): a format-specific reader turns a file into
// a list of items, and build_product() turns items into the model. A new format is a new
// ProductDescription; the model does not change.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "twin/model/product.hpp"

namespace twin {

// "create": one part instance.
struct CreatePartItem {
  std::string id;
  std::string name;
  std::string type;
  std::map<std::string, std::string> attributes;
  std::optional<std::string> color;
  Quat orientation = Quat::Identity();
  std::optional<MeshRef> mesh;
  InterfaceMap interfaces;  // declared on the instance itself
  JointMap joints;          // the joints its own interfaces declare
  std::string subassembly;  // the subassembly it belongs to; empty when it goes in alone
  SourceRef where;
};

// "parameter": an interface point of a part type, shared by all parts of that type.
struct ParameterItem {
  std::string type;
  std::string interface;
  std::optional<Frame> frame;  // empty: declared without coordinates
  std::optional<Joint> joint;  // the joint it declares, if any
  SourceRef where;
};

// "connection": two parts joined at one interface each.
struct ConnectionItem {
  std::string part_a;
  std::string interface_a;
  std::string part_b;
  std::string interface_b;
  std::string name;
  SourceRef where;
};

// "precedence": one part goes in before another. An ordering constraint, never geometry
// (docs/automationml.md, AssemblyPrecedence).
struct PrecedenceItem {
  std::string before;  // part IDs
  std::string after;
  SourceRef where;
};

using DescriptionItem = std::variant<CreatePartItem, ParameterItem, ConnectionItem, PrecedenceItem>;

class ProductDescription {
 public:
  virtual ~ProductDescription() = default;
  virtual std::string product_name() const = 0;
  virtual std::filesystem::path source() const = 0;
  // Throws DescriptionError on input it cannot read.
  virtual std::vector<DescriptionItem> items() const = 0;
};

// Applies the items in order (parameters before the connections that use them) and checks
// what the items alone can tell: duplicate IDs, dangling links, interfaces without
// coordinates. Geometry (loops, unreached parts) is placement's job.
Product build_product(const ProductDescription& description);

}  // namespace twin
