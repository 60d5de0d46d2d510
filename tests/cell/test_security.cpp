// DDS-Security on a cell (docs/security.md): `cellctl pki init` makes the files, a cell that
// uses them assembles orders, and participants without the cell's certificates, or with the
// wrong ones, get nothing and do nothing. Every process is ended by its id; every wait is
// bounded; loopback only, on domains of their own.

#include <sys/stat.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <regex>
#include <set>

#include <catch2/catch.hpp>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include "capabilitiesPubSubTypes.h"
#include "commandsPubSubTypes.h"
#include "deploy/cellctl/file_transfer.hpp"
#include "deskPubSubTypes.h"
#include "ordersPubSubTypes.h"
#include "services/dds/endpoints.hpp"
#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

unsigned mode_of(const fs::path& p) {
  struct stat st {};
  REQUIRE(::stat(p.c_str(), &st) == 0);
  return st.st_mode & 0777;
}

// The resources whose capability a participant sees.
class Sightings {
 public:
  Sightings(const dds::ParticipantPtr& participant)
      : reader_(participant, "cell/capabilities", dds::TopicKind::state, [this](const cell::Capability& c) {
          std::lock_guard<std::mutex> lock(mutex_);
          seen_.insert(c.resource_id().to_string());
          for (const auto& s : c.stock()) part_types_.insert(s.part_type().to_string());
        }) {}
  std::set<std::string> seen() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return seen_;
  }
  bool saw_part_type(const std::string& type) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return part_types_.count(type) > 0;
  }
  bool wait_for(const std::vector<std::string>& ids, std::chrono::seconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      const auto s = seen();
      if (std::all_of(ids.begin(), ids.end(), [&](const std::string& id) { return s.count(id) > 0; })) return true;
      std::this_thread::sleep_for(50ms);
    }
    return false;
  }

 private:
  mutable std::mutex mutex_;
  std::set<std::string> seen_, part_types_;
  dds::Reader<cell::Capability, cell::CapabilityPubSubType> reader_;
};

// A buffer process with `args` after its domain; its exit code within 20 s (-1: still running).
int buffer_exit(const std::string& domain, std::vector<std::string> args, const fs::path& log) {
  args.insert(args.begin(), {BUFFER_EXE, "--domain", domain});
  test::ChildProcess p(args, log.string());
  return p.wait_for_exit(20s);
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

}  // namespace

