#include "twin/planning/assembly_planner.hpp"

#include "twin/planning/interference.hpp"
#include "twin/planning/plan_verifier.hpp"
#include "twin/planning/screw_path.hpp"
#include "twin/planning/subassembly_planner.hpp"
#include "twin/planning/threads.hpp"

#include <algorithm>
#include <bitset>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_set>

namespace twin {
namespace {

std::string millimetres(double metres) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f mm", metres * 1000);
  return buffer;
}

std::string join(const std::vector<std::string>& names, const std::string& separator = ", ") {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : separator) + n;
  return out;
}

class Search {
 public:
  Search(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path, const PlannerOptions& options,
         const Gravity* stability)
      : product_(product), sequence_(sequence), path_(path), options_(options),
        scene_(product, options.collision, options.gripper), assembled_(product.product.parts().size(), false),
        stability_(options.stability ? stability : nullptr) {}

  // Whether the search put a part aside because it would not stand where it went.
  bool refused_for_gravity() const { return !falls_.empty(); }

  Plan run() {
    plan_.sequence_planner = sequence_.name();
    plan_.path_planner = path_.name();
    plan_.margin_threshold = options_.margin_threshold;
    plan_.margin_reach = options_.margin_reach;
    report_meshes();
    // Overlaps in the finished product first: no path can resolve them.
    for (Interference& i : find_interferences(product_, options_.collision).overlaps) {
      if (auto thread = thread_of(product_, i)) {
        plan_.findings.push_back({"thread", describe(product_.product, *thread), {name(thread->part2), name(thread->part1)}});
        threads_.push_back(*thread);
        scene_.link(thread->part1, thread->part2);
        continue;
      }
      plan_.findings.push_back({"interference", describe(product_.product, i), {name(i.part2), name(i.part1)}});
      interferences_.push_back(i);
    }
    for (const PlanStep& step : options_.given) {
      assembled_[step.part] = true;
      scene_.assemble(step.part);
      plan_.steps.push_back(step);
    }
    most_placeable_ = assembled_.size() - fewest_left_out();
    plan_.complete = extend();
    if (best_) keep_best_order();
    if (!plan_.complete && deepest_.size() > plan_.steps.size()) plan_.steps = deepest_;
    measure_margins();
    report();
    return std::move(plan_);
  }

 private:
  const std::string& name(PartIndex p) const { return product_.product.parts()[p].name; }
  double grasp_bounds_min(PartIndex p) const { return scene_.grasp_bounds(p).sizes().minCoeff(); }

