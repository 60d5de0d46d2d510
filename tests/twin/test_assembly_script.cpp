// An order's physical assembly as a script (twin/orchestration/assembly_script), built without
// events: what the orchestrator sends and a quote times.

#include <algorithm>

#include <catch2/catch.hpp>

#include "services/node/gripper.hpp"
#include "tests/twin/test_support.hpp"
#include "twin/orchestration/assembly_script.hpp"

namespace {

using fb::Data;
using fb::get;
using twin::ScriptAction;

struct Built {
  twin::PhysicalScript script;
  std::vector<std::string> operations;  // "fetch", "await", "grip", ... in order
};

// Cranfield at a station away from the cell's origin (at z 2), its buffer at x 2.
Built build(const test::Planned& planned, const twin::Resume& resume = {}) {
  twin::Hired hired{"o1", "station-1", "arm-1", "robot-1", {}, {}};
  hired.places["station-1"] = {{0, 0, 2}, {0.6, 0, 2}};
  hired.places["buffer-1"] = {{2, 0, 0}, {1.6, 0, 0}};
  for (const auto& part : planned.product.product.parts()) hired.buffer_of[twin::short_type_name(part.type)] = "buffer-1";
  const twin::CarryGeometry geometry(planned.product, planned.plan);
  fb::SimRequests sim("o1");
  std::size_t count = 0;
  Built b;
  b.script = twin::physical_script(planned.product, planned.plan, geometry, hired, resume, sim,
                                   [&count](const std::string& resource, const std::string& operation, const std::string& part) {
                                     return Data{{"command_id", "o1/" + std::to_string(++count) + "/" + operation},
                                                 {"resource_id", resource}, {"operation", operation}, {"part", part}};
                                   });
  for (const auto& a : b.script.actions) {
    b.operations.push_back(a.kind == ScriptAction::sim              ? get<std::string>(a.data, "kind")
                           : a.kind == ScriptAction::await_delivery ? "await"
                                                                     : get<std::string>(a.data, "operation"));
  }
  return b;
}

}  // namespace

TEST_CASE("assembly script: parts spawned at the buffer, fetched in planned order, each gripped at the dock, carried, "
          "released, backed out of, connected",
          "[twin][script]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  const auto& steps = cranfield.plan.steps;
  const Built b = build(cranfield);
  const auto& actions = b.script.actions;
  const std::size_t n = steps.size();
  REQUIRE(std::count(b.operations.begin(), b.operations.end(), "spawn") == static_cast<long>(n));
  REQUIRE(std::count(b.operations.begin(), b.operations.end(), "fetch") == static_cast<long>(n));
  CHECK(b.script.placed_by.size() == n);
  CHECK(b.script.spawned.size() == n);

  std::vector<std::string> fetched;
  for (const auto& a : actions) {
    if (a.kind == ScriptAction::sim) {  // at the buffer's dock
      const auto at = fb::numbers_pose(get<fb::Numbers>(a.data, "placement"));
      CHECK(at.translation().x() == Approx(1.6));
      CHECK(at.translation().z() == Approx(0).margin(1e-9));
    }
    if (a.kind != ScriptAction::send_heard) continue;
    CHECK(get<std::string>(a.data, "source") == "buffer-1");
    CHECK(get<std::string>(a.data, "destination") == "station-1");
    CHECK(get<std::string>(a.data, "resource_id") == "robot-1");
    fetched.push_back(get<std::string>(a.data, "part"));
  }
  for (std::size_t i = 0; i < n; ++i) CHECK(fetched[i] == "o1/" + cranfield.product.product.parts()[steps[i].part].name);

  // After the fetches, per step: await its part, grip, carry, release, back out, connect.
  const auto first_await = std::find(b.operations.begin(), b.operations.end(), "await") - b.operations.begin();
  CHECK(static_cast<std::size_t>(first_await) == 2 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const auto from = b.operations.begin() + first_await + 6 * k;
    CAPTURE(k);
    CHECK(std::vector<std::string>(from, from + 2) == std::vector<std::string>{"await", "grip"});
    CHECK((from[2] == "translate" || from[2] == "rotate"));
    // A part that stands only once fastened is connected while the gripper still holds it.
    const std::vector<std::string> then = steps[k].hold ? std::vector<std::string>{"connect", "release", "translate"}
                                                        : std::vector<std::string>{"release", "translate", "connect"};
    CHECK(std::vector<std::string>(from + 3, from + 6) == then);
  }
  // Every pose the arm is sent to is at its station (a table 1 m across at z 2), not at the
  // cell's origin, where the product's frame would put it.
  for (const auto& a : actions) {
    if (a.kind != ScriptAction::command || !a.data.count("path")) continue;
    const auto& path = get<fb::Numbers>(a.data, "path");
    for (std::size_t i = 0; i + 7 <= path.size(); i += 7) {
      const auto pose = fb::numbers_pose(fb::Numbers(path.begin() + i, path.begin() + i + 7));
      CHECK(std::abs(pose.translation().z() - 2) < 0.6);
      CHECK(std::abs(pose.translation().x()) < 0.75);
    }
  }
}

TEST_CASE("assembly script: a part the cell's state has in place is spawned there, not fetched nor assembled again",
          "[twin][script]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  const std::string first = "o1/" + cranfield.product.product.parts()[cranfield.plan.steps.front().part].name;
  twin::Resume resume;
  resume.attempt = 2;
  resume.station = "station-1";
  resume.placed = {first};
  resume.used = {first};
  const Built b = build(cranfield, resume);
  const std::size_t n = cranfield.plan.steps.size();
  CHECK(std::count(b.operations.begin(), b.operations.end(), "fetch") == static_cast<long>(n - 1));
  CHECK(b.script.placed_by.size() == n - 1);
  const auto& spawn = b.script.actions.front();
  CHECK(get<std::string>(spawn.data, "body_id") == first);
  CHECK(get<bool>(spawn.data, "is_static"));
}
