// cellctl up's dashboard over HTTP, as a stranger and as a crowd would use it: nothing
// without the token, the token out of the address once used, the page's policy, a bound on
// the pages that follow the cell, stalled connections that do not stop it answering, and
// the operator's uploads that become orders (bad and hostile ones refused, nothing kept).
// (What a person sees in a browser: tests/browser/check_dashboard.js.)

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

// A TCP connection to the dashboard that sends `request` and reads what comes back.
class RawConnection {
 public:
  RawConnection(int port, const std::string& request) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in at{};
    at.sin_family = AF_INET;
    at.sin_port = htons(static_cast<std::uint16_t>(port));
    at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval wait{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof wait);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&at), sizeof at) == 0 &&
                 ::send(fd_, request.data(), request.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(request.size());
  }
  ~RawConnection() {
    if (fd_ >= 0) ::close(fd_);
  }
  // Ends the connection at once with a reset, as a browser's tab closed mid-answer can.
  void reset() {
    const linger now{1, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_LINGER, &now, sizeof now);
    ::close(fd_);
    fd_ = -1;
  }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;
  bool connected() const { return connected_; }
  // The status line's code, or 0 when none came within 5 s.
  int status() {
    char buffer[256] = {};
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer - 1, 0);
    if (n < 12) return 0;
    return std::atoi(buffer + 9);  // "HTTP/1.1 200 OK"
  }

 private:
  int fd_;
  bool connected_ = false;
};

// `cellctl up --dashboard` on the default cell of a domain of the test's own, and the address
// it printed: the port and the token.
struct DashboardCell {
  std::unique_ptr<test::ChildProcess> up;
  int port = 0;
  std::string token;
};

DashboardCell start_dashboard_cell(const std::filesystem::path& dir, const std::string& domain) {
  using namespace std::chrono_literals;
  test::clean_stale_dds_segments();
  DashboardCell cell;
  cell.up = std::make_unique<test::ChildProcess>(
      std::vector<std::string>{CELLCTL_EXE, "up", DEFAULT_CELL, "--domain", domain, "--state-dir", (dir / "state").string(),
                               "--dashboard", "127.0.0.1:0"},
      (dir / "up.log").string());
  REQUIRE(test::appears(dir / "up.log", "cell up on domain", 90s));
  std::smatch m;
  const std::string log = test::read_text(dir / "up.log");
  REQUIRE(std::regex_search(log, m, std::regex("dashboard: http://127\\.0\\.0\\.1:(\\d+)/\\?token=([0-9a-f]+)")));
  cell.port = std::stoi(m[1]);
  cell.token = m[2];
  return cell;
}

}  // namespace

