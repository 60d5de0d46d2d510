// The cell's durable state: stock that survives a restart, parts that move from place to
// place without ever being lost or counted twice, commands a restarted resource answers, and
// a database that a SIGKILL in the middle of writing leaves whole.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sqlite3.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <random>
#include <thread>

#include "services/state/cell_store.hpp"

namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("agile-cell-store-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  return dir;
}

void require_conserved(const state::CellStore& store) {
  for (const auto& [type, c] : store.inventory()) {
    INFO(type << ": initial " << c.initial << ", in buffers " << c.in_buffers << ", assembled " << c.assembled
              << ", on stations " << c.on_stations << ", in transit " << c.in_transit << ", inspection " << c.inspection);
    REQUIRE(c.initial == c.accounted());
  }
}

}  // namespace

TEST_CASE("a buffer's stock is seeded once, and from then on the stored counts are the truth", "[state]") {
  const fs::path dir = fresh_dir("seed");
  {
    state::CellStore store(dir);
    CHECK(store.open_buffer("buffer-1", {{"Peg", 3}}) == std::map<std::string, int>{{"Peg", 3}});
    store.give("buffer-1", "Peg", "o1", "o1/peg-1", "robot-1");
  }
  state::CellStore again(dir);  // a restarted buffer, its deployment file unchanged
  CHECK(again.open_buffer("buffer-1", {{"Peg", 3}}) == std::map<std::string, int>{{"Peg", 2}});
  CHECK(again.inventory().at("Peg").initial == 3);
  CHECK(again.integrity() == "ok");
}

TEST_CASE("parts a buffer keeps for an order survive its restart, counted down as they are given", "[state]") {
  const fs::path dir = fresh_dir("kept");
  {
    state::CellStore store(dir);
    store.open_buffer("buffer-1", {{"Peg", 5}, {"Hole", 2}});
    store.keep("buffer-1", "o1", "Peg", 2);
    store.keep("buffer-1", "o1", "Peg", 1);  // a second award adds
    store.keep("buffer-1", "o2", "Hole", 1);
    store.give("buffer-1", "Peg", "o1", "o1/peg-1", "robot-1");
  }
  state::CellStore again(dir);
  using Kept = std::map<std::string, std::map<std::string, int>>;
  CHECK(again.kept("buffer-1") == Kept{{"o1", {{"Peg", 2}}}, {"o2", {{"Hole", 1}}}});
  again.give("buffer-1", "Hole", "o2", "o2/hole-1", "robot-1");  // its last kept one: none left to show
  CHECK(again.kept("buffer-1") == Kept{{"o1", {{"Peg", 2}}}});
  again.unkeep("buffer-1", "o1");
  CHECK(again.kept("buffer-1").empty());
  CHECK(again.kept("buffer-2").empty());
}

TEST_CASE("a part moves buffer, robot, station, gripper, product, and is counted once at every step", "[state]") {
  state::CellStore store(fresh_dir("moves"));
  store.open_buffer("buffer-1", {{"Peg", 2}, {"Plate", 1}});
  const auto count = [&](const std::string& type) { return store.inventory().at(type); };

  store.give("buffer-1", "Peg", "o1", "o1/peg", "robot-1");
  CHECK(count("Peg").in_transit == 1);
  CHECK(count("Peg").in_buffers == 1);
  require_conserved(store);
  store.deliver("o1", "o1/peg", "station-1");
  CHECK(count("Peg").on_stations == 1);
  store.grip("o1", {"o1/peg"}, "arm-1");
  CHECK(count("Peg").on_stations == 1);  // in the gripper, at the station
  CHECK(store.parts("o1").front().place == state::Place::in_gripper);
  store.release("o1", {"o1/peg"});
  store.assemble("o1");
  CHECK(count("Peg").assembled == 1);
  CHECK(count("Peg").on_stations == 0);
  require_conserved(store);

  SECTION("a buffer that has none refuses, and nothing changes") {
    store.give("buffer-1", "Plate", "o2", "o2/plate", "robot-1");
    CHECK_THROWS_WITH(store.give("buffer-1", "Plate", "o2", "o2/plate-2", "robot-1"),
                      Catch::Contains("buffer-1 has no Plate"));
    CHECK(store.parts("o2").size() == 1);
    require_conserved(store);
  }
  SECTION("the same part is never handed out twice") {
    CHECK_THROWS_WITH(store.give("buffer-1", "Peg", "o1", "o1/peg", "robot-1"), Catch::Contains("handed out already"));
    CHECK(count("Peg").in_buffers == 1);
  }
  SECTION("a robot that restarts gives its load back; an arm that restarts leaves its part for inspection") {
    store.give("buffer-1", "Peg", "o2", "o2/peg", "robot-1");
    store.give("buffer-1", "Plate", "o2", "o2/plate", "robot-2");
    store.deliver("o2", "o2/plate", "station-1");
    store.grip("o2", {"o2/plate"}, "arm-1");
    const auto returned = store.return_carried("robot-1");
    REQUIRE(returned.size() == 1);
    CHECK(returned.front().part == "o2/peg");
    CHECK(count("Peg").in_buffers == 1);
    const auto held = store.hold_for_inspection("arm-1");
    REQUIRE(held.size() == 1);
    CHECK(count("Plate").inspection == 1);
    require_conserved(store);
    // A part given back may be handed out again under its name.
    store.give("buffer-1", "Peg", "o2", "o2/peg", "robot-1");
    CHECK(count("Peg").in_transit == 1);
    require_conserved(store);
  }
}

