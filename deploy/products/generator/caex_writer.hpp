#pragma once
// Writes a product as CAEX 3.0 in the paper's conventions (docs/automationml.md):
// interface points as Attributes with "x,y,z" DefaultValues named like the
// ExternalInterfaces, part instances in one product element, InternalLinks "ID:interface".

#include <string>

#include <Eigen/Core>
#include <pugixml.hpp>

namespace products {

class CaexWriter {
 public:
  CaexWriter(const std::string& file_name, const std::string& product_name);

  void interface_class(const std::string& name);
  // A SystemUnitClass in the product's class library; `base` is another class's name.
  pugi::xml_node unit_class(const std::string& name, const std::string& base = "");
  // An interface point, in mm, on a class; `joint`: the joint it declares (docs/automationml.md,
  // "Joints"), none where empty.
  void interface_point(pugi::xml_node unit_class, const std::string& name,
                       const std::string& interface_class, const Eigen::Vector3d& mm, const std::string& joint = "");
  // A mesh file (relative path) for every part of a class.
  void geometry(pugi::xml_node unit_class, const std::string& ref_uri);

  // A part instance; `orientation` is "rx,ry,rz" in degrees.
  pugi::xml_node part(const std::string& name, const std::string& unit_class, const std::string& color,
                      const std::string& orientation = "0,0,0");
  void link(const std::string& name, pugi::xml_node part_a, const std::string& interface_a,
            pugi::xml_node part_b, const std::string& interface_b);

  void save(const std::string& path) const;

 private:
  pugi::xml_document document_;
  pugi::xml_node product_;
  pugi::xml_node interface_lib_;
  pugi::xml_node unit_lib_;
  std::string interface_lib_name_;
  std::string unit_lib_name_;
};

// A UUID-shaped ID derived from a seed, so that regenerated files do not change.
std::string stable_uuid(const std::string& seed);

}  // namespace products