TEST_CASE("the dashboard: nothing without the token, a bounded crowd of pages, and stalled connections do not stop it",
          "[process][cell][dashboard]") {
  using namespace std::chrono_literals;
  const auto dir = test::scratch("dashboard");
  const std::string domain = domains::text(domains::kDashboard);
  const DashboardCell cell = start_dashboard_cell(dir, domain);
  const int port = cell.port;
  const std::string& token = cell.token;
  CHECK(test::read_text(dir / "state" / "dashboard.token") == token + "\n");
  CHECK((std::filesystem::status(dir / "state" / "dashboard.token").permissions() & std::filesystem::perms::others_read) ==
        std::filesystem::perms::none);

  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(10, 0);

  SECTION("a stranger gets nothing; the operator gets every resource, the page's policy and a cookie") {
    auto r = client.Get("/state");
    REQUIRE(r);
    CHECK(r->status == 401);
    CHECK(r->body.find("token") != std::string::npos);  // says what is missing
    r = client.Get("/state", {{"Authorization", "Bearer " + std::string(token.size(), '0')}});
    REQUIRE(r);
    CHECK(r->status == 401);
    r = client.Get("/");
    REQUIRE(r);
    CHECK(r->status == 401);
    r = client.Get("/?token=nope");
    REQUIRE(r);
    CHECK(r->status == 401);

    r = client.Get(("/?token=" + token).c_str());
    REQUIRE(r);
    CHECK(r->status == 302);
    CHECK(r->get_header_value("Location") == "/");
    const std::string cookie = r->get_header_value("Set-Cookie");
    CHECK(cookie.find("HttpOnly") != std::string::npos);
    CHECK(cookie.find("SameSite=Strict") != std::string::npos);
    r = client.Get("/", {{"Cookie", cookie.substr(0, cookie.find(';'))}});
    REQUIRE(r);
    CHECK(r->status == 200);
    CHECK(r->get_header_value("Content-Security-Policy").find("script-src 'self'") != std::string::npos);
    CHECK(r->body.find("<script src=\"/dashboard.js\"") != std::string::npos);

    r = client.Get("/state", {{"Authorization", "Bearer " + token}});
    REQUIRE(r);
    REQUIRE(r->status == 200);
    const auto state = nlohmann::json::parse(r->body);
    std::vector<std::string> ids;
    for (const auto& resource : state["resources"]) {
      ids.push_back(resource["id"]);
      CHECK(resource["alive"] == true);
    }
    for (const std::string& id : test::kDefaultCellResources) {
      CHECK(std::find(ids.begin(), ids.end(), id) != ids.end());
    }
    CHECK(state["domain"] == domains::kDashboard);
    CHECK(state["attention"].empty());

    // An order's results: only the three files, of an order the cell has.
    const httplib::Headers bearer{{"Authorization", "Bearer " + token}};
    r = client.Get("/orders/nope/plan.json", bearer);
    REQUIRE(r);
    CHECK(r->status == 404);
    CHECK(r->body.find("no such order") != std::string::npos);
    r = client.Get("/orders/nope/plan.json");
    REQUIRE(r);
    CHECK(r->status == 401);
    for (const char* path : {"/orders/../../etc/passwd", "/orders/x/cell.db", "/orders/x/..%2F..%2Fcell.db"}) {
      r = client.Get(path, bearer);
      REQUIRE(r);
      CHECK(r->status == 404);
    }

    r = client.Post("/state", {{"Authorization", "Bearer " + token}}, std::string(100 * 1024, 'x'), "text/plain");
    REQUIRE(r);
    CHECK(r->status == 413);  // past 64 kB: refused, not read
  }

  SECTION("past the bound of pages following the cell, one more is refused; stalled connections and pages that leave "
          "mid-answer do not stop it") {
    const std::string follow = "GET /events HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer " + token + "\r\n\r\n";
    std::vector<std::unique_ptr<RawConnection>> pages;
    for (int i = 0; i < 8; ++i) {
      pages.push_back(std::make_unique<RawConnection>(port, follow));
      REQUIRE(pages.back()->connected());
      CHECK(pages.back()->status() == 200);
    }
    RawConnection one_more(port, follow);
    CHECK(one_more.status() == 503);

    // Half a request each, never finished: each holds a thread until the read timeout.
    std::vector<std::unique_ptr<RawConnection>> stalled;
    for (int i = 0; i < 40; ++i) stalled.push_back(std::make_unique<RawConnection>(port, "GET /state HTTP/1.1\r\nHo"));
    const auto asked = std::chrono::steady_clock::now();
    auto r = client.Get("/state", {{"Authorization", "Bearer " + token}});
    REQUIRE(r);
    CHECK(r->status == 200);
    // The first 24 hold the other threads until the read timeout (2 s) ends them; then it is
    // answered. (Bounded, not timed to the millisecond: a loaded machine may take longer.)
    CHECK(std::chrono::steady_clock::now() - asked < 12s);

    // Pages that leave mid-answer end their own connections, not the cell.
    for (int i = 0; i < 20; ++i) {
      RawConnection leaving(port, "GET /three.js HTTP/1.1\r\nHost: x\r\n\r\n");  // 600 kB to write
      REQUIRE(leaving.connected());
      std::this_thread::sleep_for(std::chrono::milliseconds(i % 4));
      if (i % 2) leaving.reset();  // else closed as it goes: the server's next write draws a reset
    }
    std::this_thread::sleep_for(1s);
    CHECK(cell.up->running());
    r = client.Get("/state", {{"Authorization", "Bearer " + token}});
    REQUIRE(r);
    CHECK(r->status == 200);
  }

  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(cell.up->wait_for_exit(20s) == 0);
}

