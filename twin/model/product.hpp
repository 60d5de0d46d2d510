#pragma once
// The product model the whole system shares: parts, their types' interface points, and
// the connections between them (paper Fig. 2). It holds no global state, so any number of
// products live side by side in one process.

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "twin/model/frame.hpp"
#include "twin/model/joint.hpp"
#include "twin/model/source_ref.hpp"

namespace twin {

using PartIndex = std::size_t;

// Declared interfaces by name; an empty optional is an interface without coordinates.
using InterfaceMap = std::map<std::string, std::optional<Frame>>;
// The joints interfaces declare (docs/automationml.md, "Joints"), by interface name.
using JointMap = std::map<std::string, Joint>;

// A part type (an AutomationML SystemUnitClass): the paper's 3D parameters, held per
// product instead of in a static HashMap.
struct PartType {
  std::string name;
  InterfaceMap interfaces;
  JointMap joints;
};

struct MeshRef {
  std::filesystem::path file;  // absolute, already checked to lie inside the product folder
  SourceRef where;
  double scale = 1;  // metres per unit of the file (its LengthUnit: a CAD export is often in mm)
};

struct DigitalPart {
  std::string id;    // normalised: no braces, lower case
  std::string name;  // what people read
  std::string type;  // key into Product::types(); empty for an untyped part
  std::map<std::string, std::string> attributes;
  std::optional<std::string> color;
  Quat orientation = Quat::Identity();  // in the finished product
  std::optional<MeshRef> mesh;
  InterfaceMap own_interfaces;  // declared on the instance; override the type's
  JointMap own_joints;          // likewise
  // The subassembly it belongs to (docs/automationml.md): built first with the other parts of
  // that name, then inserted with them as one rigid body. Empty: it goes in alone.
  std::string subassembly;
  SourceRef where;

  Pose final_pose = Pose::Identity();  // set by placement (twin/geometry/placement.hpp)
};

struct Connection {
  PartIndex part1 = 0;
  std::string interface1;
  PartIndex part2 = 0;
  std::string interface2;
  std::string name;
  SourceRef where;
  Joint joint;  // what either side's interface declares; contact where neither does
};

class Product {
 public:
  Product(std::string name, std::filesystem::path source);

  const std::string& name() const { return name_; }
  const std::filesystem::path& source() const { return source_; }
  const std::vector<DigitalPart>& parts() const { return parts_; }
  std::vector<DigitalPart>& parts() { return parts_; }
  const std::vector<Connection>& connections() const { return connections_; }
  const std::map<std::string, PartType>& types() const { return types_; }

  // Mutators check what they can at once and throw DescriptionError naming `where`.
  void set_type_interface(const std::string& type, const std::string& interface,
                          const std::optional<Frame>& frame);
  void set_type_joint(const std::string& type, const std::string& interface, const Joint& joint);
  PartIndex add_part(DigitalPart part);
  void connect(const std::string& part_a, const std::string& interface_a, const std::string& part_b,
               const std::string& interface_b, const std::string& name, const SourceRef& where);

  // `before` goes in before `after` (part IDs): an ordering constraint, not geometry. Throws
  // on an unknown part, a part before itself, or a cycle of precedences.
  void add_precedence(const std::string& before, const std::string& after, const SourceRef& where);
  // The parts that must be in before this one.
  const std::vector<PartIndex>& predecessors(PartIndex part) const { return predecessors_[part]; }
  const std::vector<PartIndex>& successors(PartIndex part) const { return successors_[part]; }
  const std::vector<std::pair<PartIndex, PartIndex>>& precedences() const { return precedences_; }

  std::optional<PartIndex> find_part(const std::string& id) const;
  std::optional<PartIndex> find_part_by_name(const std::string& name) const;
  // The paper's getConnectionPoint: the interface in its part's frame, the instance's own
  // declaration first, then its type's. nullptr when the part declares no such interface.
  const std::optional<Frame>* interface_of(PartIndex part, const std::string& interface) const;
  // The joint an interface declares, the instance's first; nothing where it declares none.
  const Joint* joint_of(PartIndex part, const std::string& interface) const;
  // Connections that touch a part, by index into connections().
  const std::vector<std::size_t>& connections_of(PartIndex part) const { return by_part_[part]; }

 private:
  std::string name_;
  std::filesystem::path source_;
  std::vector<DigitalPart> parts_;
  std::vector<Connection> connections_;
  std::map<std::string, PartType> types_;
  std::unordered_map<std::string, PartIndex> by_id_;
  std::vector<std::vector<std::size_t>> by_part_;
  std::vector<std::pair<PartIndex, PartIndex>> precedences_;
  std::vector<std::vector<PartIndex>> predecessors_, successors_;
};

// "SystemUnitClassLib1/FaceplateBack" -> "FaceplateBack"
std::string short_type_name(const std::string& type);

}  // namespace twin