TEST_CASE("a subassembly: its parts stand aside under its name, move to the gripper and back together", "[state]") {
  state::CellStore store(fresh_dir("subassembly"));
  store.open_buffer("buffer-1", {{"Shaft", 1}, {"Pendulum", 1}, {"Plate", 1}});
  for (const auto& [type, part] : {std::pair{"Shaft", "o1/shaft"}, {"Pendulum", "o1/pendulum"}, {"Plate", "o1/plate"}}) {
    store.give("buffer-1", type, "o1", part, "robot-1");
    store.deliver("o1", part, "station-1");
  }
  const auto where = [&](const std::string& part) {
    for (const auto& p : store.parts("o1")) {
      if (p.part == part) return std::pair{p.place, p.holder};
    }
    return std::pair{state::Place::returned, std::string("none")};
  };
  // Built aside: placed by the release itself, held by the subassembly's name.
  for (const char* part : {"o1/shaft", "o1/pendulum"}) {
    store.grip("o1", {part}, "arm-1");
    store.release("o1", {part}, "aside:ShaftPendulum");
    CHECK(where(part) == std::pair{state::Place::placed, std::string("ShaftPendulum")});
  }
  store.grip("o1", {"o1/plate"}, "arm-1");
  store.release("o1", {"o1/plate"});  // into nothing named: it stands on the station
  CHECK(where("o1/plate") == std::pair{state::Place::on_station, std::string()});
  store.grip("o1", {"o1/plate"}, "arm-1");
  store.release("o1", {"o1/plate"}, "product");
  // A part standing in the product is not gripped again (the journal says so).
  store.grip("o1", {"o1/plate"}, "arm-1");
  CHECK(where("o1/plate") == std::pair{state::Place::placed, std::string()});
  CHECK(store.count_events("arm-1", "unexpected in_gripper") == 1);
  // The subassembly gripped by its base, the other carried: both in the gripper at once.
  store.grip("o1", {"o1/shaft", "o1/pendulum"}, "arm-1");
  CHECK(where("o1/shaft") == std::pair{state::Place::in_gripper, std::string("arm-1")});
  CHECK(where("o1/pendulum") == std::pair{state::Place::in_gripper, std::string("arm-1")});
  require_conserved(store);
  SECTION("inserted: released and placed in the product together") {
    store.release("o1", {"o1/shaft", "o1/pendulum"}, "product");
    CHECK(where("o1/pendulum") == std::pair{state::Place::placed, std::string()});
    store.assemble("o1");
    CHECK(store.inventory().at("Pendulum").assembled == 1);
  }
  SECTION("the arm restarts under it: the whole subassembly goes to inspection") {
    CHECK(store.hold_for_inspection("arm-1").size() == 2);
    CHECK(store.inventory().at("Shaft").inspection == 1);
    CHECK(store.inventory().at("Pendulum").inspection == 1);
  }
  require_conserved(store);
}