  // Depth-first: returns true once every part is in.
  bool extend() {
    if (plan_.steps.size() == assembled_.size()) return order_found();
    if (plan_.steps.size() >= most_placeable_) {  // no plan holds more: the search is done
      stopped_ = at_most_placeable_ = true;
      return false;
    }
    if (failed_states_.count(assembled_)) return false;
    const std::vector<PartIndex> allowed(scene_.frontier().begin(), scene_.frontier().end());
    for (PartIndex part : sequence_.candidates(scene_)) {
      if (plan_.steps.size() == options_.given.size() && options_.not_next.count(part)) continue;
      tried_.insert(part);
      // A part that overlaps one in place in the finished product goes in on no path.
      if (const Interference* overlap = overlap_in_place(part)) {
        blocked_by_[part].insert(name(overlap->part1 == part ? overlap->part2 : overlap->part1));
        unplaceable_.insert(part);
        if (!sequence_.backtracks()) return give_up(part);
        continue;
      }
      if (out_of_time()) return false;
      // What the geometry said before: a part that found no way in among some parts finds none
      // among more of them (more stand in its way); a way found among some parts is free
      // among fewer.
      if (known_blocked(part)) {
        unplaceable_.insert(part);
        if (!sequence_.backtracks()) return give_up(part);
        continue;
      }
      std::vector<Attempt> tried;
      std::optional<Trajectory> trajectory;
      if (const Way* way = known_way(part)) {
        trajectory = way->trajectory;
        tried = way->tried;
      } else {
        // A part whose thread's mate is in place goes in on the helix only; into two threads at
        // once it cannot turn.
        const std::vector<const Thread*> threads = threads_in_place(part);
        if (threads.size() > 1) two_threads_.insert(part);
        std::vector<Trajectory> screws = threads.size() == 1 ? screw_insertions(scene_, part, *threads.front())
                                                             : std::vector<Trajectory>{};
        std::size_t next_screw = 0;
        const auto next = [&]() -> std::optional<Trajectory> {
          if (threads.empty()) return path_.next(scene_, part, tried);
          if (next_screw < screws.size()) return std::move(screws[next_screw++]);
          return std::nullopt;
        };
        while ((trajectory = next())) {
          ++plan_.trajectories_simulated;
          auto collision = scene_.simulate_grasps(part, *trajectory, path_.trajectories_nest() ? &known_ : nullptr);
          if (!collision) break;
          if (!collision->with.empty()) {
            (collision->member == "part" ? blocked_by_ : gripper_blocked_by_)[part].insert(collision->with);
          }
          if (!worst_.count(part) || collision->depth > worst_[part].depth) worst_[part] = *collision;
          tried.push_back({std::move(*trajectory), collision});
        }
        if (!trajectory) {
          blocked_among_[part].push_back(assembled_);
          unplaceable_.insert(part);
          if (!sequence_.backtracks()) return give_up(part);
          continue;
        }
        ways_[part].push_back({assembled_, *trajectory, tried});
      }
      const Standing standing = stands_with(part);
      if (standing.falls) {
        falls_[part] = *standing.falls;
        if (!sequence_.backtracks()) return give_up(part);
        continue;
      }
      PlanStep step{part, std::move(*trajectory), std::move(tried), allowed, "", {}, std::nullopt, false, standing.hold, {}};
      if (options_.objective == Objective::margin) {
        measure(step);
        // No order through this step beats the best found: its least margin is at most this.
        if (best_ && margin_of(step) <= best_margin_ + kMarginResolution) continue;
      }
      assembled_[part] = true;
      scene_.assemble(part);
      plan_.steps.push_back(std::move(step));
      tell(PlanProgress::Event::placed, part);
      if (extend()) return true;
      if (!sequence_.backtracks() || stopped_) return false;
      if (plan_.steps.size() > deepest_.size()) deepest_ = plan_.steps;  // the best partial plan, for the report
      // Partial disassembly: take the part off and try another one in its place.
      plan_.steps.pop_back();
      scene_.disassemble(part);
      assembled_[part] = false;
      ++plan_.backtracks;
      backtracked_.insert(part);
      tell(PlanProgress::Event::backtrack, part);
      if (plan_.backtracks >= options_.max_backtracks) {
        stopped_ = true;
        if (!best_) {
          plan_.findings.push_back({"gave-up", "the search stopped after " + std::to_string(plan_.backtracks) + " backtracks", {}});
        }
        return false;
      }
    }
    failed_states_.insert(assembled_);
    return false;
  }

  double margin_of(const PlanStep& step) const { return step.margin ? step.margin->distance : options_.margin_reach; }

  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

  // Past the time limit, or when asked to stop, the search stops where it stands (the report
  // says so).
  bool out_of_time() {
    if (options_.stop && options_.stop()) {
      stopped_ = told_to_stop_ = true;
      return true;
    }
    if (options_.time_limit <= 0 || seconds() < options_.time_limit) return false;
    stopped_ = timed_out_ = true;
    return true;
  }

  void tell(PlanProgress::Event event, PartIndex part) const {
    if (!options_.progress) return;
    options_.progress({event, name(part), plan_.steps.size(), assembled_.size(), plan_.backtracks, seconds()});
  }

