#pragma once
// Threaded joints: a shaft turned into a bore (a bolt into a nut, a leg into its threaded
// insert). Modelled with their threads, or at their nominal diameters, the two overlap in the
// finished product by up to a thread's depth all round their common axis: the thread's phase
// is not part of a pose. That overlap is the joint, not an interference, and the part goes in
// on a helix: along the axis while turning at the pitch.
//
// A pair is a thread where its overlap (interference.hpp's samples of either surface inside the
// other) lies in a thin shell all round one axis, no thicker than a thread's depth for its
// diameter; or where a link between the two declares a screw (docs/automationml.md, "Joints"),
// whose pitch it gives. Otherwise the pitch is the one the parts are modelled with, measured on
// their surfaces (the helix their crests and roots follow), or, where neither shows a helix
// clearly (a thread modelled at its nominal diameter), ISO 261's coarse pitch for the diameter.

#include <optional>
#include <string>
#include <vector>

#include "twin/planning/interference.hpp"

namespace twin {

struct Thread {
  PartIndex part1 = 0, part2 = 0;  // as the interference's: part1 < part2
  Vec3 axis = Vec3::UnitY();       // unit, product frame
  Vec3 centre = Vec3::Zero();      // on the axis, in the middle of the engaged length
  double diameter = 0;             // m, outer, of the overlap
  double depth = 0;                // m, the overlap
  double length = 0;               // m engaged along the axis
  double pitch = 0;                // m the part advances per turn
  bool declared = false;           // a link declares the screw (and its pitch)
  bool pitch_measured = false;     // the helix the parts' surfaces follow (threads.cpp)
  bool left_hand = false;          // measured so; the plan turns right-hand threads only
  bool pitch_assumed = false;      // ISO coarse for the diameter

  PartIndex other(PartIndex part) const { return part == part1 ? part2 : part1; }
};

// The thread the interference is, or nothing where it is not one.
std::optional<Thread> thread_of(const LoadedProduct& product, const Interference& interference);

// ISO 261 coarse pitch for a nominal diameter, m (the nearest listed size, M1 to M64).
double coarse_pitch(double diameter);

// "nut on bolt: a thread of 12.0 mm, 0.60 mm overlap, 14.0 mm engaged, pitch 1.75 mm (ISO
// coarse for the diameter)"
std::string describe(const Product& product, const Thread& thread);

}  // namespace twin