TEST_CASE("pki init: a CA, the governance, and per identity a key only its owner reads, a certificate and permissions by role",
          "[process][security]") {
  const fs::path dir = test::scratch("pki-init");
  const fs::path pki = dir / "pki";
  REQUIRE(test::cellctl({"pki", "init", pki.string(), "--domain", domains::text(domains::kPki)}, dir / "init.log") == 0);
  INFO(test::read_text(dir / "init.log"));
  CHECK(mode_of(pki) == 0700);
  CHECK(mode_of(pki / "ca.key.pem") == 0600);
  CHECK(fs::exists(pki / "ca.cert.pem"));
  CHECK(test::read_text(pki / "governance.p7s").find("application/x-pkcs7-signature") != std::string::npos);
  for (const std::string id : {"cell-sim", "station-1", "mobile-robot-1", "buffer-1", "buffer-2", "twin-1", "twin-10", "cellctl"}) {
    INFO(id);
    const fs::path own = pki / "identities" / id;
    CHECK(mode_of(own) == 0700);
    CHECK(mode_of(own / "key.pem") == 0600);
    CHECK(fs::exists(own / "cert.pem"));
    CHECK(test::read_text(own / "permissions.p7s").find("<subject_name>CN=" + id + "</subject_name>") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(pki / "identities" / "twin-11"));  // the default cell's twin_identities: 10
  // By role: a buffer reads its own commands only and commands nobody; a twin commands the arm
  // and the robot but publishes no capability, each twin in its own partition; cellctl binds
  // twins to orders and only reads besides.
  const auto permissions = [&](const std::string& id) { return test::read_text(pki / "identities" / id / "permissions.xml"); };
  const auto section = [](const std::string& xml, const std::string& tag) {  // every one of them
    std::string all;
    for (auto from = xml.find("<" + tag + ">"); from != std::string::npos; from = xml.find("<" + tag + ">", from + 1)) {
      all += xml.substr(from, xml.find("</" + tag + ">", from) - from);
    }
    return all;
  };
  CHECK(section(permissions("buffer-1"), "subscribe").find("cell/commands/buffer-1") != std::string::npos);
  CHECK(permissions("buffer-1").find("cell/commands/buffer-2") == std::string::npos);
  CHECK(section(permissions("buffer-1"), "publish").find("cell/commands/") == std::string::npos);
  CHECK(section(permissions("twin-1"), "publish").find("cell/commands/arm-1") != std::string::npos);
  CHECK(section(permissions("twin-1"), "publish").find("cell/capabilities") == std::string::npos);
  CHECK(permissions("twin-2").find("<topic>cell/orders/status</topic>") != std::string::npos);
  CHECK(section(permissions("twin-2"), "publish").find("<partition>twin-2</partition>") != std::string::npos);
  CHECK(section(permissions("twin-2"), "publish").find("<partition>twin-1</partition>") == std::string::npos);
  CHECK(section(permissions("cellctl"), "publish").find("<topic>cell/orders/twins</topic>") != std::string::npos);
  CHECK(section(permissions("cellctl"), "publish").find("cell/commands/") == std::string::npos);
  CHECK(section(permissions("station-1"), "publish").find("cell/orders/twins") == std::string::npos);
  CHECK(section(permissions("mobile-robot-1"), "publish").find("cell/commands/buffer-1") != std::string::npos);
  // A robot writes its gives in its own partition, and a buffer reads its commands in every one
  // (it checks that a give comes from the robot it names).
  CHECK(permissions("mobile-robot-1").find("<topic>cell/commands/buffer-2</topic>\n          </topics>\n          <partitions>\n"
                                           "            <partition>mobile-robot-1</partition>") != std::string::npos);
  const std::string buffer_1 = permissions("buffer-1");
  const auto own_commands = buffer_1.find("<topic>cell/commands/buffer-1</topic>");
  REQUIRE(own_commands != std::string::npos);
  CHECK(buffer_1.substr(own_commands, buffer_1.find("</subscribe>", own_commands) - own_commands).find("<partition>*</partition>") !=
        std::string::npos);

  // A cell keeps its CA: a second init refuses and changes nothing.
  const std::string ca_key = test::read_text(pki / "ca.key.pem");
  CHECK(test::cellctl({"pki", "init", pki.string(), "--domain", domains::text(domains::kPki)}, dir / "again.log") == 1);
  CHECK(test::read_text(dir / "again.log").find("ca.key.pem exists") != std::string::npos);
  CHECK(test::read_text(pki / "ca.key.pem") == ca_key);
  // What another host gets: the CA's certificate, the governance and one identity, its key 0600.
  REQUIRE(test::cellctl({"pki", "export", pki.string(), "buffer-1", (dir / "for-buffer-1").string()}, dir / "export.log") == 0);
  CHECK(fs::exists(dir / "for-buffer-1" / "ca.cert.pem"));
  CHECK(fs::exists(dir / "for-buffer-1" / "governance.p7s"));
  CHECK(mode_of(dir / "for-buffer-1" / "identities" / "buffer-1" / "key.pem") == 0600);
  CHECK_FALSE(fs::exists(dir / "for-buffer-1" / "ca.key.pem"));
  CHECK_FALSE(fs::exists(dir / "for-buffer-1" / "identities" / "buffer-2"));
  CHECK(test::cellctl({"pki", "export", pki.string(), "buffer-1", (dir / "for-buffer-1").string()}, dir / "export2.log") == 2);
  // An identity the cell does not have is not issued.
  CHECK(test::cellctl({"pki", "issue", pki.string(), "buffer-9", "--domain", domains::text(domains::kPki)}, dir / "issue.log") ==
        2);
  CHECK(test::read_text(dir / "issue.log").find("buffer-9 is no identity of the cell") != std::string::npos);
}

TEST_CASE("secure cell: orders are assembled, and without a certificate, with a foreign or expired one, or on a topic of another role nothing is done",
          "[process][security][cell]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("secure-cell");
  const std::string domain = domains::text(domains::kSecureCell);
  const fs::path pki = dir / "pki", foreign = dir / "foreign", stale = dir / "stale";
  REQUIRE(test::cellctl({"pki", "init", pki.string(), "--domain", domain}, dir / "init.log") == 0);
  REQUIRE(test::cellctl({"pki", "init", foreign.string(), "--domain", domain}, dir / "foreign.log") == 0);
  fs::copy(pki, stale, fs::copy_options::recursive);
  REQUIRE(test::cellctl({"pki", "issue", stale.string(), "buffer-2", "--domain", domain, "--days", "1", "--backdate-days", "2"},
                        dir / "stale.log") == 0);

  // Security on by the deployment file's key (a folder relative to the file); the dashboard
  // follows cell-sim's requests and replies under the desk's permissions.
  const fs::path cell = dir / "cell.yaml";
  std::ofstream(cell) << test::read_text(DEFAULT_CELL) << "\nsecurity: pki\n";
  test::ChildProcess up({CELLCTL_EXE, "up", "--cell", cell.string(), "--domain", domain, "--real-time-factor", "50",
                         "--state-dir", (dir / "state").string(), "--dashboard", "127.0.0.1:0"},
                        (dir / "up.log").string());
  const auto up_log = [&] { return test::read_text(dir / "up.log"); };

  auto trusted = dds::make_participant("test-operator", {std::stoi(domain), true, {pki, "cellctl"}});
  Sightings trusted_sees(trusted);
  {
    INFO(up_log());
    REQUIRE(trusted_sees.wait_for(test::kDefaultCellResources, 60s));
  }

  {  // A participant without a certificate discovers nothing, and its commands reach nobody.
    auto intruder = dds::make_participant("intruder", {std::stoi(domain), true, {}});
    Sightings intruder_sees(intruder);
    dds::Writer<cell::Command, cell::CommandPubSubType> to_arm(intruder, dds::command_topic("arm-1"), dds::TopicKind::events,
                                                                dds::command_qos());
    CHECK_FALSE(to_arm.wait_for_readers(1, 5s));
    CHECK(intruder_sees.seen().empty());
    CHECK(test::appears(dir / "up.log", "refused DDS participant", 10s));
  }

  {  // A twin's certificate cannot publish a capability; a buffer's cannot publish another
     // buffer's capability (its partition), nor read its commands.
    const auto refused_capability = [&](const std::string& id, const std::string& identity) {
      const fs::path log = dir / (identity + "-as-" + id + ".log");
      const int code = buffer_exit(domain, {"--id", id, "--security", pki.string(), "--identity", identity}, log);
      INFO(test::read_text(log));
      CHECK(code != 0);
      CHECK(test::read_text(log).find("cannot create a writer on cell/capabilities: this identity's DDS-Security permissions "
                                      "do not allow it") != std::string::npos);
    };
    refused_capability("buffer-7", "twin-1");
    refused_capability("buffer-1", "buffer-2");
    CHECK(trusted_sees.seen().count("buffer-7") == 0);
    auto as_buffer_2 = dds::make_participant("test-buffer-2", {std::stoi(domain), true, {pki, "buffer-2"}});
    CHECK_THROWS_WITH((dds::Reader<cell::Command, cell::CommandPubSubType>(as_buffer_2, dds::command_topic("buffer-1"),
                                                                           dds::TopicKind::events, [](const cell::Command&) {})),
                      Catch::Contains("cannot create a reader on cell/commands/buffer-1: this identity's DDS-Security"));
    // In its own partition, a capability that says it is buffer-1's: the readers drop it.
    dds::Writer<cell::Capability, cell::CapabilityPubSubType> forger(as_buffer_2, "cell/capabilities", dds::TopicKind::state,
                                                                     dds::owned_by({"buffer-2"}));
    REQUIRE(forger.wait_for_readers(1, 10s));
    cell::Capability forged;
    forged.resource_id("buffer-1");
    forged.kind("buffer");
    forged.stock().push_back(cell::PartStock());
    forged.stock().back().part_type("Forged");
    forged.stock().back().count(5);
    for (int i = 0; i < 3; ++i) {
      forger.write(forged);
      std::this_thread::sleep_for(500ms);
    }
    CHECK_FALSE(trusted_sees.saw_part_type("Forged"));
  }

  {  // A robot has buffers give it parts, in its own partition: it cannot write there as
     // another robot, and a buffer drops a give that names another robot as the taker (its
     // durable record would say that robot holds the part). One that names the writer reaches
     // the buffer, which refuses it: no order holds the buffer.
    auto as_robot = dds::make_participant("test-robot", {std::stoi(domain), true, {pki, "mobile-robot-1"}});
    using CommandWriter = dds::Writer<cell::Command, cell::CommandPubSubType>;
    CHECK_THROWS_WITH((CommandWriter(as_robot, dds::command_topic("buffer-1"), dds::TopicKind::events,
                                     dds::owned_by({"mobile-robot-2"}, dds::command_qos()))),
                      Catch::Contains("cannot create a writer on cell/commands/buffer-1: this identity's DDS-Security"));
    std::mutex mutex;
    std::map<std::string, std::string> answers;  // command id -> reason
    dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType> events(
        trusted, "cell/command_events", dds::TopicKind::events, [&](const cell::CommandEvent& e) {
          std::lock_guard<std::mutex> lock(mutex);
          answers[e.command_id().to_string()] = e.reason().to_string();
        });
    CommandWriter gives(as_robot, dds::command_topic("buffer-1"), dds::TopicKind::events,
                        dds::owned_by({"mobile-robot-1"}, dds::command_qos()));
    REQUIRE(gives.wait_for_readers(1, 10s));
    cell::Command give;
    give.resource_id("buffer-1");
    give.order_id("nobody");
    give.operation("give");
    give.part("nobody/p1");
    give.part_type("Brick2x4");
    give.command_id("forged/give");
    give.destination("mobile-robot-2");
    gives.write(give);
    give.command_id("own/give");
    give.destination("mobile-robot-1");
    gives.write(give);
    const auto answered = [&](const std::string& id) {
      std::lock_guard<std::mutex> lock(mutex);
      return answers.count(id) ? std::optional<std::string>(answers.at(id)) : std::nullopt;
    };
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (!answered("own/give") && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
    INFO(up_log());
    REQUIRE(answered("own/give"));
    CHECK(answered("own/give")->find("names no award of buffer-1") != std::string::npos);
    CHECK_FALSE(answered("forged/give"));
    CHECK(test::appears(dir / "up.log", "dropped a sample on cell/commands/buffer-1 for 'mobile-robot-2'", 10s));
  }

  {  // Each twin speaks for the orders bound to it alone (by cellctl, on cell/orders/twins):
     // twin-2 cannot write in twin-1's partition, every reader drops what it writes for an
     // order bound to twin-1, and what it writes for an order not bound yet waits for the binding.
    dds::Writer<cell::TwinBinding, cell::TwinBindingPubSubType> binder(trusted, "cell/orders/twins", dds::TopicKind::state);
    const auto bind = [&](const std::string& order, const std::string& identity) {
      cell::TwinBinding b;
      b.order_id(order);
      b.identity(identity);
      binder.write(b);
    };
    std::mutex mutex;
    std::map<std::string, std::string> seen;  // order -> the message of its last status that came
    dds::Reader<cell::OrderStatus, cell::OrderStatusPubSubType> statuses(
        trusted, "cell/orders/status", dds::TopicKind::state, [&](const cell::OrderStatus& s) {
          std::lock_guard<std::mutex> lock(mutex);
          seen[s.order_id().to_string()] = s.message().to_string();
        });
    const auto saw = [&](const std::string& order) {
      std::lock_guard<std::mutex> lock(mutex);
      return seen.count(order) > 0;
    };
    const auto message_of = [&](const std::string& order) {
      std::lock_guard<std::mutex> lock(mutex);
      return seen.count(order) ? seen.at(order) : std::string();
    };
    std::set<std::string> answered;  // command ids; made first, to match the arm's events early
    dds::Reader<cell::CommandEvent, cell::CommandEventPubSubType> events(
        trusted, "cell/command_events", dds::TopicKind::events, [&](const cell::CommandEvent& e) {
          std::lock_guard<std::mutex> lock(mutex);
          answered.insert(e.command_id().to_string());
        });
    const auto wait_to_see = [&](const std::string& order) {
      const auto deadline = std::chrono::steady_clock::now() + 20s;
      while (!saw(order) && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
      return saw(order);
    };
    auto as_twin_2 = dds::make_participant("test-twin-2", {std::stoi(domain), true, {pki, "twin-2"}});
    using StatusWriter = dds::Writer<cell::OrderStatus, cell::OrderStatusPubSubType>;
    CHECK_THROWS_WITH((StatusWriter(as_twin_2, "cell/orders/status", dds::TopicKind::state, dds::owned_by({"twin-1"}))),
                      Catch::Contains("cannot create a writer on cell/orders/status: this identity's DDS-Security"));
    StatusWriter status(as_twin_2, "cell/orders/status", dds::TopicKind::state);  // in its partition, twin-2
    bind("bound-to-1", "twin-1");
    bind("bound-to-2", "twin-2");
    REQUIRE(status.wait_for_readers(1, 10s));
    const auto write_status = [&](const std::string& order, const std::string& message) {
      cell::OrderStatus s;
      s.order_id(order);
      s.state(cell::SUBMITTED);
      s.message(message);
      status.write(s);
    };
    for (const std::string order : {"bound-to-1", "bound-later", "bound-to-2"}) write_status(order, "written by twin-2");
    REQUIRE(wait_to_see("bound-to-2"));
    CHECK_FALSE(saw("bound-later"));
    bind("bound-later", "twin-2");
    CHECK(wait_to_see("bound-later"));
    CHECK_FALSE(saw("bound-to-1"));

    // Bound to a new order (identities are pooled), twin-2 speaks for the orders before no
    // more: its next status of bound-later waits, while the one of its new order comes (one
    // writer: in the order written).
    bind("twin-2-next", "twin-2");
    // The binding and the statuses come from two writers: the status once the binding is in.
    const auto bindings = dds::twin_bindings(trusted);
    for (const auto until = std::chrono::steady_clock::now() + 20s;
         bindings->identity_of("bound-later") && std::chrono::steady_clock::now() < until;) {
      std::this_thread::sleep_for(20ms);
    }
    REQUIRE_FALSE(bindings->identity_of("bound-later"));
    write_status("bound-later", "after twin-2 moved on");
    write_status("twin-2-next", "written by twin-2");
    CHECK(wait_to_see("twin-2-next"));
    CHECK(message_of("bound-later") == "written by twin-2");

    // Nor do its commands count for another twin's order: the arm answers one for twin-2's
    // order (no award), and none for twin-1's.
    dds::Writer<cell::Command, cell::CommandPubSubType> to_arm(as_twin_2, dds::command_topic("arm-1"), dds::TopicKind::events,
                                                                dds::command_qos());
    REQUIRE(to_arm.wait_for_readers(1, 10s));
    for (const std::string order : {"bound-to-1", "twin-2-next"}) {
      cell::Command c;
      c.resource_id("arm-1");
      c.order_id(order);
      c.operation("release");
      c.command_id(order + "/release");
      to_arm.write(c);
    }
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    const auto was_answered = [&](const std::string& id) {
      std::lock_guard<std::mutex> lock(mutex);
      return answered.count(id) > 0;
    };
    while (!was_answered("twin-2-next/release") && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
    INFO(up_log());
    CHECK(was_answered("twin-2-next/release"));
    CHECK_FALSE(was_answered("bound-to-1/release"));
    CHECK(test::appears(dir / "up.log", "held a sample on cell/orders/status for 'twin-1'", 10s));
    CHECK(test::appears(dir / "up.log", "held a sample on cell/commands/arm-1 for 'twin-1'", 10s));
  }

  {  // An expired certificate is refused at start, with the date; a foreign CA's by the cell.
    const int expired = buffer_exit(domain, {"--id", "buffer-2", "--security", stale.string()}, dir / "expired.log");
    const std::string expired_log = test::read_text(dir / "expired.log");
    INFO(expired_log);
    CHECK(expired != 0);
    CHECK(expired_log.find("identity 'buffer-2'") != std::string::npos);
    CHECK(expired_log.find("the certificate expired on") != std::string::npos);

    // A buffer-1 with a certificate of another cell's CA (its own check passes: its CA signed
    // it), and stock the cell's buffer-1 does not have.
    const std::size_t refusals_before = count_of(up_log(), "refused DDS participant");
    test::ChildProcess stranger({BUFFER_EXE, "--domain", domain, "--id", "buffer-1", "--security", foreign.string(),
                                 "--stock", "Stolen=5"},
                                (dir / "stranger.log").string());
    CHECK(test::appears(dir / "stranger.log", "ready on domain", 20s));
    CHECK(test::appears(dir / "stranger.log", "refused DDS participant", 20s));
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    while (count_of(up_log(), "refused DDS participant") == refusals_before && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(100ms);
    }
    CHECK(count_of(up_log(), "refused DDS participant") > refusals_before);
    std::this_thread::sleep_for(2s);
    CHECK_FALSE(trusted_sees.saw_part_type("Stolen"));
    CHECK(stranger.stop() == 0);
  }

  // Whatever was tried, the cell assembles an order of a trusted submitter.
  const int order = test::cellctl({"submit", test::kLegoTower, "--domain", domain, "--security", pki.string(), "--order", "after",
                                   "--out", (dir / "after").string()},
                                  dir / "after.log");
  INFO(test::read_text(dir / "after.log") << up_log());
  CHECK(order == 0);
  {  // The dashboard read cell-sim's requests under the desk's permissions: the bodies that
     // moved for the order (the robot's base, the arm's gripper; a table's spawn at the
     // station's start may come before the dashboard's reader is matched).
    const std::string log = up_log();
    std::smatch m;
    REQUIRE(std::regex_search(log, m, std::regex("dashboard: https://127\\.0\\.0\\.1:(\\d+)/\\?token=([0-9a-f]+)")));
    httplib::SSLClient client("127.0.0.1", std::stoi(m[1]));
    client.set_ca_cert_path((pki / "ca.cert.pem").c_str());
    client.enable_server_certificate_verification(true);
    const auto state = client.Get("/state", {{"Authorization", "Bearer " + m[2].str()}});
    REQUIRE(state);
    const nlohmann::json bodies = nlohmann::json::parse(state->body)["bodies"];
    std::set<std::string> owners;
    for (const auto& b : bodies) owners.insert(b["owner"].get<std::string>());
    INFO(bodies.dump());
    CHECK(owners.count("mobile-robot-1"));
    CHECK(owners.count("arm-1"));
  }
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
}

TEST_CASE("secure dashboard: HTTPS with the cell's CA, an operator's certificate lets in without the token, a twin's or a stranger's does not",
          "[process][security][dashboard]") {
  // A client of a server that ends the handshake: its next write must fail, not end the test.
  std::signal(SIGPIPE, SIG_IGN);
  const fs::path dir = test::scratch("secure-dashboard");
  const std::string domain = domains::text(domains::kSecureDashboard);
  const fs::path cell = dir / "cell.yaml", pki = dir / "pki", foreign = dir / "foreign";
  std::ofstream(cell) << test::read_text(DEFAULT_CELL) << "\nsecurity: pki\noperators: [alice]\n";
  REQUIRE(test::cellctl({"pki", "init", pki.string(), "--cell", cell.string(), "--domain", domain}, dir / "init.log") == 0);
  REQUIRE(test::cellctl({"pki", "init", foreign.string(), "--cell", cell.string(), "--domain", domain}, dir / "foreign.log") == 0);
  test::ChildProcess up({CELLCTL_EXE, "up", "--cell", cell.string(), "--domain", domain, "--state-dir", (dir / "state").string(),
                         "--dashboard", "127.0.0.1:0"},
                        (dir / "up.log").string());
  REQUIRE(test::appears(dir / "up.log", "cell up on domain", 90s));
  const std::string log = test::read_text(dir / "up.log");
  INFO(log);
  std::smatch m;
  REQUIRE(std::regex_search(log, m, std::regex("dashboard: https://127\\.0\\.0\\.1:(\\d+)/\\?token=([0-9a-f]+)")));
  const int port = std::stoi(m[1]);
  const std::string token = m[2];
  // A browser of `identity` (its certificate and key from `from`; none: "") that trusts the cell's CA.
  const auto as = [&](const std::string& identity, const fs::path& from = {}) {
    const fs::path id = (from.empty() ? pki : from) / "identities" / identity;
    auto client = identity.empty() ? std::make_unique<httplib::SSLClient>("127.0.0.1", port)
                                   : std::make_unique<httplib::SSLClient>("127.0.0.1", port, (id / "cert.pem").string(),
                                                                          (id / "key.pem").string());
    client->set_ca_cert_path((pki / "ca.cert.pem").c_str());
    client->enable_server_certificate_verification(true);
    client->set_connection_timeout(5);
    return client;
  };

  const auto alice = as("alice")->Get("/state");
  REQUIRE(alice);
  CHECK(alice->status == 200);
  CHECK(nlohmann::json::parse(alice->body).contains("resources"));
  const auto page = as("alice")->Get("/");
  REQUIRE(page);
  CHECK(page->status == 200);

  const auto nobody = as("")->Get("/state");
  REQUIRE(nobody);
  CHECK(nobody->status == 401);
  const auto with_token = as("")->Get("/state", {{"Authorization", "Bearer " + token}});
  REQUIRE(with_token);
  CHECK(with_token->status == 200);
  const auto twin = as("twin-1")->Get("/state");  // the cell's CA signed it, but it is no operator
  REQUIRE(twin);
  CHECK(twin->status == 401);
  CHECK_FALSE(as("alice", foreign)->Get("/state"));  // another CA's alice: no handshake
  httplib::Client plain("127.0.0.1", port);
  plain.set_connection_timeout(5);
  const auto in_clear = plain.Get("/state", {{"Authorization", "Bearer " + token}});
  CHECK((!in_clear || in_clear->status != 200));

  // Pages that leave: each takes the first event of the live stream and closes its connection;
  // the dashboard's next writes to them (the states alice's actions make, below) find them
  // gone, and a TLS write to a closed socket draws SIGPIPE.
  for (int i = 0; i < 4; ++i) as("alice")->Get("/events", [](const char*, std::size_t) { return false; });

  // What alice does is hers in the cell's journal.
  const auto out = as("alice")->Post("/resources/buffer-2/out-of-service", "bin count", "text/plain");
  REQUIRE(out);
  CHECK(out->status == 200);
  CHECK(test::cellctl({"status", "--cell", cell.string(), "--domain", domain, "--json"}, dir / "status.log", 30s) == 0);
  CHECK(test::read_text(dir / "status.log").find("bin count (operator alice (dashboard))") != std::string::npos);
  const auto back = as("alice")->Post("/resources/buffer-2/in-service", "", "text/plain");
  REQUIRE(back);
  CHECK(back->status == 200);
  for (const char* way : {"out-of-service", "in-service", "out-of-service", "in-service"}) {
    as("alice")->Post(std::string("/resources/buffer-1/") + way, "again", "text/plain");
    std::this_thread::sleep_for(300ms);
  }
  CHECK(up.running());

  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
}

TEST_CASE("order desk: a client submits over DDS-Security and gets its results, past a limit or with a bad description it is refused with the reason, and it reads no other client's orders",
          "[process][security][desk]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("order-desk");
  const std::string domain = domains::text(domains::kOrderDesk);
  // The default cell, with a desk that takes 50 kB (the Lego tower, not Cranfield), one
  // order a minute per client and one order queued or under way in the cell.
  std::string yaml = test::read_text(DEFAULT_CELL);
  yaml.replace(yaml.find("max_order_mb: 64"), 16, "max_order_mb: 0.05");
  yaml.replace(yaml.find("orders_per_minute: 60"), 21, "orders_per_minute: 1");
  yaml.replace(yaml.find("max_orders: 1000"), 16, "max_orders: 1");
  yaml.replace(yaml.find("clients: [oem-a, oem-b]"), 23, "clients: [oem-a, oem-b, oem-c, oem-d, oem-e]");
  const fs::path cell = dir / "cell.yaml", pki = dir / "pki";
  std::ofstream(cell) << yaml;
  REQUIRE(test::cellctl({"pki", "init", pki.string(), "--cell", cell.string(), "--domain", domain}, dir / "init.log") == 0);
  test::ChildProcess up({CELLCTL_EXE, "up", "--cell", cell.string(), "--domain", domain, "--security", pki.string(),
                         "--real-time-factor", "50", "--state-dir", (dir / "state").string()},
                        (dir / "up.log").string());
  REQUIRE(test::appears(dir / "up.log", "cell up on domain", 60s));
  const auto args = [&](const std::string& client, const std::string& product, const std::string& id) {
    return std::vector<std::string>{CELLCTL_EXE, "submit", "--remote", "--client", client, product, "--cell", cell.string(),
                                    "--domain", domain, "--security", pki.string(), "--order", id, "--out", (dir / id).string()};
  };
  const auto submit = [&](const std::string& client, const std::string& product, const std::string& id) {
    test::ChildProcess p(args(client, product, id), (dir / (id + ".log")).string());
    return p.wait_for_exit(120s);
  };
  const auto refused = [&](const std::string& id, int code, const std::string& why) {
    const std::string log = test::read_text(dir / (id + ".log"));
    INFO(log);
    CHECK(log.find("the desk refused the order: " + why) != std::string::npos);
    return code;
  };

  // While oem-a's first order runs, its second within the minute is refused.
  test::ChildProcess tower(args("oem-a", test::kLegoTower, "tower"), (dir / "tower.log").string());
  REQUIRE(test::appears(dir / "tower.log", "order oem-a-tower accepted", 60s));
  CHECK(refused("again", submit("oem-a", test::kLegoTower, "again"), "the desk takes 1 orders a minute from a client") == 1);
  const int lego = tower.wait_for_exit(120s);
  {
    INFO(test::read_text(dir / "tower.log") << test::read_text(dir / "up.log"));
    REQUIRE(lego == 0);
  }
  CHECK(test::read_text(dir / "tower" / "plan.json").find("\"complete\": true") != std::string::npos);
  CHECK(fs::file_size(dir / "tower" / "animation.gltf") > 1000);
  CHECK(fs::exists(dir / "state" / "desk" / "oem-a" / "tower" / "product" / "lego-tower.aml"));

  CHECK(refused("big", submit("oem-b", std::string(PRODUCTS_DIR) + "/cranfield/cranfield.aml", "big"),
                "the order's files pass the desk's limit of 50000 bytes") == 2);
  CHECK(refused("bad", submit("oem-c", std::string(TEST_DATA_DIR) + "/bad/unknown_link_id.aml", "bad"), "unknown_link_id.aml:") == 2);
  CHECK_FALSE(fs::exists(dir / "state" / "desk" / "oem-c" / "bad"));  // nothing kept of a refused order

  {  // A file whose bytes are not the ones its order names (its SHA-256) is refused, and
     // nothing of it is kept: oem-d's own client, writing the desk's topics as cellctl does.
    auto oem_d = dds::make_participant("test-oem-d", {std::stoi(domain), true, {pki, "oem-d"}});
    std::mutex mutex;
    std::optional<cell::DeskReply> answer;
    dds::Reader<cell::DeskReply, cell::DeskReplyPubSubType> replies(
        oem_d, cellctl::desk_topic("replies", "oem-d"), dds::TopicKind::state, [&](const cell::DeskReply& r) {
          std::lock_guard<std::mutex> lock(mutex);
          if (r.submission().to_string() == "tampered") answer = r;
        });
    cellctl::ChunkWriter chunks(oem_d, cellctl::desk_topic("files", "oem-d"), dds::TopicKind::events, cellctl::chunk_qos());
    dds::Writer<cell::OrderRequest, cell::OrderRequestPubSubType> orders(oem_d, cellctl::desk_topic("orders", "oem-d"),
                                                                         dds::TopicKind::events);
    REQUIRE(chunks.wait_for_readers(1, 20s));
    REQUIRE(orders.wait_for_readers(1, 20s));
    const std::string bytes = cellctl::read_file_bytes(test::kLegoTower);
    REQUIRE(cellctl::send_file(chunks, "tampered", "lego-tower.aml", bytes, std::chrono::steady_clock::now() + 20s));
    REQUIRE(chunks.wait_for_acknowledgments(20s));
    cell::OrderRequest request;
    request.submission("tampered");
    request.request("r1");
    request.product("lego-tower.aml");
    cell::FileDigest digest;
    digest.name("lego-tower.aml");
    digest.size(bytes.size());
    digest.sha256(cellctl::sha256_hex(bytes + "changed on the way"));
    request.files().push_back(digest);
    REQUIRE(orders.write(request));
    const auto deadline = std::chrono::steady_clock::now() + 20s;
    const auto answered = [&] {
      std::lock_guard<std::mutex> lock(mutex);
      return answer;
    };
    while (!answered() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
    INFO(test::read_text(dir / "up.log"));
    REQUIRE(answered());
    CHECK(answered()->state() == cell::DESK_REFUSED);
    CHECK(answered()->message().to_string() == "lego-tower.aml: its size or SHA-256 is not what the order says");
    CHECK(answered()->exit_code() == 2);
    CHECK_FALSE(fs::exists(dir / "state" / "desk" / "oem-d" / "tampered"));
  }

  // An order under way in the cell (one its desk did not take: no twin of the desk runs it)
  // makes the cell full at one: oem-e's order is refused with the reason, and the desk stays.
  state::CellStore(dir / "state").set_order("placed-elsewhere", "PHYSICAL_ASSEMBLY");
  CHECK(refused("busy", submit("oem-e", test::kLegoTower, "busy"), "the cell has 1 orders queued or under way, its limit (desk: max_orders); try again later") == 1);
  CHECK_FALSE(fs::exists(dir / "state" / "desk" / "oem-e" / "busy"));

  // oem-b's certificate reads its own answers, not oem-a's, nor the cell's order status.
  auto oem_b = dds::make_participant("test-oem-b", {std::stoi(domain), true, {pki, "oem-b"}});
  const auto reader_on = [&](const std::string& topic) {
    dds::Reader<cell::DeskReply, cell::DeskReplyPubSubType> r(oem_b, topic, dds::TopicKind::state, [](const cell::DeskReply&) {});
  };
  CHECK_NOTHROW(reader_on("cell/desk/replies/oem-b"));
  CHECK_THROWS_WITH(reader_on("cell/desk/replies/oem-a"), Catch::Contains("permissions do not allow it"));
  CHECK_THROWS_WITH(reader_on("cell/orders/status"), Catch::Contains("permissions do not allow it"));

  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
  CHECK(test::read_text(dir / "up.log").find("refused oem-b's order big") != std::string::npos);
  CHECK(test::read_text(dir / "up.log").find("refused oem-a's order again") != std::string::npos);
}