  // `a` holds no part that `b` does not.
  static bool within(const std::vector<bool>& a, const std::vector<bool>& b) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i] && !b[i]) return false;
    }
    return true;
  }

  bool known_blocked(PartIndex part) const {
    const auto it = blocked_among_.find(part);
    if (it == blocked_among_.end()) return false;
    return std::any_of(it->second.begin(), it->second.end(), [&](const auto& among) { return within(among, assembled_); });
  }

  struct Way {
    std::vector<bool> among;  // the parts in place when it was found
    Trajectory trajectory;
    std::vector<Attempt> tried;
  };
  const Way* known_way(PartIndex part) const {
    const auto it = ways_.find(part);
    if (it == ways_.end()) return nullptr;
    for (const Way& w : it->second) {
      if (within(assembled_, w.among)) return &w;
    }
    return nullptr;
  }

  struct Standing {
    std::optional<Instability> falls;  // what would move
    bool hold = false;                 // stands only once the part's fastening is made
  };

  // Whether the parts in place stand with `part` put in, its fastenings to them made; and
  // whether it needs the arm until they are (it would not stand released before). Known
  // states are not asked again.
  Standing stands_with(PartIndex part) {
    if (!stability_) return {};
    std::vector<bool> key = assembled_;
    key.push_back(false);
    key[part] = true;
    if (const auto known = standing_.find(key); known != standing_.end()) return known->second;
    std::vector<PlacedPart> placed;
    for (PartIndex p = 0; p < assembled_.size(); ++p) {
      if (assembled_[p] || p == part) placed.push_back({p, product_.product.parts()[p].final_pose});
    }
    const auto& connections = product_.product.connections();
    std::vector<bool> fastened(connections.size(), false), before;
    for (std::size_t c = 0; c < connections.size(); ++c) {
      const auto in = [&](PartIndex p) { return assembled_[p] || p == part; };
      fastened[c] = connections[c].joint.fastens() && in(connections[c].part1) && in(connections[c].part2);
    }
    Standing out;
    out.falls = stability_->check(placed, {}, fastened, part);
    before = fastened;
    bool fastens = false;
    for (std::size_t c : product_.product.connections_of(part)) {
      fastens = fastens || before[c];
      before[c] = false;
    }
    if (!out.falls && fastens) out.hold = stability_->check(placed, {}, before, part).has_value();
    return standing_[key] = out;
  }

  bool too_large_to_measure(PartIndex part) const {
    return scene_.exact_triangles(part) > options_.margin_max_triangles;
  }

  void measure(PlanStep& step) const {
    if (options_.margin_reach <= 0) return;  // margins not asked for
    if (too_large_to_measure(step.part)) return;
    step.margin = scene_.margin(step.part, step.trajectory, options_.margin_reach);
    step.margin_measured = true;
  }

  // Every part in: done, unless the objective asks to look on for more room. Then the order
  // is kept if it is the best so far, and the search goes back for another.
  bool order_found() {
    if (options_.objective != Objective::margin) return true;
    const double least = least_margin(plan_.steps, options_.margin_reach);
    ++orders_found_;
    if (!best_) {
      first_margin_ = least;
      first_backtracks_ = plan_.backtracks;
      first_backtracked_ = backtracked_;
    }
    if (!best_ || least > best_margin_ + kMarginResolution) {
      best_ = plan_.steps;
      best_margin_ = least;
    }
    return best_margin_ + kMarginResolution >= options_.margin_reach;  // nothing has more room than the reach
  }

  // The best order found; the backtracks the designer reads of are those it took to find
  // the first order, the rest went into looking for more room.
  void keep_best_order() {
    const std::size_t explored = plan_.backtracks - first_backtracks_;
    plan_.steps = std::move(*best_);
    plan_.complete = true;
    plan_.backtracks = first_backtracks_;
    backtracked_ = first_backtracked_;
    const std::string least = millimetres(best_margin_) + (best_margin_ >= options_.margin_reach ? " or more" : "");
    plan_.findings.push_back(
        {"margin-search", "the order kept has a least margin of " + least + " (the first order found: " +
                              millimetres(first_margin_) + "); " + std::to_string(orders_found_) +
                              " orders went together in " + std::to_string(explored) + " further backtracks" +
                              (stopped_ ? ", when the search stopped at its limit" : ""),
         {}});
  }

  // The margins the search did not measure: each step in the scene of the steps before it.
  void measure_margins() {
    for (PartIndex p = 0; p < assembled_.size(); ++p) scene_.disassemble(p);
    for (PlanStep& step : plan_.steps) {
      if (!step.margin_measured) measure(step);
      scene_.assemble(step.part);
    }
  }

  // A sequence that does not backtrack ends at its first part that cannot go in.
  bool give_up(PartIndex part) {
    stopped_ = true;
    stopped_at_ = {part, plan_.steps.size() + 1};
    return false;
  }

  // The fewest parts any plan leaves out because they overlap others in the finished product:
  // of each overlapping pair one stays out, so as many as the least set of parts that holds
  // one of every pair (a vertex cover; the given parts are in). Exact over up to 20 parts
  // that overlap; over more, the pairs of a greedy matching, each of which leaves one out.
  std::size_t fewest_left_out() const {
    std::vector<PartIndex> involved;
    std::vector<std::pair<PartIndex, PartIndex>> pairs;
    std::set<PartIndex> out;  // the partners of given parts stay out
    for (const Interference& i : interferences_) {
      const bool given1 = assembled_[i.part1], given2 = assembled_[i.part2];
      if (given1 && given2) continue;
      if (given1 || given2) {
        out.insert(given1 ? i.part2 : i.part1);
        continue;
      }
      pairs.emplace_back(i.part1, i.part2);
    }
    pairs.erase(std::remove_if(pairs.begin(), pairs.end(), [&](const auto& e) { return out.count(e.first) || out.count(e.second); }),
                pairs.end());
    for (const auto& [a, b] : pairs) {
      for (PartIndex p : {a, b}) {
        if (std::find(involved.begin(), involved.end(), p) == involved.end()) involved.push_back(p);
      }
    }
    if (involved.size() > 20) {
      std::set<PartIndex> matched;
      std::size_t matching = 0;
      for (const auto& [a, b] : pairs) {
        if (matched.count(a) || matched.count(b)) continue;
        matched.insert({a, b});
        ++matching;
      }
      return out.size() + matching;
    }
    const auto bit = [&](PartIndex p) { return 1u << (std::find(involved.begin(), involved.end(), p) - involved.begin()); };
    std::vector<std::uint32_t> pair_bits;
    for (const auto& e : pairs) pair_bits.push_back(bit(e.first) | bit(e.second));
    std::size_t fewest = involved.size();
    for (std::uint32_t cover = 0; cover < (1u << involved.size()); ++cover) {
      const std::size_t size = std::bitset<32>(cover).count();
      if (size >= fewest) continue;
      if (std::all_of(pair_bits.begin(), pair_bits.end(), [&](std::uint32_t pair) { return (cover & pair) != 0; })) fewest = size;
    }
    return out.size() + fewest;
  }

  // The overlap in the finished product between the part and one in place, if any.
  const Interference* overlap_in_place(PartIndex part) const {
    for (const Interference& i : interferences_) {
      if ((i.part1 == part && assembled_[i.part2]) || (i.part2 == part && assembled_[i.part1])) return &i;
    }
    return nullptr;
  }

  // "leg1, leg2": the parts the part is threaded to.
  std::string threads_named(PartIndex part) const {
    std::vector<std::string> names;
    for (const Thread& t : threads_) {
      if (t.part1 == part || t.part2 == part) names.push_back(name(t.other(part)));
    }
    return join(names);
  }

  // The threads whose mates are in place: the part turns into them.
  std::vector<const Thread*> threads_in_place(PartIndex part) const {
    std::vector<const Thread*> out;
    for (const Thread& t : threads_) {
      if ((t.part1 == part || t.part2 == part) && assembled_[t.other(part)]) out.push_back(&t);
    }
    return out;
  }

  // Why a part is not in the plan, as far as the search knows.
  std::string why_not(PartIndex p) {
    if (const auto fell = falls_.find(p); fell != falls_.end() && !unplaceable_.count(p)) {
      return "it would not stand where it goes: " + describe(product_.product, fell->second, options_.stand);
    }
    if (at_most_placeable_) {
      if (const Interference* overlap = overlap_in_place(p)) {
        return describe(product_.product, *overlap) + " (of the two, one stays out)";
      }
    }
    if (unplaceable_.count(p)) {
      const auto& blockers = blocked_by_[p];
      std::vector<std::string> why;
      if (const auto worst = worst_.find(p); worst != worst_.end() && worst->second.phase == "grasp") {
        why.push_back("no grasp: it is " + millimetres(grasp_bounds_min(p)) + " across at its narrowest, " +
                      millimetres(worst->second.depth) + " more than the gripper opens");
      } else if (worst != worst_.end() && worst->second.phase == "gripping") {
        why.push_back("no grasp holds it: on every pair of faces of its box the gripper opens to, a finger closes on "
                      "air (the part is concave or tapered there)");
      } else if (worst != worst_.end()) {
        const Collision& c = worst->second;
        const auto& gripper = gripper_blocked_by_[p];
        std::string what = "no collision-free path; ";
        if (!blockers.empty()) what += "blocked by " + join({blockers.begin(), blockers.end()});
        if (!blockers.empty() && !gripper.empty()) what += "; where the part was free, ";
        if (!gripper.empty()) what += "the gripper hit " + join({gripper.begin(), gripper.end()}) + " on every grasp";
        why.push_back(what + " (deepest: the " + c.member + " hit " + c.with + " " + millimetres(c.depth) +
                      " deep while " + c.phase + ")");
      }
      if (two_threads_.count(p)) {
        why.push_back("where it would turn into two threads at once (" + threads_named(p) + "), it cannot");
      }
      if (const std::size_t n = scene_.grasps_in_members(p); n > 0) {
        why.push_back(std::to_string(n) + (n == 1 ? " grasp" : " grasps") + " of its base would put the gripper in its " +
                      "other members (a subassembly is gripped by its base)");
      }
      for (const Interference& i : interferences_) {
        const PartIndex other = i.part1 == p ? i.part2 : i.part2 == p ? i.part1 : p;
        if (other != p && blockers.count(name(other))) why.push_back(describe(product_.product, i));
      }
      return why.empty() ? "the path planner had no trajectory for it" : join(why, "; ");
    }
    if (stopped_at_) {
      return "not tried after step " + std::to_string(stopped_at_->second) + " failed (" + name(stopped_at_->first) +
             "): the " + sequence_.name() + " sequence does not go back";
    }
    if (tried_.count(p)) return "it went in at times, but the remaining parts could not be completed after it";
    if (timed_out_) {
      return "not in place when the search reached its time limit (" + std::to_string(static_cast<int>(options_.time_limit)) +
             " s) after " + std::to_string(plan_.backtracks) + " backtracks";
    }
    if (stopped_) return "not in place when the search stopped after " + std::to_string(plan_.backtracks) + " backtracks";
    return "never reachable: the parts it is linked to could not be assembled";
  }

  void report() {
    // Collisions met on the way to the plan, and how each was resolved.
    for (const auto& step : plan_.steps) {
      for (const auto& a : step.failed) {
        if (a.collision->phase == "gripping") {
          plan_.findings.push_back({"grasp",
                                    name(step.part) + " (" + a.trajectory.label + "): no grasp for this direction holds "
                                        "it (a finger closes on air on each); resolved by " + step.trajectory.label,
                                    {name(step.part)}});
          continue;
        }
        plan_.findings.push_back({"collision",
                                  name(step.part) + " (" + a.trajectory.label + "): " + a.collision->member + " hit " +
                                      a.collision->with + " while " + a.collision->phase + ", " +
                                      millimetres(a.collision->depth) + " deep; resolved by " +
                                      step.trajectory.label,
                                  {name(step.part), a.collision->with}});
      }
    }
    for (std::size_t i = 0; i < plan_.steps.size(); ++i) {
      const PlanStep& step = plan_.steps[i];
      if (options_.margin_reach > 0 && too_large_to_measure(step.part)) {
        plan_.findings.push_back({"margin",
                                  "step " + std::to_string(i + 1) + " (" + name(step.part) + "): margin not measured: " +
                                      "one concave piece of " + std::to_string(scene_.exact_triangles(step.part)) +
                                      " triangles, more than the " + std::to_string(options_.margin_max_triangles) +
                                      " measured (a part authored as convex pieces is measured at any size)",
                                  {name(step.part)}});
      }
      if (!step.margin || step.margin->distance >= options_.margin_threshold) continue;
      const Margin& m = *step.margin;
      plan_.findings.push_back({"margin",
                                "step " + std::to_string(i + 1) + " (" + name(step.part) + "): the " + m.member +
                                    " passes " + millimetres(m.distance) + " from " + m.with + " while " + m.phase +
                                    ", under the " + millimetres(options_.margin_threshold) + " threshold",
                                {name(step.part), m.with}});
    }
    if (plan_.backtracks > 0) {
      std::vector<std::string> names;
      for (PartIndex p : backtracked_) names.push_back(name(p));
      plan_.findings.push_back({"backtrack",
                                std::to_string(plan_.backtracks) + " partial disassembl" +
                                    (plan_.backtracks == 1 ? "y" : "ies") + " to find an order; taken off again: " +
                                    join(names),
                                names});
    }
    report_open_order();
    if (at_most_placeable_) {
      plan_.findings.push_back({"search-bound",
                                "the search stopped at " + std::to_string(plan_.steps.size()) + " of " +
                                    std::to_string(assembled_.size()) + " parts, the most any plan holds: of each pair "
                                    "of parts that overlap in the finished product one stays out",
                                {}});
    }
    if (timed_out_ && !plan_.complete) {
      plan_.findings.push_back({"gave-up",
                                "the search reached its time limit of " + std::to_string(static_cast<int>(options_.time_limit)) +
                                    " s after " + std::to_string(plan_.backtracks) + " backtracks; the plan holds the most "
                                    "parts it had in place",
                                {}});
    }
    if (told_to_stop_ && !plan_.complete) {
      plan_.findings.push_back({"gave-up", "the search was told to stop after " + std::to_string(plan_.backtracks) +
                                               " backtracks; the plan holds the most parts it had in place", {}});
    }
    if (!plan_.complete) {
      std::vector<bool> in(assembled_.size(), false);
      for (const auto& s : plan_.steps) in[s.part] = true;
      for (PartIndex p = 0; p < in.size(); ++p) {
        if (in[p]) continue;
        std::vector<std::string> parts = {name(p)};
        parts.insert(parts.end(), blocked_by_[p].begin(), blocked_by_[p].end());
        parts.insert(parts.end(), gripper_blocked_by_[p].begin(), gripper_blocked_by_[p].end());
        const std::string why = why_not(p);
        plan_.findings.push_back({"infeasible", name(p) + ": " + why, parts});
      }
    }
  }

  // What loading repaired or found wrong in each mesh file, and what the check simplified,
  // once per file.
  void report_meshes() {
    std::map<const sim::TriangleMesh*, std::vector<std::string>> users;
    for (PartIndex p = 0; p < product_.meshes.size(); ++p) {
      if (product_.meshes[p] && !sim::loading_report(*product_.meshes[p]).empty()) {
        users[product_.meshes[p].get()].push_back(name(p));
      }
    }
    for (const auto& [mesh, parts] : users) {
      const auto& part = product_.product.parts()[*product_.product.find_part_by_name(parts.front())];
      plan_.findings.push_back({"mesh", part.mesh->file.filename().string() + " (" + join(parts) + "): " +
                                            sim::loading_report(*mesh), parts});
    }
  }

  // Where the links left a choice: the designer steers the sequence through links (paper 5.2).
  void report_open_order() {
    for (std::size_t i = 0; i < plan_.steps.size(); ++i) {
      const auto& allowed = plan_.steps[i].allowed;
      if (allowed.size() < 2) continue;
      std::vector<std::string> names;
      for (PartIndex p : allowed) names.push_back(name(p));
      plan_.findings.push_back({"open-order",
                                "step " + std::to_string(i + 1) + ": the links allow any of " + join(names) +
                                    "; the planner chose " + name(plan_.steps[i].part),
                                names});
    }
  }

  const LoadedProduct& product_;
  SequencePlanner& sequence_;
  PathPlanner& path_;
  const PlannerOptions& options_;
  AssemblyScene scene_;
  std::vector<bool> assembled_;
  Plan plan_;
  std::vector<PlanStep> deepest_;
  std::unordered_set<std::vector<bool>> failed_states_;
  std::map<PartIndex, std::set<std::string>> blocked_by_;          // what the part itself hit
  std::map<PartIndex, std::set<std::string>> gripper_blocked_by_;  // what the gripper hit, the part free
  std::set<PartIndex> unplaceable_;
  std::set<PartIndex> backtracked_;
  std::set<PartIndex> tried_;
  std::map<PartIndex, Collision> worst_;  // the deepest collision of each part's tries
  std::vector<Interference> interferences_;
  std::vector<Thread> threads_;  // overlaps that are threads: the part goes in on a helix
  std::set<PartIndex> two_threads_;  // parts that met the mates of two of their threads in place
  // Objective::margin: the best order so far, and what the first one found was.
  std::optional<std::vector<PlanStep>> best_;
  double best_margin_ = 0, first_margin_ = 0;
  std::size_t orders_found_ = 0, first_backtracks_ = 0;
  std::set<PartIndex> first_backtracked_;
  bool stopped_ = false;
  std::size_t most_placeable_ = 0;  // no plan holds more parts (fewest_left_out)
  bool at_most_placeable_ = false;  // the search stopped there
  std::optional<std::pair<PartIndex, std::size_t>> stopped_at_;  // the part and step a sequence ended at
  const Gravity* stability_;
  std::map<std::vector<bool>, Standing> standing_;  // by the parts in place, the new one among them
  std::map<PartIndex, std::vector<std::vector<bool>>> blocked_among_;  // parts in place where a part found no way
  std::map<PartIndex, std::vector<Way>> ways_;                       // and where it found one
  KnownCollisions known_;                                            // grasps' collisions that recur
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  bool timed_out_ = false;
  bool told_to_stop_ = false;
  std::map<PartIndex, Instability> falls_;          // the last group each part would have made fall
};

}  // namespace

