#pragma once
// The chaos run of the durable-state issue, shared by the CI test (short) and the bench
// program (full): a cell of `cellctl up` takes N orders; a killer SIGKILLs a random process
// of the cell every 2-5 s of wall time (a resource, cell-sim, a twin, and once cellctl up
// itself, which is then started again on the same state, as an operator or systemd would).
// Measured: the conservation of every part type at every tick (read from the database, as
// `cellctl status --json` reads it), each kill's recovery time (from the kill until the
// killed process is back and the cell's ledger or an order's state moved again), and how
// the orders ended.

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "services/state/cell_store.hpp"
#include "tests/support/cell_test.hpp"
#include "tests/support/child_process.hpp"
#include "tests/support/order_twins.hpp"

namespace test {

struct ChaosOptions {
  std::filesystem::path dir;  // scratch: logs, outputs, the state folder
  std::string cell;           // deployment file
  int domain = 0;
  int orders = 10, kills = 20;
  std::string real_time_factor = "10";
  unsigned seed = 1;
  // Killed first, where they run, before the random picks: process names ("twin": one that
  // has its order). A short run's random picks may miss a kind the test means to kill.
  std::vector<std::string> first_victims;
  std::chrono::seconds order_timeout{600};  // for all orders to end after the last kill
  std::function<void(const std::string&)> log = [](const std::string&) {};
};

struct ChaosResult {
  std::vector<std::string> kills;    // "t=12.3 s mobile-robot-2 (pid 123)"
  std::vector<double> recovery_s;    // per kill that had an order open and saw it move again
  int not_measured = 0;              // kills after which no order was left to move
  int assembled = 0, failed = 0, unfinished = 0;
  std::vector<std::string> failures;  // "order: reason"
  long conservation_checks = 0;
  std::vector<std::string> conservation_violations;
  nlohmann::json status;              // cellctl status --json once every order ended
  bool down_ok = false;
  std::vector<std::string> processes_left;  // after cellctl down: processes still on the domain
  std::string integrity;
  std::size_t holds_left = 0;
};

// Processes whose command line has `--domain <domain>`.
inline std::vector<std::string> processes_on_domain(int domain) {
  std::vector<std::string> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (name == std::to_string(::getpid())) continue;  // bench_chaos --domain N itself
    std::ifstream in(entry.path() / "cmdline", std::ios::binary);
    std::vector<std::string> args;
    for (std::string a; std::getline(in, a, '\0');) args.push_back(a);
    for (std::size_t i = 0; i + 1 < args.size(); ++i) {
      if (args[i] == "--domain" && args[i + 1] == std::to_string(domain)) {
        out.push_back(args[0] + " (pid " + name + ")");
        break;
      }
    }
  }
  return out;
}

namespace chaos_detail {

// What identifies a cell process across restarts: a twin's order (on its command line, or for
// a standby twin in the journal), a resource's id, or its name.
inline std::string identity_of(pid_t pid, const std::string& name, const state::CellStore& store) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::vector<std::string> args;
  for (std::string a; std::getline(in, a, '\0');) args.push_back(a);
  for (std::size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--order" || args[i] == "--id") return args[i + 1];
  }
  const std::string order = order_of_twin(store, pid);
  return order.empty() ? name : order;
}

// The live process of cellctl up `up` that `identity` names, or 0.
inline pid_t process_of(pid_t up, const std::string& identity, const state::CellStore& store) {
  if (const pid_t pid = child_with_argument(up, identity)) return pid;
  const pid_t twin = twin_of(store, identity);
  return twin > 0 && is_running(twin) ? twin : 0;
}

// The ledger and the orders' states as one string: it changes when anything moved.
inline std::string fingerprint(const state::CellStore& store) {
  std::ostringstream out;
  for (const auto& p : store.parts()) out << p.order << p.part << state::place_name(p.place) << ';';
  for (const auto& o : store.orders()) out << o.order << o.state << ';';
  return out.str();
}

}  // namespace chaos_detail