TEST_CASE("an order's plan is stored whole and replaced whole, and kept across a reopening", "[state]") {
  const auto dir = fresh_dir("plan");
  {
    state::CellStore store(dir);
    CHECK(store.plan_of("o1").empty());
    store.set_plan("o1", {{"back", "down"}, {"shaft", "down"}, {"ShaftPendulum", "down"}});
    store.set_plan("o2", {{"b1", "down"}});
    store.set_plan("o1", {{"back", "down"}, {"shaft", "from +x"}});
  }
  state::CellStore again(dir);
  CHECK(again.plan_of("o1") == std::vector<state::PlanStepRecord>{{"back", "down"}, {"shaft", "from +x"}});
  CHECK(again.plan_of("o2") == std::vector<state::PlanStepRecord>{{"b1", "down"}});
}

TEST_CASE("a cancel is asked of an order that has not ended, and says who asked, and an older database gets the column",
          "[state]") {
  const auto dir = fresh_dir("cancel");
  {
    // A database of a cell from before cancels: its orders table without the column.
    fs::create_directories(dir);
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open(state::CellStore::file_in(dir).c_str(), &db) == SQLITE_OK);
    REQUIRE(sqlite3_exec(db, "CREATE TABLE orders(order_id TEXT PRIMARY KEY, state TEXT NOT NULL, reason TEXT NOT NULL DEFAULT '', "
                             "updated REAL, product TEXT NOT NULL DEFAULT '', out_dir TEXT NOT NULL DEFAULT '', "
                             "sequence TEXT NOT NULL DEFAULT '', path_planner TEXT NOT NULL DEFAULT '', exit_code INTEGER, "
                             "attempts INTEGER NOT NULL DEFAULT 0); "
                             "INSERT INTO orders(order_id, state) VALUES('old', 'QUEUED')",
                         nullptr, nullptr, nullptr) == SQLITE_OK);
    sqlite3_close(db);
  }
  state::CellStore store(dir);
  CHECK(store.cancel_requested("old").empty());
  CHECK(store.request_cancel("old", "the operator (cellctl)"));
  CHECK(store.cancel_requested("old") == "the operator (cellctl)");
  CHECK_FALSE(store.request_cancel("nope", "the operator (cellctl)"));
  REQUIRE(store.submit_order({"done", "", "", "p.aml", "out", "search", "linear"}));
  store.set_order("done", "DONE", "", 0);
  CHECK_FALSE(store.request_cancel("done", "the operator (dashboard)"));
  CHECK(store.cancel_requested("done").empty());
  const auto orders = store.orders();
  REQUIRE(orders.size() == 2);
  CHECK(orders[0].cancelled_by == "the operator (cellctl)");
  CHECK(orders[1].cancelled_by.empty());
}

TEST_CASE("a resource out of service stays so, with why and who, across a reopening, until it is put back", "[state]") {
  const auto dir = fresh_dir("service");
  {
    state::CellStore store(dir);
    CHECK(store.out_of_service().empty());
    store.set_out_of_service("arm-1", "gripper worn", "the operator (cellctl)");
    store.set_out_of_service("rack-a", "restocking", "the operator (dashboard)");
    store.set_out_of_service("arm-1", "gripper replaced, calibrating", "the operator (dashboard)");
  }
  state::CellStore store(dir);
  auto out = store.out_of_service();
  REQUIRE(out.size() == 2);
  CHECK(out["arm-1"].reason == "gripper replaced, calibrating");
  CHECK(out["arm-1"].by == "the operator (dashboard)");
  CHECK(out["arm-1"].since > 0);
  CHECK(out["rack-a"].reason == "restocking");
  store.set_out_of_service("arm-1", "", "the operator (cellctl)");
  out = store.out_of_service();
  CHECK(out.size() == 1);
  CHECK(out.count("rack-a") == 1);
}

TEST_CASE("the commands a resource had taken on are answered once by the process after it", "[state]") {
  state::CellStore store(fresh_dir("commands"));
  store.command_taken({"robot-1", "o1/c1", "o1", "fetch", "o1/peg"});
  store.command_taken({"robot-1", "o1/c2", "o1", "fetch", "o1/plate"});
  store.command_taken({"arm-1", "o1/c3", "o1", "grip", "o1/peg"});
  store.command_ended("robot-1", "o1/c1");
  const auto interrupted = store.take_interrupted("robot-1");
  REQUIRE(interrupted.size() == 1);
  CHECK(interrupted.front().command_id == "o1/c2");
  CHECK(store.take_interrupted("robot-1").empty());
  CHECK(store.take_interrupted("arm-1").size() == 1);
}

