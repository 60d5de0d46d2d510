// cellctl up's dashboard over HTTP, as a stranger and as a crowd would use it: nothing
// without the token, the token out of the address once used, the page's policy, a bound on
// the pages that follow the cell, and stalled connections that do not stop it answering.
// (What a person sees in a browser: tests/browser/check_dashboard.js.)

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <regex>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include "tests/support/cell_test.hpp"

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
  ~RawConnection() { ::close(fd_); }
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

}  // namespace

TEST_CASE("the dashboard: nothing without the token, a bounded crowd of pages, and stalled connections do not stop it",
          "[process][cell][dashboard]") {
  using namespace std::chrono_literals;
  const auto dir = test::scratch("dashboard");
  const std::string domain = "175";
  test::clean_stale_dds_segments();
  test::ChildProcess up({CELLCTL_EXE, "up", DEFAULT_CELL, "--domain", domain, "--state-dir", (dir / "state").string(),
                         "--dashboard", "127.0.0.1:0"},
                        (dir / "up.log").string());
  REQUIRE(test::appears(dir / "up.log", "cell up on domain", 90s));
  std::smatch m;
  const std::string log = test::read_text(dir / "up.log");
  REQUIRE(std::regex_search(log, m, std::regex("dashboard: http://127\\.0\\.0\\.1:(\\d+)/\\?token=([0-9a-f]+)")));
  const int port = std::stoi(m[1]);
  const std::string token = m[2];
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
    for (const std::string id : {"station-1", "arm-1", "mobile-robot-1", "buffer-1", "buffer-2"}) {
      CHECK(std::find(ids.begin(), ids.end(), id) != ids.end());
    }
    CHECK(state["domain"] == 175);
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

  SECTION("past the bound of pages following the cell, one more is refused; stalled connections do not stop it") {
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
  }

  CHECK(test::cellctl({"down", "--domain", domain}, dir / "down.log", 30s) == 0);
  CHECK(up.wait_for_exit(20s) == 0);
}
