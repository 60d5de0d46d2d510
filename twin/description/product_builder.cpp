#include "twin/description/product_description.hpp"

namespace twin {
namespace {

struct ItemApplier {
  Product& product;

  void operator()(const CreatePartItem& item) const {
    DigitalPart part;
    part.id = item.id;
    part.name = item.name;
    part.type = item.type;
    part.attributes = item.attributes;
    part.color = item.color;
    part.orientation = item.orientation;
    part.mesh = item.mesh;
    part.own_interfaces = item.interfaces;
    part.own_joints = item.joints;
    part.subassembly = item.subassembly;
    part.where = item.where;
    product.add_part(std::move(part));
  }
  void operator()(const ParameterItem& item) const {
    product.set_type_interface(item.type, item.interface, item.frame);
    if (item.joint) product.set_type_joint(item.type, item.interface, *item.joint);
  }
  void operator()(const ConnectionItem&) const {}
  void operator()(const PrecedenceItem&) const {}
};

}  // namespace

Product build_product(const ProductDescription& description) {
  Product product(description.product_name(), description.source());
  const std::vector<DescriptionItem> items = description.items();
  // Connections last: a link may name a part declared further down the file.
  for (const auto& item : items) std::visit(ItemApplier{product}, item);
  for (const auto& item : items) {
    if (const auto* c = std::get_if<ConnectionItem>(&item)) {
      product.connect(c->part_a, c->interface_a, c->part_b, c->interface_b, c->name, c->where);
    }
    if (const auto* p = std::get_if<PrecedenceItem>(&item)) product.add_precedence(p->before, p->after, p->where);
  }
  return product;
}

}  // namespace twin