inline ChaosResult run_chaos(const ChaosOptions& o) {
  namespace fs = std::filesystem;
  using namespace std::chrono_literals;
  using Clock = std::chrono::steady_clock;
  ChaosResult r;
  const fs::path state_dir = o.dir / "state";
  const std::string domain = std::to_string(o.domain);
  int up_count = 0;
  const auto start_up = [&] {
    const fs::path log = o.dir / ("up-" + std::to_string(++up_count) + ".log");
    auto up = std::make_unique<ChildProcess>(std::vector<std::string>{CELLCTL_EXE, "up", o.cell, "--domain", domain,
                                                                      "--real-time-factor", o.real_time_factor,
                                                                      "--state-dir", state_dir.string()},
                                             log.string());
    appears(log, "cell up on domain", 60s);
    return up;
  };
  clean_stale_dds_segments();
  auto up = start_up();
  const Clock::time_point t0 = Clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };

  std::vector<std::unique_ptr<ChildProcess>> submits;
  for (int i = 0; i < o.orders; ++i) {
    const std::string product = i % 2 == 0 ? std::string(PRODUCTS_DIR) + "/lego-tower/lego-tower.aml"
                                           : std::string(PRODUCTS_DIR) + "/cranfield/cranfield.aml";
    const std::string id = "order-" + std::to_string(i + 1);
    submits.push_back(std::make_unique<ChildProcess>(
        std::vector<std::string>{CELLCTL_EXE, "submit", product, "--domain", domain, "--order", id, "--out",
                                 (o.dir / id).string()},
        (o.dir / (id + ".log")).string()));
  }

  state::CellStore store(state_dir);
  std::mt19937 random(o.seed);
  std::vector<std::string> first_victims = o.first_victims;
  const auto next_gap = [&] { return std::chrono::milliseconds(2000 + random() % 3001); };
  Clock::time_point next_kill = Clock::now() + next_gap();
  struct Pending {
    Clock::time_point at;
    std::string identity;
    pid_t old_pid = 0;
    bool is_up = false, back = false;
    std::string seen;  // the fingerprint once the victim was back
  };
  std::vector<Pending> pending;
  const auto open_orders = [&] {
    for (const auto& order : store.orders()) {
      if (!order.ended()) return true;
    }
    return false;
  };
  const auto submits_running = [&] {
    return std::any_of(submits.begin(), submits.end(), [](const auto& s) { return is_running(s->pid()); });
  };
  const Clock::time_point give_up_at = Clock::now() + o.order_timeout + std::chrono::seconds(5 * o.kills);

  while (Clock::now() < give_up_at) {
    // Conservation at every tick.
    ++r.conservation_checks;
    for (const auto& [type, c] : store.inventory()) {
      if (c.initial != c.accounted()) {
        r.conservation_violations.push_back("t=" + std::to_string(seconds()) + " " + type + ": initial " +
                                            std::to_string(c.initial) + ", accounted " + std::to_string(c.accounted()));
      }
    }
    // Recoveries.
    const std::string now_print = chaos_detail::fingerprint(store);
    for (auto it = pending.begin(); it != pending.end();) {
      if (!it->back) {
        const pid_t pid = it->is_up ? (is_running(up->pid()) ? up->pid() : 0) : chaos_detail::process_of(up->pid(), it->identity, store);
        const bool order_ended = [&] {
          for (const auto& order : store.orders()) {
            if (order.order == it->identity) return order.ended();
          }
          return false;
        }();
        if ((pid > 0 && pid != it->old_pid) || order_ended) {
          it->back = true;
          it->seen = now_print;
        }
      } else if (now_print != it->seen) {
        r.recovery_s.push_back(std::chrono::duration<double>(Clock::now() - it->at).count());
        it = pending.erase(it);
        continue;
      }
      if (!open_orders()) {
        ++r.not_measured;
        it = pending.erase(it);
        continue;
      }
      ++it;
    }
    // The killer.
    if (static_cast<int>(r.kills.size()) < o.kills && Clock::now() >= next_kill) {
      next_kill = Clock::now() + next_gap();
      if (static_cast<int>(r.kills.size()) == o.kills / 2) {
        const pid_t old = up->pid();
        const auto children = children_of(old);
        r.kills.push_back("t=" + std::to_string(seconds()) + " cellctl up (pid " + std::to_string(old) + ")");
        pending.push_back({Clock::now(), "cellctl up", old, true, false, ""});
        up->kill_hard();
        // Its processes end with it (they asked for SIGTERM when their parent goes): the
        // operator starts it again once they are gone.
        const auto deadline = Clock::now() + 30s;
        const auto any_left = [&] {
          return std::any_of(children.begin(), children.end(), [](const auto& c) { return is_running(c.second); });
        };
        while (any_left() && Clock::now() < deadline) std::this_thread::sleep_for(50ms);
        up = start_up();
      } else if (const auto children = children_of(up->pid()); !children.empty()) {
        std::size_t pick = children.size();
        for (std::size_t k = 0; k < first_victims.size() && pick == children.size(); ++k) {
          for (std::size_t i = 0; i < children.size() && pick == children.size(); ++i) {
            const auto& [name, pid] = children[i];
            if (name == first_victims[k] && (name != "twin" || chaos_detail::identity_of(pid, name, store) != name)) pick = i;
          }
          if (pick != children.size()) first_victims.erase(first_victims.begin() + static_cast<long>(k));
        }
        if (pick == children.size()) pick = random() % children.size();
        const auto& [name, pid] = children[pick];
        const std::string identity = chaos_detail::identity_of(pid, name, store);
        ::kill(pid, SIGKILL);
        r.kills.push_back("t=" + std::to_string(seconds()) + " " + identity + " (pid " + std::to_string(pid) + ")");
        pending.push_back({Clock::now(), identity, pid, false, false, ""});
      }
      o.log(r.kills.back());
    }
    if (static_cast<int>(r.kills.size()) >= o.kills && !submits_running()) break;
    std::this_thread::sleep_for(50ms);
  }
  r.not_measured += static_cast<int>(pending.size());

  for (const auto& order : store.orders()) {
    if (order.state == "DONE") {
      ++r.assembled;
    } else if (order.state == "FAILED") {
      ++r.failed;
      r.failures.push_back(order.order + ": " + order.reason);
    } else {
      ++r.unfinished;
      r.failures.push_back(order.order + ": still " + order.state);
    }
  }
  // The last status once the cell is whole again (bounded): a process killed near the end is
  // still coming back, and a killed cell-sim brings every other process back after it.
  const fs::path status = o.dir / "status.json";
  const auto whole = [&] {
    if (cellctl({"status", "--json", "--cell", o.cell, "--domain", domain}, status, 30s) != 0) return false;
    r.status = nlohmann::json::parse(read_text(status), nullptr, false);
    if (!r.status.is_object() || !r.status["resources"].is_array()) return false;
    for (const auto& resource : r.status["resources"]) {
      if (resource["alive"] != true) return false;
    }
    return true;
  };
  const auto settle_by = Clock::now() + 60s;
  while (!whole() && Clock::now() < settle_by) std::this_thread::sleep_for(1s);
  r.down_ok = cellctl({"down", "--cell", o.cell, "--domain", domain}, o.dir / "down.log", 30s) == 0;
  up->wait_for_exit(20s);
  const auto deadline = Clock::now() + 10s;
  while (!(r.processes_left = processes_on_domain(o.domain)).empty() && Clock::now() < deadline) {
    std::this_thread::sleep_for(100ms);
  }
  r.integrity = store.integrity();
  r.holds_left = store.holders().size();
  return r;
}

}  // namespace test
