// The twin's orchestration block driven with events and no DDS: a stand-in cell answers every
// cell-sim request and command, and refuses what the test says.

#include <functional>

#include <catch2/catch.hpp>

#include "services/runtime/block_test_fixture.hpp"
#include "twin/geometry/product_loader.hpp"
#include "twin/orchestration/order_orchestrator.hpp"

namespace {

using fb::Data;
using fb::get;

struct Outcome {
  std::vector<std::string> findings;  // kinds
  std::vector<std::string> canceled;  // command ids
  std::vector<std::string> spawned;   // bodies, in order
  bool finished = false, complete = false;
  std::string error;
};

// Runs an order against a cell that answers everything at once; `refuse(command)` returns a
// reason to abort a command with (empty: it succeeds; kNoAnswer: it is never answered).
const std::string kNoAnswer = "(no answer)";
Outcome run(fb::BlockTestFixture<twin::OrderOrchestrator>& f, const std::function<std::string(const Data&)>& refuse) {
  Outcome out;
  for (const char* id : {"station-1", "arm-1", "mobile-robot-1", "buffer-1"}) {
    f.send("CAPABILITY", {{"resource_id", std::string(id)}, {"dock", fb::Numbers{0.6, 0, 0}},
                          {"position", fb::Numbers{0, 0, 0}}});
  }
  std::vector<fb::Event> pending = f.send("START");
  for (int guard = 0; !pending.empty() && guard < 100000; ++guard) {
    const fb::Event e = pending.front();
    pending.erase(pending.begin());
    std::vector<fb::Event> more;
    if (e.name == "CFP") {
      const std::string& op = get<std::string>(e.data, "operation");
      const std::string resource = op == "host" ? "station-1" : op == "translate" ? "arm-1"
                                 : op == "fetch" ? "mobile-robot-1" : "buffer-1";
      more = f.send("PROPOSAL", {{"call_id", e.data.at("call_id")}, {"resource_id", resource}});
    } else if (e.name == "AWARD") {
      more = f.send("AWARD_REPLY", {{"call_id", e.data.at("call_id")}, {"resource_id", e.data.at("resource_id")},
                                    {"confirmed", true}, {"reason", std::string()}});
    } else if (e.name == "SIM") {
      if (get<std::string>(e.data, "kind") == "spawn") out.spawned.push_back(get<std::string>(e.data, "body_id"));
      more = f.send("SIM_REPLY", {{"request_id", e.data.at("request_id")}, {"ok", true}, {"error", std::string()},
                                  {"collided", false}});
    } else if (e.name == "COMMAND") {
      const std::string reason = refuse(e.data);
      if (reason == kNoAnswer) continue;
      more = f.send("COMMAND_EVENT", {{"command_id", e.data.at("command_id")}, {"order_id", e.data.at("order_id")},
                                      {"state", std::string(reason.empty() ? "succeeded" : "aborted")},
                                      {"reason", reason}});
    } else if (e.name == "CANCEL") {
      out.canceled.push_back(get<std::string>(e.data, "command_id"));
    } else if (e.name == "FINDING") {
      out.findings.push_back(get<std::string>(e.data, "kind"));
    } else if (e.name == "FINISHED") {
      out.finished = true;
      out.complete = get<bool>(e.data, "complete");
      out.error = get<std::string>(e.data, "error");
    }
    pending.insert(pending.end(), more.begin(), more.end());
  }
  return out;
}

// A product from deploy/products, planned (search, linear) as the twin plans it.
struct Planned {
  explicit Planned(const std::string& product_file)
      : product(twin::load_product(std::string(PRODUCTS_DIR) + "/" + product_file, meshes)),
        plan(plan_of(product)) {}
  static twin::Plan plan_of(const twin::LoadedProduct& product) {
    twin::SearchSequencePlanner sequence;
    return twin::plan_assembly(product, sequence, *twin::make_path_planner("linear"));
  }
  static twin::OrderSettings order_o1() {
    twin::OrderSettings settings;
    settings.order_id = "o1";
    return settings;
  }
  sim::MeshCache meshes;
  twin::LoadedProduct product;
  twin::Plan plan;
};

}  // namespace

