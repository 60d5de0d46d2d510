#pragma once
// Whether a grasp holds its part: a grasp sits on a pair of opposite faces of the part's box
// (grasp.hpp), and on a concave part (an L, a bracket, a lipped wall) or a tapered one a face
// of the box may be air where a finger lands. A finger holds where the part's surface comes
// within `within` of its pad, the side that faces the part.

#include <optional>
#include <utility>

#include "services/node/gripper.hpp"
#include "sim/mesh/triangle_mesh.hpp"
#include "twin/planning/grasp.hpp"

namespace twin {

// True when both fingers of `grasp` have a triangle of `part` (in the part's frame) within
// `within` (m) of their pads.
bool fingers_touch(const sim::TriangleMesh& part, const Grasp& grasp, const fb::GripperGeometry& gripper, double within);

// Where the part lies between the fingers of `grasp`: the least and greatest x, in the
// gripper's frame (the closing axis), of its surface within the fingers' reach below the palm
// and their width; nothing where no surface comes there.
std::optional<std::pair<double, double>> span_between_fingers(const sim::TriangleMesh& part, const Grasp& grasp,
                                                              const fb::GripperGeometry& gripper);

// True when no box of the gripper at `grasp` (each shrunk by `tolerance`) meets a triangle of
// `part` from `first_triangle` on: a subassembly gripped by its base (its first triangles)
// carries its other members, which the gripper must not stand in.
bool gripper_clear_of(const sim::TriangleMesh& part, std::size_t first_triangle, const Grasp& grasp,
                      const fb::GripperGeometry& gripper, double tolerance);

}  // namespace twin
