#include "deploy/cellctl/quote_command.hpp"

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/quote_answer.hpp"
#include "deploy/cellctl/remote_submit.hpp"
#include "deploy/cellctl/text_table.hpp"

namespace cellctl {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::atomic<bool> stop_quoting{false};  // set by a signal handler
void stop_quoting_on_signal(int) { stop_quoting = true; }

struct QuoteOptions {
  std::string product, client, out = "quotes", json_file, sequence = "search";
  std::vector<std::string> cells;
  double wait_s = 30;
};

struct Asked {
  std::string name;  // the deployment file's stem (made unique)
  CellConfig cell;
  RemoteSubmission submission;
  int exit_code = -1;
  std::string error;  // why it gave no answer
  json quote;         // its quote.json; null: none came
};

std::string unique_name(std::string name, std::set<std::string>& taken) {
  std::string candidate = name;
  for (int i = 2; taken.count(candidate); ++i) candidate = name + "-" + std::to_string(i);
  taken.insert(candidate);
  return candidate;
}

// "8 margin, 2 collision" of a checked quote (read_quote).
std::string findings_summary(const json& q) {
  std::map<std::string, int> kinds;
  for (const auto& f : q["findings"]) ++kinds[f["kind"].get<std::string>()];
  std::string out;
  for (const auto& [kind, n] : kinds) out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
  return out.empty() ? "none" : out;
}

int run_quotes(const QuoteOptions& o) {
  std::vector<std::unique_ptr<Asked>> asked;
  std::set<std::string> names;
  std::set<int> domains;
  const std::string submission = quote_submission_id(o.product);
  for (const auto& file : o.cells) {
    auto a = std::make_unique<Asked>();
    a->cell = read_cell_config(file);
    if (!domains.insert(a->cell.domain).second) {
      throw ConfigError(file + ": domain " + std::to_string(a->cell.domain) + " is another cell's too: each cell quotes on its own domain");
    }
    a->name = unique_name(fs::path(file).stem().string(), names);
    a->submission = RemoteSubmission{o.product, o.client, submission, (fs::path(o.out) / a->name).string(),
                                     o.sequence, a->cell.participant_settings(o.client),
                                     std::chrono::seconds(static_cast<long>(o.wait_s)), true, "[" + a->name + "] "};
    asked.push_back(std::move(a));
  }
  std::signal(SIGINT, stop_quoting_on_signal);
  {
    std::vector<std::thread> threads;
    for (auto& a : asked) {
      std::error_code ignored;  // an answer of an earlier run must not pass for this one's
      fs::remove(fs::path(a->submission.out) / "quote.json", ignored);
      threads.emplace_back([&a] {
        try {
          a->exit_code = submit_remote(a->submission, stop_quoting, &a->error);
        } catch (const std::exception& e) {
          a->error = e.what();
          std::cerr << "[" << a->name << "] error: " << a->error << '\n';
          a->exit_code = 1;
        }
      });
    }
    for (auto& t : threads) t.join();
  }

  // The comparison: every cell's answer, the best feasible one by time and by cost.
  const Asked* fastest = nullptr;
  const Asked* cheapest = nullptr;
  json cells = json::array();
  for (auto& a : asked) {
    std::string why;
    if (stop_quoting) why = "stopped before it answered";
    else if (a->exit_code == 0) a->quote = read_quote(fs::path(a->submission.out) / "quote.json", o.client + "-" + submission, why);
    else why = a->error.empty() ? "its desk ended the request with exit " + std::to_string(a->exit_code) : a->error;
    json entry = {{"cell", a->name}, {"file", fs::absolute(a->cell.file).string()}, {"domain", a->cell.domain},
                  {"results", a->submission.out}};
    if (a->quote.is_null()) {
      a->error = why;
      entry["answered"] = false;
      entry["reason"] = why;
    } else {
      entry["answered"] = true;
      entry["quote"] = a->quote;
      if (a->quote["feasible"].get<bool>()) {
        const auto time = [](const Asked* x) { return x->quote["time_s"]["makespan"].get<double>(); };
        const auto cost = [](const Asked* x) { return x->quote["cost"]["total"].get<double>(); };
        if (!fastest || time(a.get()) < time(fastest)) fastest = a.get();
        if (!cheapest || cost(a.get()) < cost(cheapest)) cheapest = a.get();
      }
    }
    cells.push_back(entry);
  }

  TextTable table({"cell", "feasible", "makespan s", "wait s", "cost", "station", "findings", "best"});
  for (const auto& a : asked) {
    const json& q = a->quote;
    if (q.is_null()) {
      table.add_row({a->name, "no answer", "-", "-", "-", "-", a->error, ""});
      continue;
    }
    if (!q["feasible"].get<bool>()) {
      table.add_row({a->name, "no", "-", "-", "-", "-", q["reason"].get<std::string>(), ""});
      continue;
    }
    std::string best;
    if (a.get() == fastest) best = "time";
    if (a.get() == cheapest) best += best.empty() ? "cost" : ", cost";
    table.add_row({a->name, "yes", fixed(q["time_s"]["makespan"].get<double>(), 1), fixed(q["time_s"]["wait"].get<double>(), 1),
                   fixed(q["cost"]["total"].get<double>(), 2) + " " + q["cost"]["currency"].get<std::string>(),
                   q["station"].get<std::string>(), findings_summary(q), best});
  }
  std::cout << "\nquotes for " << fs::path(o.product).filename().string() << ":\n";
  table.print(std::cout);

  const json all = {{"schema", "agile-cell/quotes"}, {"version", 1}, {"product", fs::absolute(o.product).string()},
                    {"cells", cells}, {"best_time", fastest ? json(fastest->name) : json()},
                    {"best_cost", cheapest ? json(cheapest->name) : json()}};
  const fs::path json_file = o.json_file.empty() ? fs::path(o.out) / "quotes.json" : fs::path(o.json_file);
  if (json_file.has_parent_path()) fs::create_directories(json_file.parent_path());
  // Text from the cells (reasons, findings) is written as it came; bytes that are not UTF-8 are replaced.
  if (!(std::ofstream(json_file) << all.dump(2, ' ', false, json::error_handler_t::replace) << '\n')) {
    std::cerr << "error: cannot write " << json_file.string() << '\n';
    return 1;
  }
  std::cout << "wrote " << json_file.string() << "; each cell's report.html and quote.json are in " << o.out << "/CELL/\n";
  return fastest ? 0 : 1;
}

}  // namespace

void add_quote_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<QuoteOptions>();
  CLI::App* cmd = app.add_subcommand("quote", "Ask several cells for a quote for a product (virtual assembly only) and compare them");
  cmd->add_option("product", o->product, "The product's AutomationML file")->required()->check(CLI::ExistingFile);
  cmd->add_option("--cell", o->cells, "A cell's deployment file (repeat): its domain, network and security")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--client", o->client, "Our client id at the cells (their `clients:`; with security, our identity)")->required();
  cmd->add_option("--out", o->out, "Folder for each cell's answer (OUT/CELL/) and quotes.json");
  cmd->add_option("--json", o->json_file, "Write the comparison here instead of OUT/quotes.json");
  cmd->add_option("--sequence", o->sequence, "Sequence planner the cells use")->check(CLI::IsMember({"search", "paper"}));
  cmd->add_option("--wait", o->wait_s, "How long each cell's desk may take to answer at all, s")->check(CLI::PositiveNumber);
  cmd->callback([o, &exit_code] { exit_code = run_quotes(*o); });
}

}  // namespace cellctl