TEST_CASE("the dashboard takes orders: the operator's zip of a product becomes an order of the cell's, and the operator "
          "cancels one, while a stranger's, another site's, a hostile or a bad one is refused with the reason, and nothing is kept",
          "[process][cell][dashboard]") {
  using namespace std::chrono_literals;
  namespace fs = std::filesystem;
  const auto dir = test::scratch("dashboard-orders");
  const std::string domain = domains::text(domains::kDashboardTakesOrders);
  const DashboardCell cell = start_dashboard_cell(dir, domain);
  const int port = cell.port;
  const httplib::Headers bearer{{"Authorization", "Bearer " + cell.token}};
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(30, 0);
  const std::string zip = test::read_text(LEGO_ZIP);
  REQUIRE(zip.size() > 1000);
  const auto uploads = dir / "state" / "uploads";
  const auto message_of = [](const httplib::Result& r) { return nlohmann::json::parse(r->body).value("message", ""); };

  // A stranger's upload is answered before its body is read: a declared gigabyte, never sent.
  RawConnection stranger(port, "POST /orders HTTP/1.1\r\nHost: x\r\nContent-Type: application/zip\r\nContent-Length: 1000000000\r\n\r\n");
  CHECK(stranger.status() == 401);
  // Past the desk's limit (64 MB by default), refused before it is read.
  RawConnection too_large(port, "POST /orders HTTP/1.1\r\nHost: x\r\nAuthorization: " + bearer.begin()->second +
                                    "\r\nContent-Length: 1000000000\r\n\r\n");
  CHECK(too_large.status() == 413);
  // Another site's page, with the operator's credentials: refused.
  auto foreign = bearer;
  foreign.emplace("Origin", "http://evil.example");
  auto r = client.Post("/orders?order=o-foreign", foreign, zip, "application/zip");
  REQUIRE(r);
  CHECK(r->status == 403);

  // Bad and hostile archives: refused with the reason, nothing kept.
  r = client.Post("/orders?order=o-bad", bearer, "not a zip", "application/zip");
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(message_of(r).find("not a zip archive") != std::string::npos);
  // The description's entry renamed, in both of the zip's directories, to a path as long
  // that leaves the folder.
  std::string tampered = zip;
  for (auto at = tampered.find("lego-tower/lego-tower.aml"); at != std::string::npos;
       at = tampered.find("lego-tower/lego-tower.aml")) {
    tampered.replace(at, 25, "../../../../../etc/xx.aml");
  }
  r = client.Post("/orders?order=o-escape", bearer, tampered, "application/zip");
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(message_of(r).find("leaves the product's folder") != std::string::npos);
  r = client.Post("/orders?order=../../x", bearer, zip, "application/zip");
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(message_of(r).find("id") != std::string::npos);
  CHECK((!fs::exists(uploads) || fs::is_empty(uploads)));

  // The product's zip: an order, journalled as the dashboard's, then the same id refused.
  r = client.Post("/orders?order=o-1", bearer, zip, "application/zip");
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(nlohmann::json::parse(r->body)["order"] == "o-1");
  CHECK(fs::exists(uploads / "o-1" / "product" / "lego-tower" / "lego-tower.aml"));
  r = client.Post("/orders?order=o-1", bearer, zip, "application/zip");
  REQUIRE(r);
  CHECK(r->status == 409);
  r = client.Post("/orders", bearer, zip, "application/zip");  // no id: one is made
  REQUIRE(r);
  CHECK(r->status == 200);
  const std::string made = nlohmann::json::parse(r->body)["order"];
  CHECK(made.rfind("upload-", 0) == 0);

  // The operator cancels the second: a stranger, another site and an unknown order cannot.
  const std::string cancel = "/orders/" + made + "/cancel";
  r = client.Post(cancel.c_str());
  REQUIRE(r);
  CHECK(r->status == 401);
  r = client.Post(cancel.c_str(), foreign, "", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 403);
  r = client.Post("/orders/nope/cancel", bearer, "", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 404);
  r = client.Post(cancel.c_str(), bearer, "", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 200);

  // Both show on the page's state: the first done, the second failed as cancelled.
  std::string first, second;
  for (auto until = std::chrono::steady_clock::now() + 90s;
       !(first == "DONE" && second == "FAILED") && std::chrono::steady_clock::now() < until;
       std::this_thread::sleep_for(200ms)) {
    r = client.Get("/state", bearer);
    REQUIRE(r);
    const auto state = nlohmann::json::parse(r->body);
    for (const auto& o : state["orders"]) {
      if (o["order"] == "o-1") first = o["state"];
      if (o["order"] == made && o["state"] == "FAILED") {
        second = "FAILED";
        CHECK(o["reason"].get<std::string>().rfind("cancelled by the operator (dashboard)", 0) == 0);
      }
    }
  }
  CHECK(first == "DONE");
  CHECK(second == "FAILED");
  r = client.Post(cancel.c_str(), bearer, "", "text/plain");  // it has ended
  REQUIRE(r);
  CHECK(r->status == 409);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(cell.up->wait_for_exit(20s) == 0);
}