std::string step_name(const Product& product, const PlanStep& step) {
  const std::string& part = product.parts()[step.part].name;
  if (step.carried.empty()) return part;
  std::vector<std::string> members{part};
  for (PartIndex p : step.carried) members.push_back(product.parts()[p].name);
  return step.subassembly + " (" + join(members) + ")";
}

std::string step_result(const PlanStep& step) {
  std::string out = step.failed.empty() ? "ok" : "ok after " + std::to_string(step.failed.size()) + " collision(s)";
  if (const auto& screw = step.trajectory.screw) {
    char turns[48];
    std::snprintf(turns, sizeof turns, ", screwed %.1f turns", screw->turns);
    out += turns;
  }
  if (step.hold) out += ", held until fastened";
  if (!step.fixture.empty()) out += ", a fixture holds " + std::to_string(step.fixture.size()) + " part(s) from here";
  return out;
}

double least_margin(const std::vector<PlanStep>& steps, double reach) {
  double least = reach;
  for (const PlanStep& s : steps) {
    if (s.margin) least = std::min(least, s.margin->distance);
  }
  return least;
}

namespace {

// The plan replayed on its own (plan_verifier.hpp): a step that fails it makes the plan
// incomplete, with a finding that says what went how deep into what.
void verify(const LoadedProduct& product, Plan& plan, const PlannerOptions& options, const StabilityAnalysis& stability) {
  VerifyOptions check;
  check.analysis = &stability;
  check.contact_tolerance = options.collision.contact_tolerance;
  check.resolution = options.verify_resolution;
  check.gripper = options.gripper;
  check.stability = options.stability;
  check.stand = options.stand;
  const auto start = std::chrono::steady_clock::now();
  const Verification v = verify_plan(product, plan, check);
  plan.verification.run = true;
  plan.verification.passed = v.violations.empty();
  plan.verification.poses = v.poses;
  plan.verification.sweeps = v.sweeps;
  plan.verification.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const Violation& violation : v.violations) {
    std::vector<std::string> parts{product.product.parts()[plan.steps[violation.step - 1].part].name};
    if (!violation.with.empty()) parts.push_back(violation.with);
    plan.findings.push_back({"verification", describe(product.product, violation) + ": the step cannot be built as planned", parts});
  }
  if (!v.violations.empty()) plan.complete = false;
}

