#pragma once
// Assembly sequence planning: the role of the paper's nextUnassembledPart. A planner ranks
// the parts that may come next; AssemblyPlanner tries them in that order.

#include <memory>
#include <string>
#include <vector>

#include "twin/planning/assembly_scene.hpp"

namespace twin {

class SequencePlanner {
 public:
  virtual ~SequencePlanner() = default;
  virtual std::string name() const = 0;
  // Parts to try next, best first. Empty: nothing can come next.
  virtual std::vector<PartIndex> candidates(const AssemblyScene& scene) const = 0;
  // Whether the planner may take assembled parts off again (partial disassembly) and try
  // another order when no candidate can be inserted.
  virtual bool backtracks() const = 0;
};

// The paper's heuristic: a part that stands on the assembly surface first (document
// order), else the lowest part linked to an assembled one. One candidate, no backtracking.
class PaperSequencePlanner : public SequencePlanner {
 public:
  std::string name() const override { return "paper"; }
  std::vector<PartIndex> candidates(const AssemblyScene& scene) const override;
  bool backtracks() const override { return false; }
};

// Every part the links allow (linked to an assembled part, or standing on the station's
// surface, which supports it), lowest first; with backtracking, so that a dead end leads to
// another order.
class SearchSequencePlanner : public SequencePlanner {
 public:
  std::string name() const override { return "search"; }
  std::vector<PartIndex> candidates(const AssemblyScene& scene) const override;
  bool backtracks() const override { return true; }
};

// An order given by part IDs (a subassembly, where the scene holds it as one body, by
// "subassembly " and its base's ID, as subassembly_planner names it): the first of them not
// assembled yet, where the links and precedences allow it now; else nothing. One candidate,
// no backtracking. A twin that takes an order up plans again in the order its predecessor
// began to build.
class GivenSequencePlanner : public SequencePlanner {
 public:
  explicit GivenSequencePlanner(std::vector<std::string> ids) : order_(std::move(ids)) {}
  std::string name() const override { return "given"; }
  std::vector<PartIndex> candidates(const AssemblyScene& scene) const override;
  bool backtracks() const override { return false; }

 private:
  std::vector<std::string> order_;
};

std::unique_ptr<SequencePlanner> make_sequence_planner(const std::string& name);


}  // namespace twin
