// The designer's report as text: one self-contained page, escaped where it quotes names.
// (tests/browser/check_report.js opens it in chromium.)

#include "tests/twin/test_support.hpp"
#include "twin/report/html_report.hpp"

namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

}  // namespace

TEST_CASE("the report is one page with the viewer built in, every finding, the margins and the cell's run",
          "[report]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  const twin::LoadedProduct& loaded = cranfield.product;
  const twin::Plan& plan = cranfield.plan;
  REQUIRE(plan.complete);

  const std::string page = twin::html_report(loaded, plan);
  CHECK(page.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(page.find("var REVISION=\"111\"") != std::string::npos);  // three.js, as libjs-three ships it
  CHECK(page.find("THREE.GLTFLoader") != std::string::npos);
  CHECK(page.find("window.agileReport") != std::string::npos);
  CHECK(count(page, "<li class=\"finding\"") == plan.findings.size());
  CHECK(page.find("<td class=\"low\" title=\"the part passes 0.50 mm from back while insert\">0.50 back</td>") !=
        std::string::npos);
  CHECK(page.find("id=\"margin-chart\"") != std::string::npos);
  CHECK(page.find("<td>pendulum</td><td>pendulum, separator, front</td>") != std::string::npos);  // an open choice
  CHECK(page.find("id=\"gantt-chart\"") == std::string::npos);  // a plan alone has no run

  SECTION("a cell run's commands as a Gantt chart; what it quotes cannot break out of the page") {
    twin::ReportOptions options;
    options.title = "order <b>7</b>";
    options.timeline = {{"arm-1", "grip", "back", "succeeded", 10, 11},
                        {"</script><script>alert(1)</script>", "fetch", "shaft", "aborted", 10.5, 12}};
    const std::string run = twin::html_report(loaded, plan, options);
    CHECK(run.find("id=\"gantt-chart\"") != std::string::npos);
    CHECK(run.find("<small>order &lt;b&gt;7&lt;/b&gt;</small>") != std::string::npos);
    CHECK(run.find("alert(1)") != std::string::npos);
    CHECK(run.find("<script>alert(1)") == std::string::npos);
    CHECK(count(run, "<script") == count(page, "<script"));
    CHECK(run.find("grip back: 10.0 to 11.0 s, succeeded") != std::string::npos);
    CHECK(run.find("class=\"op op-1 failed\"") != std::string::npos);  // the aborted fetch
  }
}