TEST_CASE("the operator takes a station out of service from the dashboard: the station says so and refuses new work with "
          "the reason, and the order that needed it fails with it, and back in service from the command line it builds the next",
          "[process][cell][dashboard]") {
  using namespace std::chrono_literals;
  const auto dir = test::scratch("dashboard-service");
  const std::string domain = domains::text(domains::kOperatorTakesAStationOut);
  const DashboardCell cell = start_dashboard_cell(dir, domain);
  const httplib::Headers bearer{{"Authorization", "Bearer " + cell.token}};
  httplib::Client client("127.0.0.1", cell.port);
  client.set_read_timeout(30, 0);
  const auto state_of = [&] {
    const auto r = client.Get("/state", bearer);
    REQUIRE(r);
    return nlohmann::json::parse(r->body);
  };
  const auto resource = [](const nlohmann::json& state, const std::string& id) {
    for (const auto& r : state["resources"]) {
      if (r["id"] == id) return r;
    }
    return nlohmann::json::object();
  };

  // A stranger, another site, an unknown resource, no reason, a control character: refused.
  const char* out = "/resources/station-1/out-of-service";
  auto r = client.Post(out, "worn", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 401);
  auto foreign = bearer;
  foreign.emplace("Origin", "http://evil.example");
  r = client.Post(out, foreign, "worn", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 403);
  r = client.Post("/resources/station-9/out-of-service", bearer, "worn", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 404);
  r = client.Post(out, bearer, "", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 400);
  r = client.Post(out, bearer, "worn\x1b[2J", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 400);

  // The operator's ask reaches the station, which says so in its capability.
  r = client.Post(out, bearer, "gripper worn", "text/plain");
  REQUIRE(r);
  CHECK(r->status == 200);
  const std::string why = "gripper worn (the operator (dashboard))";
  bool said = false;
  for (auto until = std::chrono::steady_clock::now() + 30s; !said && std::chrono::steady_clock::now() < until;
       std::this_thread::sleep_for(200ms)) {
    said = resource(state_of(), "station-1").value("out_of_service", "") == why;
  }
  CHECK(said);
  CHECK(test::cellctl({"status", "--domain", domain}, dir / "status.log", 30s) == 0);
  CHECK(test::read_text(dir / "status.log").find("out of service") != std::string::npos);

  // An order needs the cell's one station: every call is refused with the reason, and after
  // the twin's wait (30 s) the order fails with it.
  const std::string zip = test::read_text(LEGO_ZIP);
  r = client.Post("/orders?order=o-out", bearer, zip, "application/zip");
  REQUIRE(r);
  REQUIRE(r->status == 200);
  const auto final_state = [&](const std::string& order, nlohmann::json& found) {
    for (auto until = std::chrono::steady_clock::now() + 120s; std::chrono::steady_clock::now() < until;
         std::this_thread::sleep_for(250ms)) {
      const auto state = state_of();
      for (const auto& o : state["orders"]) {
        if (o["order"] == order && (o["state"] == "DONE" || o["state"] == "FAILED")) {
          found = o;
          return o["state"].get<std::string>();
        }
      }
    }
    return std::string("not ended");
  };
  nlohmann::json order;
  CHECK(final_state("o-out", order) == "FAILED");
  INFO(order.dump());
  CHECK(order.value("reason", "").find("station-1 is out of service: " + why) != std::string::npos);
  CHECK(resource(state_of(), "station-1").value("reserved_by", "x").empty());

  // Back, from the command line: the next order is built on it.
  CHECK(test::cellctl({"service", "station-1", "--back", "--domain", domain}, dir / "back.log", 30s) == 0);
  CHECK(test::read_text(dir / "back.log").find("station-1 is back in service") != std::string::npos);
  r = client.Post("/orders?order=o-back", bearer, zip, "application/zip");
  REQUIRE(r);
  REQUIRE(r->status == 200);
  CHECK(final_state("o-back", order) == "DONE");
  CHECK(resource(state_of(), "station-1").value("out_of_service", "x").empty());
  // The alarms have both, and whose they were.
  const std::string alarms = state_of()["alarms"].dump();
  CHECK(alarms.find("out of service") != std::string::npos);
  CHECK(alarms.find("in service") != std::string::npos);
  CHECK(alarms.find("the operator (dashboard)") != std::string::npos);
  CHECK(alarms.find("the operator (cellctl)") != std::string::npos);
  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(cell.up->wait_for_exit(20s) == 0);
}
