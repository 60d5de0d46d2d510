#pragma once
// The path of a part turned into its thread (threads.hpp): in straight from a safe height, as
// LinearPathPlanner's insertions, to where its thread meets the mate's, then along the axis
// while turning at the pitch (a right-hand thread: it turns about the way it advances) to its
// place, released, and the arm backs out along its carriage. One trajectory for each way along
// the axis; the collision world decides which the part can come from.

#include <vector>

#include "twin/planning/assembly_scene.hpp"
#include "twin/planning/threads.hpp"

namespace twin {

std::vector<Trajectory> screw_insertions(const AssemblyScene& scene, PartIndex part, const Thread& thread);

}  // namespace twin
