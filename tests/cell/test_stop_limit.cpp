// A cell process asked to stop ends within services::kStopLimit, even when its teardown hangs:
// one orphaned by a killed cellctl up must not stay on the domain.

#include <signal.h>

#include <chrono>

#include <catch2/catch.hpp>

#include "services/node/run.hpp"
#include "tests/support/cell_test.hpp"

TEST_CASE("a cell process whose end hangs after SIGTERM exits within the stop limit, and says why",
          "[process][supervision]") {
  using namespace std::chrono_literals;
  const auto log = test::scratch("stop-limit") / "hangs.log";
  test::ChildProcess hangs({HANGS_ON_STOP_EXE}, log.string());
  REQUIRE(test::appears(log, "running", 10s));

  const auto asked = std::chrono::steady_clock::now();
  ::kill(hangs.pid(), SIGTERM);
  const int code = hangs.wait_for_exit(services::kStopLimit + 15s);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
  const std::string said = test::read_text(log);
  INFO(said);
  CHECK(code == 1);
  CHECK(took >= static_cast<double>(services::kStopLimit.count()) - 0.5);  // its teardown had the time
  CHECK(said.find("asked to stop; hanging") != std::string::npos);
  CHECK(said.find("after it was asked to stop") != std::string::npos);
}