TEST_CASE("orchestrator: no path in cell-sim for a part sends it back to sequence planning", "[twin][orchestration]") {
  const Planned cranfield("cranfield/cranfield.aml");
  const twin::Plan& plan = cranfield.plan;
  REQUIRE(plan.complete);
  const std::string second = "o1/virtual/" + cranfield.product.product.parts()[plan.steps[1].part].name;
  fb::BlockTestFixture<twin::OrderOrchestrator> f("twin", cranfield.product, plan, Planned::order_o1());

  // cell-sim refuses every move of the plan's second part while it would be second.
  int connected = 0;
  const Outcome out = run(f, [&](const Data& c) -> std::string {
    const std::string& op = get<std::string>(c, "operation");
    if (op == "connect" && get<std::string>(c, "part").find("/virtual/") != std::string::npos) ++connected;
    if (op == "translate" && get<std::string>(c, "part") == second && connected == 1) return "collision of it";
    return "";
  });
  INFO(out.error);
  CHECK(out.finished);
  CHECK(out.complete);
  // Every trajectory the planner had for it was tried in cell-sim first.
  CHECK(std::count(out.findings.begin(), out.findings.end(), "collision") ==
        static_cast<long>(plan.steps[1].failed.size() + 1));
  CHECK(std::count(out.findings.begin(), out.findings.end(), "backtrack") == 1);
  // The part came later instead; the rest of the plan is complete and validated.
  const auto& steps = f.block().plan().steps;
  REQUIRE(steps.size() == plan.steps.size());
  CHECK(steps[0].part == plan.steps[0].part);
  CHECK(steps[1].part != plan.steps[1].part);
  CHECK(std::find(out.spawned.begin(), out.spawned.end(), second) != out.spawned.end());
}

TEST_CASE("orchestrator: a part that fits nowhere in cell-sim fails the order, with the reason", "[twin][orchestration]") {
  const Planned lego("lego-tower/lego-tower.aml");
  const twin::Plan& plan = lego.plan;
  fb::BlockTestFixture<twin::OrderOrchestrator> f("twin", lego.product, plan, Planned::order_o1());
  const Outcome out = run(f, [](const Data& c) -> std::string {
    return get<std::string>(c, "operation") == "translate" && get<std::string>(c, "part") == "o1/virtual/hanging"
               ? "collision of it" : "";
  });
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error.find("no collision-free path in cell-sim for hanging") != std::string::npos);
  // What it had spawned left cell-sim again.
  CHECK(f.block().state() == "ENDED");
}

TEST_CASE("orchestrator: a failure in physical assembly cancels the fetches not yet delivered", "[twin][orchestration]") {
  const Planned lego("lego-tower/lego-tower.aml");
  const twin::Plan& plan = lego.plan;
  fb::BlockTestFixture<twin::OrderOrchestrator> f("twin", lego.product, plan, Planned::order_o1());
  // The robot delivers the first two parts; the arm cannot grip the second.
  int fetches = 0, physical_grips = 0;
  std::vector<std::string> unanswered;
  const Outcome out = run(f, [&](const Data& c) -> std::string {
    const std::string& op = get<std::string>(c, "operation");
    if (op == "fetch" && ++fetches > 2) {
      unanswered.push_back(get<std::string>(c, "command_id"));
      return kNoAnswer;
    }
    const bool physical = get<std::string>(c, "part").find("/virtual/") == std::string::npos;
    if (op == "grip" && physical && ++physical_grips == 2) return "gripper jammed";
    return "";
  });
  CHECK(out.finished);
  CHECK_FALSE(out.complete);
  CHECK(out.error.find("gripper jammed") != std::string::npos);
  CHECK(out.canceled == unanswered);
  CHECK(unanswered.size() == plan.steps.size() - 2);
}