// Where no order stands, the order that goes together without gravity, with the steps after
// which something would fall named: a fixture must hold it. Complete only for a cell that has
// fixtures (PlannerOptions::fixtures) and only if every part goes in; a partial plan still
// tells the designer more than one that stopped at the first part that would fall.
Plan plan_with_fixtures(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                        const PlannerOptions& options, const Gravity& stability, double time_limit) {
  PlannerOptions loose = options;
  loose.stability = false;
  loose.time_limit = time_limit;
  Plan plan = Search(product, sequence, path, loose, nullptr).run();
  const auto& connections = product.product.connections();
  std::vector<PlacedPart> placed;
  std::vector<PartIndex> held;  // by fixtures, from the step that needs them on
  std::vector<bool> in(product.product.parts().size(), false);
  for (std::size_t i = 0; i < plan.steps.size(); ++i) {
    const PartIndex part = plan.steps[i].part;
    in[part] = true;
    placed.push_back({part, product.product.parts()[part].final_pose});
    std::vector<bool> fastened(connections.size());
    for (std::size_t c = 0; c < connections.size(); ++c) {
      fastened[c] = connections[c].joint.fastens() && in[connections[c].part1] && in[connections[c].part2];
    }
    if (const auto falls = stability.check(placed, held, fastened, std::nullopt)) {
      plan.steps[i].fixture = falls->parts;
      held.insert(held.end(), falls->parts.begin(), falls->parts.end());
      plan.findings.push_back({"fixture",
                               "step " + std::to_string(i + 1) + " (" + product.product.parts()[part].name +
                                   "): a fixture must hold " + describe(product.product, *falls, options.stand),
                               {product.product.parts()[part].name}});
      continue;
    }
    // Standing once fastened, not before: the arm holds it until then.
    std::vector<bool> before = fastened;
    for (std::size_t c : product.product.connections_of(part)) before[c] = false;
    plan.steps[i].hold = before != fastened && stability.check(placed, held, before, std::nullopt).has_value();
  }
  plan.stability = options.stability;
  // An order that needs no fixture after all stands as it is.
  const bool fixed = std::any_of(plan.steps.begin(), plan.steps.end(), [](const PlanStep& s) { return !s.fixture.empty(); });
  plan.complete = plan.complete && (options.fixtures || !fixed);
  return plan;
}

}  // namespace