TEST_CASE("a give counted out whose command was never answered goes back to the buffer", "[state]") {
  state::CellStore store(fresh_dir("unanswered"));
  store.open_buffer("buffer-1", {{"Peg", 3}});
  store.keep("buffer-1", "o1", "Peg", 2);
  // Answered: counted out, its command ended. Unanswered: the process died between the two.
  store.command_taken({"buffer-1", "o1/g1", "o1", "give", "o1/peg-1"});
  store.give("buffer-1", "Peg", "o1", "o1/peg-1", "robot-1");
  store.command_ended("buffer-1", "o1/g1");
  store.command_taken({"buffer-1", "o1/g2", "o1", "give", "o1/peg-2"});
  store.give("buffer-1", "Peg", "o1", "o1/peg-2", "robot-2");
  // A robot's fetch of the same part, still open, is not a give.
  store.command_taken({"robot-1", "o1/f1", "o1", "fetch", "o1/peg-1"});
  CHECK(store.given("buffer-1", "o1", "o1/peg-2", "robot-2"));
  CHECK_FALSE(store.given("buffer-1", "o1", "o1/peg-2", "robot-1"));  // not to that robot

  const auto undone = store.undo_unanswered_gives("buffer-1");
  REQUIRE(undone.size() == 1);
  CHECK(undone.front().part == "o1/peg-2");
  CHECK(undone.front().holder == "robot-2");
  CHECK(store.inventory().at("Peg").in_buffers == 2);
  CHECK(store.inventory().at("Peg").in_transit == 1);  // o1/peg-1, answered, is on its way
  CHECK(store.kept("buffer-1").at("o1").at("Peg") == 1);  // kept for the order again
  CHECK_FALSE(store.given("buffer-1", "o1", "o1/peg-2", "robot-2"));
  require_conserved(store);
  CHECK(store.undo_unanswered_gives("buffer-1").empty());  // once
  // The command itself is still the restarted buffer's to answer (ABORTED), and the part may
  // be given again under its name.
  CHECK(store.take_interrupted("buffer-1").size() == 1);
  store.give("buffer-1", "Peg", "o1", "o1/peg-2", "robot-2");
  require_conserved(store);
}

TEST_CASE("an undone give that took a part from the free stock keeps none for its order", "[state]") {
  state::CellStore store(fresh_dir("unanswered-free"));
  store.open_buffer("buffer-1", {{"Peg", 3}});
  store.keep("buffer-1", "o1", "Peg", 1);
  store.command_taken({"buffer-1", "o1/g1", "o1", "give", "o1/peg-1"});
  store.give("buffer-1", "Peg", "o1", "o1/peg-1", "robot-1");  // the kept one
  store.command_ended("buffer-1", "o1/g1");
  store.command_taken({"buffer-1", "o1/g2", "o1", "give", "o1/peg-2"});
  store.give("buffer-1", "Peg", "o1", "o1/peg-2", "robot-1");  // nothing kept left: a free one
  REQUIRE(store.undo_unanswered_gives("buffer-1").size() == 1);
  CHECK(store.inventory().at("Peg").in_buffers == 2);
  CHECK(store.kept("buffer-1").count("o1") == 0);  // back in the free stock, not kept for o1
  require_conserved(store);
}

