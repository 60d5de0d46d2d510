// The OEM's side of quotes reads what a cell sent back: only what it checked goes on.

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>

#include "deploy/cellctl/quote_answer.hpp"

namespace {

nlohmann::json read(const std::string& text, std::string& why) {
  const auto file = std::filesystem::temp_directory_path() / ("quote-" + std::to_string(::getpid()) + ".json");
  std::ofstream(file) << text;
  auto q = cellctl::read_quote(file, "oem-a-q1", why);
  std::filesystem::remove(file);
  return q;
}

const char* kGood = R"({"schema": "agile-cell/quote", "version": 1, "order": "oem-a-q1", "feasible": true, "steps": 9,
  "station": "station-1", "robot": "mobile-robot-1", "extra": {"anything": [1, 2, 3]},
  "time_s": {"makespan": 26.6, "wait": 0, "station": 26.6, "robot": 14.7},
  "cost": {"currency": "EUR", "setup": 40, "station": 1.1, "robot": 0.16, "total": 41.26},
  "findings": [{"kind": "margin", "message": "step 2", "parts": ["shaft"]}, {"kind": 7}]})";

}  // namespace

TEST_CASE("quote answers: a good one is copied field by field, anything else is left out", "[cellctl][quote]") {
  std::string why;
  const auto q = read(kGood, why);
  INFO(why);
  REQUIRE(q.is_object());
  CHECK(q["feasible"] == true);
  CHECK(q["time_s"]["makespan"] == Approx(26.6));
  CHECK(q["cost"]["currency"] == "EUR");
  CHECK(q["findings"].size() == 1);  // the finding without a message is left out
  CHECK_FALSE(q.contains("extra"));
  const auto no = read(R"({"schema": "agile-cell/quote", "order": "oem-a-q1", "feasible": false, "reason": "no Shaft"})", why);
  CHECK(no["reason"] == "no Shaft");
}

TEST_CASE("quote answers: wrong kinds, numbers that are no numbers >= 0, another order, deep nesting are refused with a reason",
          "[cellctl][quote]") {
  const auto refused = [](const std::string& text, const std::string& says) {
    std::string why;
    const auto q = read(text, why);
    INFO(text << " -> " << why);
    CHECK(q.is_null());
    CHECK(why.find(says) != std::string::npos);
  };
  std::string good = kGood;
  const auto with = [&good](const std::string& from, const std::string& to) {
    std::string t = good;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  refused("not json", "is not a quote");
  refused("[1, 2]", "is not a quote");
  refused(with(R"("feasible": true)", R"("feasible": "yes")"), "is not a quote");
  refused(with(R"("schema": "agile-cell/quote")", R"("schema": 7)"), "is not a quote");
  refused(with(R"("order": "oem-a-q1")", R"("order": "oem-a-earlier")"), "is not the answer to this request");
  refused(with(R"("makespan": 26.6)", R"("makespan": -1)"), "time_s.makespan is not a number >= 0");
  refused(with(R"("makespan": 26.6)", R"("makespan": 1e999)"), "is not a quote");  // the parser refuses an overflow
  refused(with(R"("total": 41.26)", R"("total": "41")"), "cost.total is not a number >= 0");
  refused(with(R"("cost": {"currency": "EUR", "setup": 40, "station": 1.1, "robot": 0.16, "total": 41.26})", R"("cost": [1])"),
          "cost.setup is not a number >= 0");
  refused(std::string(100000, '[') + std::string(100000, ']'), "is not a quote");
  // A reason that is not text, deep findings: the quote stands, without them.
  std::string why;
  const auto odd = read(R"({"schema": "agile-cell/quote", "order": "oem-a-q1", "feasible": false, "reason": 7,
                            "findings": [[[[[[[[[[{"kind": "x", "message": "y"}]]]]]]]]]]})", why);
  REQUIRE(odd.is_object());
  CHECK(odd["reason"] == "(the cell gave no reason)");
  CHECK(odd["findings"].empty());
}

TEST_CASE("quote answers: the submission id is one the desk takes, and new each time", "[cellctl][quote]") {
  const std::string a = cellctl::quote_submission_id("/x/gear box (v2).aml");
  const std::string b = cellctl::quote_submission_id("/x/gear box (v2).aml");
  CHECK(a != b);
  CHECK(a.rfind("quote-gear-box--v2--", 0) == 0);
  CHECK(a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") == std::string::npos);
  CHECK(cellctl::quote_submission_id(std::string(200, 'p') + ".aml").size() <= 64);
}