Plan plan_assembly(const LoadedProduct& product, SequencePlanner& sequence, PathPlanner& path,
                   const PlannerOptions& options) {
  // One analysis for the search and the replay: contacts between parts are found once.
  const StabilityAnalysis stability(product, options.stand);
  const Gravity& gravity = options.gravity ? *options.gravity : stability;
  Plan plan;
  if (!subassemblies_of(product.product).empty()) {
    if (!options.given.empty()) throw std::logic_error("planning on from given steps of a product with subassemblies");
    plan = plan_with_subassemblies(product, sequence, path, options, stability);
  } else {
    const auto start = std::chrono::steady_clock::now();
    Search search(product, sequence, path, options, &gravity);
    plan = search.run();
    const double left =
        options.time_limit - std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const bool stopped = options.stop && options.stop();
    if (!plan.complete && search.refused_for_gravity() && (options.time_limit <= 0 || left > 0) && !stopped) {
      Plan fixtures = plan_with_fixtures(product, sequence, path, options, gravity, options.time_limit <= 0 ? 0 : left);
      if (fixtures.complete || fixtures.steps.size() > plan.steps.size()) plan = std::move(fixtures);
    }
  }
  plan.stability = options.stability;
  if (options.verify) verify(product, plan, options, stability);
  return plan;
}

}  // namespace twin