TEST_CASE("a database of an earlier version gets the later columns and is used as it stands", "[state]") {
  const fs::path dir = fresh_dir("earlier");
  fs::create_directories(dir);
  sqlite3* db = nullptr;
  REQUIRE(sqlite3_open(state::CellStore::file_in(dir).c_str(), &db) == SQLITE_OK);
  // The tables as 2026-11 wrote them: parts without from_kept, orders without quote.
  REQUIRE(sqlite3_exec(db, R"sql(
    CREATE TABLE parts(order_id TEXT NOT NULL, part TEXT NOT NULL, part_type TEXT NOT NULL, buffer TEXT NOT NULL,
      place TEXT NOT NULL, holder TEXT NOT NULL DEFAULT '', station TEXT NOT NULL DEFAULT '', PRIMARY KEY(order_id, part));
    CREATE TABLE orders(order_id TEXT PRIMARY KEY, state TEXT NOT NULL, reason TEXT NOT NULL DEFAULT '', updated REAL,
      product TEXT NOT NULL DEFAULT '', out_dir TEXT NOT NULL DEFAULT '', sequence TEXT NOT NULL DEFAULT '',
      path_planner TEXT NOT NULL DEFAULT '', exit_code INTEGER, attempts INTEGER NOT NULL DEFAULT 0);
    INSERT INTO parts VALUES('o0', 'o0/peg-1', 'Peg', 'buffer-1', 'assembled', '', 'station-1');
    INSERT INTO parts VALUES('o2', 'o2/peg-1', 'Peg', 'buffer-1', 'in_transit', 'robot-1', '');
  )sql", nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(db);
  state::CellStore store(dir);
  store.open_buffer("buffer-1", {{"Peg", 3}});
  store.keep("buffer-1", "o1", "Peg", 1);
  store.command_taken({"buffer-1", "o1/g1", "o1", "give", "o1/peg-1"});
  store.give("buffer-1", "Peg", "o1", "o1/peg-1", "robot-1");
  // A give under way at the upgrade: undone as the earlier version did, kept for its order.
  store.keep("buffer-1", "o2", "Peg", 0);  // its award's row, counted down by that give
  store.command_taken({"buffer-1", "o2/g1", "o2", "give", "o2/peg-1"});
  REQUIRE(store.undo_unanswered_gives("buffer-1").size() == 2);
  CHECK(store.kept("buffer-1").at("o1").at("Peg") == 1);
  CHECK(store.kept("buffer-1").at("o2").at("Peg") == 1);
  CHECK(store.inventory().at("Peg").assembled == 1);  // the earlier row stands
  REQUIRE(sqlite3_open(state::CellStore::file_in(dir).c_str(), &db) == SQLITE_OK);
  int columns = 0;
  REQUIRE(sqlite3_exec(db, "SELECT name FROM pragma_table_info('parts') WHERE name = 'from_kept' UNION ALL "
                           "SELECT name FROM pragma_table_info('orders') WHERE name IN ('quote', 'client', 'request')",
                       [](void* n, int, char**, char**) { return ++*static_cast<int*>(n), 0; }, &columns, nullptr) == SQLITE_OK);
  sqlite3_close(db);
  CHECK(columns == 4);
}

TEST_CASE("orders come back in the order they came, with a remote order's client and request", "[state]") {
  state::CellStore store(fresh_dir("arrival"));
  for (const char* id : {"zeta", "alpha", "mid"}) REQUIRE(store.submit_order({id, "", "", "p.aml", "out", "search", "linear"}));
  state::OrderRecord remote{"oem-a-x", "", "", "p.aml", "out", "search", "linear"};
  remote.client = "oem-a";
  remote.request = "r-17";
  REQUIRE(store.submit_order(remote));
  store.set_order("alpha", "QUEUED");  // a change keeps its place
  std::vector<std::string> ids;
  for (const auto& o : store.orders()) ids.push_back(o.order);
  CHECK(ids == std::vector<std::string>{"zeta", "alpha", "mid", "oem-a-x"});
  const auto orders = store.orders();
  CHECK(orders[0].arrival < orders[1].arrival);
  CHECK(orders[3].client == "oem-a");
  CHECK(orders[3].request == "r-17");
  CHECK(orders[0].client.empty());
}

TEST_CASE("bookings, orders and the journal", "[state]") {
  state::CellStore store(fresh_dir("holds"));
  store.set_bookings("station-1", {{"o1", {"o1/host"}, 40, true}, {"o2", {"o2/host", "o2/host-2"}, 30, false}});
  store.set_bookings("arm-1", {{"o1", {"o1/arm"}, 40, true}});
  store.set_bookings("arm-1", {});
  store.set_bookings("robot-1", {{"o1", {"o1/fetch"}, 0, false}});
  CHECK(store.holders() == std::map<std::string, std::string>{{"station-1", "o1"}});
  const auto station = store.bookings("station-1");
  REQUIRE(station.size() == 2);
  CHECK(station[1].order == "o2");
  CHECK(station[1].calls == std::vector<std::string>{"o2/host", "o2/host-2"});
  CHECK(station[1].duration == 30);
  CHECK_FALSE(station[1].holds);
  store.set_order("o1", "PLANNING");
  store.set_order("o1", "FAILED", "arm-1 restarted");
  REQUIRE(store.orders().size() == 1);
  CHECK(store.orders().front().reason == "arm-1 restarted");
  store.journal("buffer-1", "restarted");
  store.journal("buffer-1", "restarted");
  CHECK(store.count_events("buffer-1", "restarted") == 2);
  CHECK(store.journal_since(1).size() == 1);
}

// Writers in other processes, killed with SIGKILL at random moments while they give parts:
// every give either happened whole (the stock one less and the part in transit) or not at all.
TEST_CASE("SIGKILL in the middle of writing loses nothing committed and corrupts nothing", "[state][processes]") {
  const fs::path dir = fresh_dir("crash");
  constexpr int kStock = 100000;
  state::CellStore(dir).open_buffer("buffer-1", {{"Peg", kStock}});
  std::mt19937 random(7);
  int part = 0;
  for (int round = 0; round < 12; ++round) {
    std::vector<pid_t> writers;
    for (int w = 0; w < 2; ++w) {
      const int first = (part += 100000);
      const pid_t pid = ::fork();
      REQUIRE(pid >= 0);
      if (pid == 0) {
        try {
          state::CellStore store(dir);
          for (int i = first;; ++i) store.give("buffer-1", "Peg", "o", "p" + std::to_string(i), "robot-1");
        } catch (...) {
          ::_exit(1);
        }
      }
      writers.push_back(pid);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20 + random() % 80));
    for (pid_t pid : writers) {
      ::kill(pid, SIGKILL);
      int status = 0;
      ::waitpid(pid, &status, 0);
      CHECK(WIFSIGNALED(status));  // killed while writing, not ended by an error
    }
  }
  state::CellStore store(dir);
  CHECK(store.integrity() == "ok");
  const auto peg = store.inventory().at("Peg");
  INFO("gives committed: " << peg.in_transit);
  CHECK(peg.in_transit > 0);
  CHECK(peg.in_transit == static_cast<int>(store.parts("o").size()));
  CHECK(peg.initial == peg.accounted());
}

