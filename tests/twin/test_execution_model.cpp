// The cell's model of an order's physical assembly (twin/orchestration/execution_model): a
// script timed as the orchestrator runs it, the robot's fetches beside the arm's work.

#include <cmath>
#include <stdexcept>

#include <catch2/catch.hpp>

#include "services/node/gripper.hpp"
#include "twin/orchestration/execution_model.hpp"

namespace {

using fb::Data;
using twin::Pose;
using twin::ScriptAction;

Data fetch(const std::string& id, const std::string& source) {
  return {{"command_id", id}, {"resource_id", std::string("robot")}, {"operation", std::string("fetch")},
          {"source", source}, {"destination", std::string("station")}};
}

Data arm(const std::string& operation, const std::vector<Pose>& path = {}) {
  return {{"command_id", "arm/" + operation}, {"resource_id", std::string("arm")}, {"operation", operation},
          {"path", twin::pose_numbers(path)}};
}

Pose at(double x, double y, double z, double turn = 0) {
  Pose p(Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitY()));
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

// Two parts: the robot (at x 3, 2 m/s) fetches from buffer-a (5 m from the station's dock,
// 4 m from the robot) and buffer-b (2 m); the arm (0.5 m/s, 1 rad/s) carries the first 1 m
// and turns it a quarter, the second 0.5 m.
twin::Script two_parts() {
  return {{ScriptAction::sim, {{"request_id", std::string("s1")}, {"kind", std::string("spawn")}}},
          {ScriptAction::send_heard, fetch("f1", "buffer-a")},
          {ScriptAction::send_heard, fetch("f2", "buffer-b")},
          {ScriptAction::await_delivery, {{"command_id", std::string("f1")}}},
          {ScriptAction::command, arm("grip", {at(0, 0.1, 0)})},
          {ScriptAction::command, arm("translate", {at(1, 0.1, 0), at(1, 0.1, 0, M_PI / 2)})},
          {ScriptAction::command, arm("release")},
          {ScriptAction::await_delivery, {{"command_id", std::string("f2")}}},
          {ScriptAction::command, arm("grip", {at(0, 0.1, 0)})},
          {ScriptAction::command, arm("translate", {at(0, 0.6, 0)})}};
}

twin::ResourceModels models() {
  twin::ResourceModels m;
  m.docks = {{"station", {0, 0, 0}}, {"buffer-a", {3, 0, 4}}, {"buffer-b", {0, 0, 2}}};
  m.robot_at = {3, 0, 0};
  m.robot_speed = 2;
  m.arm_speed = 0.5;
  m.arm_angular_speed = 1;
  return m;
}

}  // namespace

TEST_CASE("execution model: the robot's drives beside the arm's paths, timed as cell-sim moves them", "[twin][quote]") {
  const twin::ModelledRun run = twin::run_script(two_parts(), models(), 0, 0);
  // Deliveries: (4 + 5) / 2 = 4.5 s, then from the station to buffer-b and back, 2 s more.
  REQUIRE(run.delivered.size() == 2);
  CHECK(run.delivered[0] == Approx(4.5));
  CHECK(run.delivered[1] == Approx(6.5));
  CHECK(run.robot_s == Approx(6.5));
  // The arm from the first delivery: 1 m (2 s), a quarter turn (pi/2 s); the second part is
  // there by then; 0.5 m (1 s).
  CHECK(run.start == 0);
  CHECK(run.end == Approx(4.5 + 2 + M_PI / 2 + 1));
}

TEST_CASE("execution model: the station's queue and the robot's hold the work up", "[twin][quote]") {
  const twin::ModelledRun later = twin::run_script(two_parts(), models(), 10, 0);
  CHECK(later.start == 10);
  CHECK(later.end == Approx(10 + 4.5 + 2 + M_PI / 2 + 1));
  // A robot busy until 20: the parts come at 24.5 and 26.5; the arm waits for the first only.
  const twin::ModelledRun busy = twin::run_script(two_parts(), models(), 0, 20);
  CHECK(busy.delivered[0] == Approx(24.5));
  CHECK(busy.delivered[1] == Approx(26.5));
  CHECK(busy.end == Approx(24.5 + 2 + M_PI / 2 + 1));
}

TEST_CASE("execution model: messages cost their wall time times the real-time factor", "[twin][quote]") {
  twin::ResourceModels m = models();
  m.real_time_factor = 20;
  const double request = m.messages.request * 20, command = m.messages.command * 20, fetch = m.messages.fetch * 20;
  const twin::ModelledRun run = twin::run_script(two_parts(), m, 0, 0);
  // The spawn, then each fetch heard (half a command); the robot's work adds the fetch's cost.
  const double first = request + command / 2 + 4.5 + fetch;
  CHECK(run.delivered[0] == Approx(first));
  CHECK(run.delivered[1] == Approx(first + 2 + fetch));
  // Five commands of the arm, each with its cost, after the first delivery.
  CHECK(run.end == Approx(first + 5 * command + 2 + M_PI / 2 + 1));
  // A physical cell (real time) pays its messages in milliseconds.
  m.real_time_factor = 1;
  CHECK(twin::run_script(two_parts(), m, 0, 0).end - twin::run_script(two_parts(), models(), 0, 0).end < 0.05);
}

TEST_CASE("execution model: a fetch from a place without a dock is refused with the place", "[twin][quote]") {
  twin::ResourceModels m = models();
  m.docks.erase("buffer-b");
  CHECK_THROWS_WITH(twin::run_script(two_parts(), m, 0, 0), "no dock known for 'buffer-b'");
}
