// cellctl quote: two cells, each on a domain of its own, answer the same request for a quote;
// the faster cell is the dearer one, so the best by time is not the best by cost.

#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/domains.hpp"

namespace domains = test::domains;

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A cell of deploy/cells on the test's domain; `replace`: (text, by) in its file.
fs::path cell_file(const fs::path& dir, const std::string& name, const std::string& domain,
                   std::vector<std::pair<std::string, std::string>> replace = {}) {
  std::string yaml = test::read_text(std::string(DEPLOY_CELLS) + "/" + name + ".yaml");
  replace.emplace_back(yaml.substr(yaml.find("domain: "), yaml.find('\n', yaml.find("domain: ")) - yaml.find("domain: ")),
                       "domain: " + domain);
  for (const auto& [text, by] : replace) {
    const auto at = yaml.find(text);
    REQUIRE(at != std::string::npos);
    yaml.replace(at, text.size(), by);
  }
  const fs::path file = dir / (name + ".yaml");
  std::ofstream(file) << yaml;
  return file;
}

}  // namespace

TEST_CASE("quotes: two cells answer with time, cost and findings, the best by time and by cost differ, and nothing is taken",
          "[process][quote]") {
  test::clean_stale_dds_segments();
  const fs::path dir = test::scratch("quotes");
  // The thrifty cell has no 2x2 bricks: the Lego tower is not feasible there.
  const fs::path fast = cell_file(dir, "fast", domains::text(domains::kQuotesFast));
  const fs::path thrifty =
      cell_file(dir, "thrifty", domains::text(domains::kQuotesThrifty), {{"Brick2x2: 100", "Brick2x2: 0"}});
  test::ChildProcess up_fast({CELLCTL_EXE, "up", "--cell", fast.string(), "--state-dir", (dir / "state-fast").string()},
                             (dir / "up-fast.log").string());
  test::ChildProcess up_thrifty({CELLCTL_EXE, "up", "--cell", thrifty.string(), "--state-dir", (dir / "state-thrifty").string()},
                                (dir / "up-thrifty.log").string());
  REQUIRE(test::appears(dir / "up-fast.log", "cell up on domain", 60s));
  REQUIRE(test::appears(dir / "up-thrifty.log", "cell up on domain", 60s));

  const auto quote = [&](const std::string& product, const std::string& out) {
    return test::cellctl({"quote", std::string(PRODUCTS_DIR) + "/" + product, "--client", "oem-a", "--cell", fast.string(),
                          "--cell", thrifty.string(), "--out", (dir / out).string()},
                         dir / (out + ".log"), 180s);
  };
  const auto read_json = [](const fs::path& file) { return nlohmann::json::parse(std::ifstream(file)); };

  REQUIRE(quote("cranfield/cranfield.aml", "cranfield") == 0);
  {
    const std::string log = test::read_text(dir / "cranfield.log");
    INFO(log);
    const auto all = read_json(dir / "cranfield" / "quotes.json");
    CHECK(all["best_time"] == "fast");
    CHECK(all["best_cost"] == "thrifty");
    REQUIRE(all["cells"].size() == 2);
    const auto& f = all["cells"][0]["quote"];
    const auto& t = all["cells"][1]["quote"];
    REQUIRE(f["feasible"] == true);
    REQUIRE(t["feasible"] == true);
    // The fast cell's arm is 3.3 times as fast: its makespan is well under the thrifty one's;
    // its setup cost alone (40) is above the thrifty cell's whole cost.
    CHECK(f["time_s"]["makespan"].get<double>() * 2 < t["time_s"]["makespan"].get<double>());
    CHECK(f["cost"]["total"].get<double>() > 40);
    CHECK(t["cost"]["total"].get<double>() < 15);
    CHECK(f["cost"]["setup"] == 40);
    CHECK(f["time_s"]["wait"] == 0);  // nobody else's order
    CHECK(f["findings"].size() > 0);  // Cranfield's tight fits: margins under 1 mm
    // The table marks each best; each cell's results came back beside its quote.
    CHECK(log.find("fast     yes") != std::string::npos);
    CHECK(log.find("time\n") != std::string::npos);
    CHECK(log.find("cost\n") != std::string::npos);
    // The report says the answer at its top.
    CHECK(test::read_text(dir / "cranfield" / "thrifty" / "report.html").find("<p class=\"answer\">quoted: done in") !=
          std::string::npos);
    CHECK(fs::file_size(dir / "cranfield" / "thrifty" / "animation.gltf") > 1000);
    CHECK(read_json(dir / "cranfield" / "fast" / "quote.json")["order"].get<std::string>().rfind("oem-a-quote-cranfield-", 0) == 0);
  }

  REQUIRE(quote("lego-tower/lego-tower.aml", "lego") == 0);
  {
    INFO(test::read_text(dir / "lego.log"));
    const auto all = read_json(dir / "lego" / "quotes.json");
    CHECK(all["best_time"] == "fast");
    CHECK(all["best_cost"] == "fast");
    const auto& t = all["cells"][1]["quote"];
    CHECK(t["feasible"] == false);
    CHECK(t["reason"].get<std::string>().find("nobody offered give Brick2x2") != std::string::npos);
    CHECK(test::read_text(dir / "lego.log").find("thrifty  no") != std::string::npos);
    CHECK(test::read_text(dir / "lego" / "thrifty" / "report.html").find("quoted: not feasible: nobody offered give Brick2x2") !=
          std::string::npos);
  }

  // The manufacturer sees the quotes among the cell's orders.
  REQUIRE(test::cellctl({"status", "--json", "--cell", fast.string(), "--state-dir", (dir / "state-fast").string()},
                        dir / "status.log", 60s) == 0);
  const std::string said = test::read_text(dir / "status.log");  // the JSON object, whatever else was said
  const auto status = nlohmann::json::parse(said.substr(said.find('{'), said.rfind('}') - said.find('{') + 1));
  REQUIRE(status["orders"].size() == 2);
  for (const auto& o : status["orders"]) CHECK(o["quote"] == true);

  CHECK(test::cellctl({"down", "--domain", domains::text(domains::kQuotesFast)}, dir / "down-fast.log", 30s) == 0);
  CHECK(test::cellctl({"down", "--domain", domains::text(domains::kQuotesThrifty)}, dir / "down-thrifty.log", 30s) == 0);
  CHECK(up_fast.wait_for_exit(20s) == 0);
  CHECK(up_thrifty.wait_for_exit(20s) == 0);
  // A quote takes no stock and leaves no part anywhere.
  state::CellStore store(dir / "state-fast");
  const auto stock = store.open_buffer("buffer-1", {});
  CHECK(stock.at("Shaft") == 20);
  CHECK(store.open_buffer("buffer-2", {}).at("Brick2x2") == 100);
  for (const auto& o : store.orders()) {
    CHECK(o.quote);
    CHECK(o.state == "DONE");
    CHECK(store.parts(o.order).empty());
  }
}