TEST_CASE("a process opens a database that has the schema while another holds the write lock", "[state]") {
  const fs::path dir = fresh_dir("opened-while-written");
  { state::CellStore first(dir); }  // makes the schema
  sqlite3* writer = nullptr;
  REQUIRE(sqlite3_open(state::CellStore::file_in(dir).c_str(), &writer) == SQLITE_OK);
  REQUIRE(sqlite3_exec(writer, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr) == SQLITE_OK);
  // Reads only: it neither waits for the lock nor fails (it waited 10 s and failed before).
  std::unique_ptr<state::CellStore> second;
  CHECK_NOTHROW(second = std::make_unique<state::CellStore>(dir));
  if (second) CHECK(second->orders().empty());
  sqlite3_exec(writer, "ROLLBACK", nullptr, nullptr, nullptr);
  sqlite3_close(writer);
}

// The desk starts the next order once it reads that one ended; the journal must say so by
// then, or it shows more orders under way than max_twins (the order-queue test saw 3 of 2).
TEST_CASE("an order's change and its journal line are seen together by a reader in another connection", "[state]") {
  const fs::path dir = fresh_dir("change-and-line");
  state::CellStore store(dir);
  constexpr int kOrders = 400;
  std::thread writer([&store] {
    for (int i = 0; i < kOrders; ++i) store.set_order("o" + std::to_string(i), "DONE", "", 0, {"twin", "DONE", ""});
  });
  sqlite3* reader = nullptr;
  REQUIRE(sqlite3_open(state::CellStore::file_in(dir).c_str(), &reader) == SQLITE_OK);
  sqlite3_busy_timeout(reader, 5000);
  // One snapshot: orders that ended without their line (0 when every change came with it).
  const auto unjournaled = [reader] {
    sqlite3_exec(reader, "BEGIN", nullptr, nullptr, nullptr);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(reader,
                       "SELECT COUNT(*) FROM orders WHERE state = 'DONE' AND order_id NOT IN "
                       "(SELECT order_id FROM journal WHERE event = 'DONE')",
                       -1, &s, nullptr);
    const int n = sqlite3_step(s) == SQLITE_ROW ? sqlite3_column_int(s, 0) : -1;
    sqlite3_finalize(s);
    sqlite3_exec(reader, "COMMIT", nullptr, nullptr, nullptr);
    return n;
  };
  int snapshots = 0, torn = 0;
  while (store.orders().size() < kOrders) {
    ++snapshots;
    if (unjournaled() != 0) ++torn;
  }
  writer.join();
  sqlite3_close(reader);
  INFO(snapshots << " snapshots");
  CHECK(torn == 0);
  CHECK(store.journal_since(0).size() == kOrders);
}
