#include "deploy/cellctl/cell_commands.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"
#include "deploy/cellctl/cell_roster.hpp"
#include "deploy/cellctl/cell_status.hpp"
#include "deploy/cellctl/dashboard.hpp"
#include "deploy/cellctl/host_limits.hpp"
#include "deploy/cellctl/order_desk.hpp"
#include "deploy/cellctl/order_intake.hpp"
#include "deploy/cellctl/processes.hpp"
#include "deploy/cellctl/remote_desk.hpp"
#include "deploy/cellctl/remote_submit.hpp"
#include "deploy/cellctl/resource_service.hpp"
#include "deploy/cellctl/supervisor.hpp"
#include "deploy/cellctl/text_table.hpp"
#include "deploy/cellctl/twin_identities.hpp"
#include "deploy/cellctl/twin_pool.hpp"
#include "services/state/cell_store.hpp"

namespace cellctl {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::atomic<bool> stop_requested{false};  // set by a signal handler
void request_stop(int) { stop_requested = true; }

struct CellOptions {
  std::string cell = CELL_DEFAULT_FILE;
  int domain = -1;  // -1: the file's
  double real_time_factor = 0;
  double wait_s = 30;
  std::string state_dir;
  std::string security_dir;
  std::vector<std::string> interfaces, peers, discovery_servers;

  CellConfig load() const;
};

void add_cell_options(CLI::App* cmd, CellOptions& o) {
  cmd->add_option("--cell", o.cell, "Deployment file of the cell")->check(CLI::ExistingFile);
  cmd->add_option("--domain", o.domain, "DDS domain id, instead of the file's")->check(CLI::Range(0, 232));
  cmd->add_option("--real-time-factor", o.real_time_factor, "Instead of the file's")->check(CLI::PositiveNumber);
  cmd->add_option("--state-dir", o.state_dir, "Folder of the cell's database, instead of the file's state_dir");
  cmd->add_option("--security", o.security_dir, "DDS-Security: the folder `cellctl pki init` wrote, instead of the file's")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--interface", o.interfaces, "Use this IPv4 address of the host (repeat), instead of the file's network");
  cmd->add_option("--peer", o.peers, "Look for participants at this IPv4 address too (another host; repeat)");
  cmd->add_option("--discovery-server", o.discovery_servers, "The cell's discovery servers, IP:PORT (repeat), instead of the file's")
      ->check(dds::server_address_problem);
  cmd->add_option("--wait", o.wait_s, "How long the cell's resources may take to be heard on DDS, s: a twin's wait for "
                                      "them; for up, at its start and for a process that goes silent (then restarted)")
      ->check(CLI::PositiveNumber);
}

fs::path pid_file(int domain) {
  const char* tmp = std::getenv("TMPDIR");
  return fs::path(tmp ? tmp : "/tmp") / ("agile-cell-" + std::to_string(domain) + ".pid");
}

bool is_cellctl_up(pid_t pid) {
  std::ifstream cmdline("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::vector<std::string> args;
  for (std::string arg; std::getline(cmdline, arg, '\0');) args.push_back(arg);
  return !args.empty() && fs::path(args[0]).filename() == "cellctl" &&
         std::find(args.begin(), args.end(), "up") != args.end();
}

// The pid file's pid and the state folder of the cell.
std::pair<pid_t, std::string> read_pid_file(int domain) {
  std::ifstream file(pid_file(domain));
  pid_t pid = 0;
  std::string dir;
  if (!(file >> pid) || pid <= 0) return {0, ""};
  file >> std::ws;
  std::getline(file, dir);
  return {pid, dir};
}

// The pid of the `cellctl up` that runs the cell on the domain, or 0. A pid file left by an
// up that was killed (its processes ended with it) is stale: `stale` says so, and it goes,
// so that no other process that got the same pid is ever signalled.
pid_t running_up(int domain, bool& stale) {
  const pid_t pid = read_pid_file(domain).first;
  stale = pid > 0 && !is_cellctl_up(pid);
  if (stale) fs::remove(pid_file(domain));
  return stale ? 0 : pid;
}

// The state folder of the cell `cellctl up` runs on the domain, or "".
std::string running_state_dir(int domain) {
  const auto [pid, dir] = read_pid_file(domain);
  return pid > 0 && is_cellctl_up(pid) ? dir : "";
}

// The state folder: --state-dir, else that of the cell running on the domain (submit and
// status talk to it), else the file's.
CellConfig CellOptions::load() const {
  CellConfig c = read_cell_config(cell);
  if (domain >= 0) c.domain = domain;
  if (real_time_factor > 0) c.real_time_factor = real_time_factor;
  if (!security_dir.empty()) c.security_dir = fs::absolute(security_dir);
  if (!interfaces.empty()) c.interfaces = interfaces;
  if (!peers.empty()) c.peers = peers;
  if (!discovery_servers.empty()) {
    c.discovery_servers = discovery_servers;
    c.simple_discovery = false;
    c.discovery_given = true;
  }
  if (!c.security_dir.empty() && !c.simple_discovery) {
    throw ConfigError(cell + ": discovery through a server does not work with security: on Fast DDS 2.9 a secure cell uses "
                      "simple discovery (discovery: simple)");
  }
  if (!state_dir.empty()) {
    c.state_dir = state_dir;
  } else if (const std::string running = running_state_dir(c.domain); !running.empty()) {
    c.state_dir = running;
  }
  return c;
}

[[noreturn]] void cell_did_not_come_up(const std::vector<std::string>& missing, std::chrono::milliseconds waited) {
  std::string list;
  for (const auto& m : missing) list += " " + m;
  throw std::runtime_error("the cell did not come up within " + std::to_string(waited.count() / 1000) + " s; missing:" + list);
}

// Until every resource of the file has published its capability; throws naming the missing.
void wait_for_cell(const CellConfig& cell, CellObserver& observer, std::chrono::milliseconds wait) {
  const auto missing = observer.wait_for_resources(cell.resource_ids(), wait);
  if (!missing.empty()) cell_did_not_come_up(missing, wait);
}

// Throws ConfigError naming each limit of this host that the cell with `twins` twins at once
// would pass (host_limits.hpp); `what`: where those twins come from.
void check_host_limits(const CellConfig& cell, std::size_t twins, const std::string& what) {
  const auto problems = limit_problems(cell, cell_processes(cell, executable_dir()).size(), twins, read_host_limits());
  if (problems.empty()) return;
  std::string text = cell.file.string() + ": the cell with " + std::to_string(twins) + " " + what + " does not fit this host";
  for (const auto& p : problems) text += "\n  " + p;
  throw ConfigError(text);
}

// The resources alive on DDS now.
std::set<std::string> heard_resources(const CellObserver& observer) {
  std::set<std::string> heard;
  for (const auto& [id, r] : observer.resources()) {
    if (r.alive) heard.insert(id);
  }
  return heard;
}

// The cell's processes, started in order; cell-sim first, as the others wait for it.
// Each beats on `heartbeats` (named to children before): one whose heartbeat stops is hung.
class RunningCell {
 public:
  RunningCell(const CellConfig& cell, CellObserver& observer, std::chrono::milliseconds wait, HeartbeatSocket& heartbeats)
      : heartbeats_(heartbeats) {
    for (const auto& spec : cell_processes(cell, executable_dir())) {
      processes_.push_back(std::make_unique<Process>(spec.name, spec.argv));
      heartbeats_.watch(processes_.back()->pid());
    }
    wait_for_cell(cell, observer, wait);
  }
  ~RunningCell() { stop(); }

  // Ends each process that runs but has not beaten for `silence` (its loop stuck): a run does
  // not restart its cell, so ended() then names it as a fault, and the orders that wait for
  // it end at their own waits rather than never.
  void end_hung(HeartbeatSocket::Clock::duration silence) {
    const auto stopped = heartbeats_.stopped(silence);
    for (auto& p : processes_) {
      const auto beat = stopped.find(p->pid());
      if (beat == stopped.end() || p->poll() >= 0) continue;
      std::cerr << "error: " << p->name() << " runs but " << beat->second << "; ending it" << std::endl;
      heartbeats_.forget(p->pid());
      p->stop(std::chrono::seconds(2));
    }
  }

  // A process that ended by itself, or nullptr.
  Process* ended() {
    for (auto& p : processes_) {
      if (p->poll() >= 0) return p.get();
    }
    return nullptr;
  }

  void forget(Process* process) {
    processes_.erase(std::remove_if(processes_.begin(), processes_.end(),
                                    [&](const auto& p) { return p.get() == process; }),
                     processes_.end());
  }

  std::vector<std::pair<std::string, long>> peak_rss() const {
    std::vector<std::pair<std::string, long>> out;
    for (const auto& p : processes_) out.emplace_back(p->name(), p->peak_rss_kb());
    return out;
  }

  void stop() {
    std::vector<Process*> all;
    for (auto& p : processes_) all.push_back(p.get());
    stop_all(all);
    processes_.clear();
  }

 private:
  HeartbeatSocket& heartbeats_;
  std::vector<std::unique_ptr<Process>> processes_;
};

const char* state_name(cell::OrderState state) {
  static const char* names[] = {"SUBMITTED", "PLANNING", "VIRTUAL_ASSEMBLY", "WAITING", "PHYSICAL_ASSEMBLY", "DONE",
                                "FAILED"};
  return names[state];
}

void print_progress(const cell::OrderStatus& s) {
  std::cout << "[" << s.order_id() << "] t=" << fixed(s.sim_time(), 1) << " s  " << state_name(s.state()) << "  "
            << static_cast<int>(s.progress() * 100) << "%  " << s.message() << std::endl;
}

struct SubmitOptions {
  std::vector<std::string> products;
  std::string order, out, sequence = "search", path = "linear";
  bool remote = false;
  bool detach = false;
  std::string client;
};

void add_submit_options(CLI::App* cmd, SubmitOptions& o, bool several) {
  auto* products = cmd->add_option("PRODUCT", o.products, several ? "AutomationML files (.aml): one order each" : "AutomationML file (.aml)")
                       ->required()
                       ->check(CLI::ExistingFile);
  if (!several) products->expected(1);
  cmd->add_option("--order", o.order, "Order id (one product only; default: the product's name)");
  cmd->add_option("--out", o.out, "The order's folder (one product), or the folder of one folder per order "
                                  "(default: out/ORDER)");
  cmd->add_option("--sequence", o.sequence, "Sequence planner")->check(CLI::IsMember({"paper", "search"}));
  cmd->add_option("--path", o.path, "Path planner")->check(CLI::IsMember({"linear", "ompl"}));
}

struct Order {
  std::string id, product, out;
  std::unique_ptr<Process> twin;
  int exit_code = -1;
  double sim_start = 0, sim_end = 0;
  long peak_rss_kb = 0;
  std::string ended_why = {};  // why the twin was ended, where this cellctl ended it
};

// One order per product: ids from the product files' stems, numbered where one repeats.
std::vector<Order> orders_of(const SubmitOptions& o) {
  if (!o.order.empty() && o.products.size() > 1) throw CLI::ValidationError("--order", "names one order; give one product");
  std::vector<Order> out;
  std::map<std::string, int> seen;
  for (const auto& product : o.products) {
    const std::string stem = fs::path(product).stem().string();
    const int n = ++seen[stem];
    std::string id = o.order.empty() ? (n == 1 ? stem : stem + "-" + std::to_string(n)) : o.order;
    std::string folder = o.products.size() == 1 && !o.out.empty() ? o.out
                                                                   : (fs::path(o.out.empty() ? "out" : o.out) / id).string();
    out.push_back({id, product, folder, nullptr});
  }
  return out;
}

// With security each twin at once needs an identity of its own (twin_identities.hpp).
void check_identities_for(const CellConfig& cell, std::size_t orders) {
  if (!cell.security_dir.empty() && orders > static_cast<std::size_t>(cell.twin_identities)) {
    throw ConfigError(cell.file.string() + ": " + std::to_string(orders) + " orders at once need as many twin identities; " +
                      "twin_identities is " + std::to_string(cell.twin_identities));
  }
}

// Starts a twin per order, or hands each order to a twin of `standby` where one stands by,
// and follows them to their ends, printing their progress. At most the deployment's
// max_twins run at once, as in `up`'s queue; the other orders wait their turn, in order.
// (Sixty twins at once on two cores: every new twin's endpoints discovered by every other
// process took 20-45 s, and orders failed waiting for the cell.) A twin that runs but whose
// heartbeat stops for the cell's twin_watchdog is ended, and its order fails saying so (`up`'s
// desk starts another for it; a run has no queue to take it up). `tend`: the cell's own
// care between the looks.
void run_orders(const CellConfig& cell, const SubmitOptions& o, std::vector<Order>& orders, CellObserver& observer,
                double wait_s, TwinIdentities& identities, HeartbeatSocket& heartbeats, TwinPool* standby = nullptr,
                const std::function<void()>& tend = {}) {
  std::set<std::string> ids;
  for (const auto& order : orders) ids.insert(order.id);
  observer.on_status([ids](const cell::OrderStatus& s) {
    if (ids.count(s.order_id().to_string())) print_progress(s);
  });
  const auto start = [&](Order& order) {
    order.sim_start = observer.sim_now();
    // `run` gives its state folder; a submit to processes started by hand gives the file's, if any.
    if (standby) {
      order.twin = standby->take("twin-" + order.id, order.id,
                                 twin_order_args(cell, order.id, order.product, order.out, o.sequence, o.path,
                                                 cell.state_dir, wait_s, false))
                       .process;
    }
    if (!order.twin) {
      order.twin = identities.start(order.id, twin_argv(cell, executable_dir(), order.id, order.product, order.out,
                                                        o.sequence, o.path, cell.state_dir, wait_s))
                       .process;  // check_identities_for: there is an identity for each
    }
    heartbeats.watch(order.twin->pid());
    std::cout << "order " << order.id << ": twin pid " << order.twin->pid() << std::endl;
  };
  const auto end_unheard_twins = [&] {
    const auto stopped = heartbeats.past_twin_watchdog(cell.twin_watchdog);
    for (auto& order : orders) {
      if (!order.twin || order.exit_code >= 0) continue;
      const auto beat = stopped.find(order.twin->pid());
      if (beat == stopped.end()) continue;
      order.ended_why = "its twin ran but " + beat->second + "; ended";
      std::cerr << "error: order " << order.id << ": " << order.ended_why << std::endl;
      heartbeats.forget(order.twin->pid());
      order.twin->stop(std::chrono::seconds(2));
    }
  };
  const std::size_t at_once = static_cast<std::size_t>(cell.max_twins);
  if (orders.size() > at_once) {
    std::cout << orders.size() - at_once << " of " << orders.size() << " orders wait for a twin (max_twins: "
              << at_once << " at once)" << std::endl;
  }
  std::size_t next = 0;  // the first order not started
  for (std::size_t running = 0;; running = 0) {
    std::vector<Process*> twins;
    for (auto& order : orders) {
      if (!order.twin || order.exit_code >= 0) continue;
      twins.push_back(order.twin.get());
      order.peak_rss_kb = std::max(order.peak_rss_kb, order.twin->peak_rss_kb());
      order.exit_code = order.twin->poll();
      running += order.exit_code < 0;
    }
    if (stop_requested) {
      for (; next < orders.size(); ++next) orders[next].exit_code = 1;  // never started
      if (running > 0) stop_all(twins);  // each says why it stopped, at once
    }
    for (; next < orders.size() && running < at_once; ++next, ++running) start(orders[next]);
    if (running == 0 && next == orders.size()) break;
    end_unheard_twins();
    if (standby) standby->tend();
    if (tend) tend();
    std::this_thread::sleep_for(50ms);
  }
  observer.on_status({});
  const auto statuses = observer.orders();
  for (auto& order : orders) {
    const auto it = statuses.find(order.id);
    order.sim_end = it != statuses.end() ? it->second.sim_time() : observer.sim_now();
  }
}

// Hands the order to the desk of the cell `cellctl up` runs (its database), and follows it to
// its end: the twin's exit code (0 assembled, 1 failed, 2 a bad product description; 3 when no
// cell has run on the domain for a minute: the order waits in the state for the next up).
// Stores the order for the desk of the cell `cellctl up` runs; false (and why, on stderr)
// when the cell has an order of that id.
bool hand_to_desk(state::CellStore& store, const SubmitOptions& o, const Order& order) {
  const std::string product = fs::absolute(order.product).string(), out = fs::absolute(order.out).string();
  if (!store.submit_order({order.id, "", "", product, out, o.sequence, o.path})) {
    for (const auto& known : store.orders()) {
      if (known.order == order.id) {
        std::cerr << "error: the cell has an order " << order.id << " already (" << known.state
                  << "); give this one another id with --order\n";
      }
    }
    return false;
  }
  store.journal("cellctl", "submitted", order.id, product);
  return true;
}

int submit_to_desk(const CellConfig& cell, const SubmitOptions& o, const Order& order, CellObserver& observer) {
  state::CellStore store(cell.state_folder());
  if (!hand_to_desk(store, o, order)) return 1;
  const std::string out = fs::absolute(order.out).string();
  observer.on_status([id = order.id](const cell::OrderStatus& s) {
    if (s.order_id().to_string() == id) print_progress(s);
  });
  auto cell_seen = std::chrono::steady_clock::now();
  std::string last_place;
  for (;;) {
    if (!running_state_dir(cell.domain).empty()) cell_seen = std::chrono::steady_clock::now();
    if (std::chrono::steady_clock::now() - cell_seen > 60s) {  // a paused cell that does not come back
      observer.on_status({});
      std::cerr << "error: no cell has run on domain " << cell.domain << " for 60 s; order " << order.id
                << " waits in the cell's state (" << cell.state_folder().string()
                << "), and the next `cellctl up` on it takes the order up\n";
      return 3;
    }
    const auto orders = store.orders();
    if (const std::string place = OrderDesk::place_text(OrderDesk::queue(orders), order.id); !place.empty()) {
      if (place != last_place) std::cout << "[" << order.id << "] waits in the cell's queue, " << place << std::endl;
      last_place = place;
    }
    for (const auto& known : orders) {
      if (known.order != order.id || !known.ended() || known.exit_code < 0) continue;
      observer.on_status({});
      if (known.state == "DONE") std::cout << "order " << order.id << " done: " << out << "/report.html, " << out << "/plan.json, " << out << "/animation.gltf\n";
      if (known.state == "FAILED") std::cerr << "error: order " << order.id << ": " << known.reason << '\n';
      return known.exit_code;
    }
    if (stop_requested) {
      observer.on_status({});
      std::cout << "order " << order.id << " goes on in the cell; `cellctl status` follows it\n";
      return 0;
    }
    std::this_thread::sleep_for(100ms);
  }
}

// The dashboard, its address printed and its token kept beside the cell's state (0600) for
// the operator who did not see the print.
std::unique_ptr<Dashboard> open_dashboard(const DashboardAddress& at, const CellConfig& cell, CellObserver& observer) {
  auto page = std::make_unique<Dashboard>(at, cell, observer);
  const fs::path token_file = cell.state_folder() / "dashboard.token";
  fs::create_directories(cell.state_folder());
  fs::remove(token_file);
  const int fd = ::open(token_file.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);  // never readable by others
  const std::string line = page->token() + "\n";
  const bool written = fd >= 0 && ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
  if (fd >= 0) ::close(fd);
  if (!written) throw std::runtime_error("cannot write the dashboard's token to " + token_file.string());
  std::cout << "dashboard: " << page->url() << " (the token is in " << token_file.string() << ")" << std::endl;
  return page;
}

// The orders' table and the makespan; true when every order was assembled.
bool report_orders(const std::vector<Order>& orders, CellObserver& observer) {
  const auto statuses = observer.orders();
  TextTable table({"order", "product", "result", "sim start s", "sim end s", "twin peak RSS MB"});
  double first = 1e300, last = 0;
  bool all = true;
  for (const auto& order : orders) {
    const auto it = statuses.find(order.id);
    std::string result = order.exit_code == 0 ? "assembled" : "failed (exit " + std::to_string(order.exit_code) + ")";
    if (!order.ended_why.empty()) {
      result += ": " + order.ended_why;
    } else if (order.exit_code != 0 && it != statuses.end() && it->second.message().size() > 0) {
      result += ": " + it->second.message().to_string();
    }
    table.add_row({order.id, fs::path(order.product).filename().string(), result, fixed(order.sim_start, 1),
                   fixed(order.sim_end, 1), std::to_string(order.peak_rss_kb / 1024)});
    first = std::min(first, order.sim_start);
    last = std::max(last, order.sim_end);
    all &= order.exit_code == 0;
  }
  std::cout << '\n';
  table.print(std::cout);
  std::cout << "\nmakespan " << fixed(last - first, 1) << " sim s for " << orders.size() << " orders\n";
  return all;
}

}  // namespace

void add_cell_commands(CLI::App& app, int& exit_code) {
  auto cell_options = std::make_shared<CellOptions>();
  auto submit_options = std::make_shared<SubmitOptions>();
  auto events = std::make_shared<std::string>();

  CLI::App* up = app.add_subcommand("up", "Start the cell of a deployment file and supervise it");
  add_cell_options(up, *cell_options);
  up->add_option("CELL", cell_options->cell, "Deployment file (the same as --cell)")->check(CLI::ExistingFile);
  auto dashboard = std::make_shared<std::string>();
  up->add_option("--dashboard", *dashboard,
                 "Serve the cell's live page at [ADDR:]PORT (loopback unless ADDR; 0: any free port), instead of the "
                 "file's dashboard (docs/dashboard.md)");
  up->callback([cell_options, dashboard, &exit_code] {
    CellConfig cell = cell_options->load();
    if (!dashboard->empty()) cell.dashboard = *dashboard;
    const std::optional<DashboardAddress> dashboard_at =
        cell.dashboard.empty() ? std::nullopt : std::optional(parse_dashboard_address(cell.dashboard));
    cell.check_twin_identities();
    check_host_limits(cell, static_cast<std::size_t>(cell.max_twins), "max_twins");
    std::signal(SIGINT, request_stop);
    std::signal(SIGTERM, request_stop);
    bool stale = false;
    if (const pid_t other = running_up(cell.domain, stale)) {
      throw std::runtime_error("a cell runs on domain " + std::to_string(cell.domain) + " already (cellctl up, pid " +
                               std::to_string(other) + "); `cellctl down --domain " + std::to_string(cell.domain) +
                               "` stops it");
    }
    if (stale) std::cerr << "cellctl up: the last cellctl up on this domain was killed; starting the cell afresh\n";
    CellObserver observer(cell.participant_settings("order-desk"));
    // Before anything starts: a port that is taken stops up here, and the page shows the start.
    const std::unique_ptr<Dashboard> page = dashboard_at ? open_dashboard(*dashboard_at, cell, observer) : nullptr;
    state::CellStore store(cell.state_folder());
    RosterWriter roster(observer.participant(), cell, out_of_service_in(store));
    store.journal("cellctl", "up", "", "domain " + std::to_string(cell.domain));
    bool world_lost = false;  // cell-sim restarts: the twins' virtual scenes went with it
    Supervisor supervisor(cell_processes(cell, executable_dir()), cell.restart,
                          [&](const std::string& process, const std::string& event, const std::string& what) {
                            std::cerr << "cellctl up: " << what << std::endl;
                            store.journal(process, event, "", what);
                            observer.note_change();  // the dashboard shows it now
                            world_lost |= event == "restarting all";
                          });
    // Before the cell is up: a submit that sees the cell's resources finds its state too.
    std::ofstream(pid_file(cell.domain)) << ::getpid() << '\n' << fs::absolute(cell.state_folder()).string() << '\n';
    const auto wait = std::chrono::milliseconds(static_cast<long>(cell_options->wait_s * 1000));
    try {
      // Until every resource is there. A process that dies meanwhile is restarted like any
      // other (a young process can die in DDS discovery: a restarted robot did so under TSan,
      // and this up gave the whole cell up), and so is one of ours that runs unheard, once.
      const auto deadline = std::chrono::steady_clock::now() + wait;
      std::set<std::string> ended_unheard;
      for (std::vector<std::string> missing; !(missing = observer.wait_for_resources(cell.resource_ids(), 500ms)).empty();) {
        for (const std::string& process : supervisor.end_unheard(heard_resources(observer), wait)) {
          if (!ended_unheard.insert(process).second) {
            throw std::runtime_error("the cell did not come up: " + process + " was not heard on DDS within " +
                                     std::to_string(wait.count() / 1000) + " s of its start, twice");
          }
        }
        if (const std::string why = supervisor.tend(); !why.empty()) throw std::runtime_error(why);
        const bool others_missing = std::any_of(missing.begin(), missing.end(), [&](const std::string& r) { return !supervisor.runs(r); });
        if (others_missing && std::chrono::steady_clock::now() > deadline) cell_did_not_come_up(missing, wait);
      }
    } catch (const std::exception& e) {
      store.journal("cellctl", "down", "", std::string("gave up: ") + e.what());
      fs::remove(pid_file(cell.domain));
      throw;
    }
    const auto log = [](const std::string& what) { std::cerr << "cellctl up: " << what << std::endl; };
    OrderDesk desk(cell, store, observer.participant(), supervisor.heartbeats(), log);
    RemoteDesk remote(cell, store, observer, log);
    std::cout << "cell up on domain " << cell.domain << " (" << cell.resource_ids().size() << " resources, state in "
              << cell.state_folder().string() << "); `cellctl down --domain " << cell.domain << "` stops it"
              << std::endl;
    std::string gave_up;  // why the supervisor stopped the cell
    while (!stop_requested) {
      if (world_lost) desk.interrupt_all();
      world_lost = false;
      remote.tend();
      desk.tend();
      roster.update(out_of_service_in(store));  // the operator took a resource out of service, or back
      supervisor.end_unheard(heard_resources(observer), wait);
      if (const std::string why = supervisor.tend(); !why.empty()) {
        std::cerr << "error: " << why << "; stopping the cell. Look at that process's output above, fix the cause, "
                  << "and start the cell again\n";
        gave_up = "gave up: " + why;
        exit_code = 1;
        break;
      }
      std::this_thread::sleep_for(100ms);
    }
    desk.interrupt_all();  // their orders are INTERRUPTED: the next up on this state takes them up
    supervisor.stop();
    store.journal("cellctl", "down", "", gave_up);
    fs::remove(pid_file(cell.domain));
    std::cout << "cell down" << std::endl;
  });

  CLI::App* submit_cmd = app.add_subcommand("submit", "Hand an order to the cell of cellctl up on the domain (or, with none, run its twin here) and follow it to its end");
  add_cell_options(submit_cmd, *cell_options);
  add_submit_options(submit_cmd, *submit_options, false);
  submit_cmd->add_flag("--remote", submit_options->remote,
                       "Send the order to the cell's order desk over DDS, as --client (docs/order-desk.md)");
  submit_cmd->add_option("--client", submit_options->client, "The client's id (the cell's `clients:`; with --security its identity)");
  submit_cmd->add_flag("--detach", submit_options->detach,
                       "Hand the order to the cell of cellctl up and return at once (cellctl status follows it)");
  submit_cmd->callback([cell_options, submit_options, &exit_code] {
    CellConfig cell = cell_options->load();
    std::signal(SIGINT, request_stop);
    if (submit_options->remote) {
      if (submit_options->client.empty()) throw CLI::ValidationError("--client", "--remote needs the client's id");
      const auto orders = orders_of(*submit_options);
      const Order& order = orders.front();
      RemoteSubmission s{order.product, submit_options->client, order.id, order.out, submit_options->sequence,
                         cell.participant_settings(submit_options->client),
                         std::chrono::seconds(static_cast<long>(cell_options->wait_s)), false, ""};
      exit_code = submit_remote(s, stop_requested);
      return;
    }
    auto orders = orders_of(*submit_options);
    // Read once: an up that started after load() looked (its pid file is new) keeps its
    // state where it says, and that is where its desk reads orders.
    const std::string running = running_state_dir(cell.domain);
    if (!running.empty()) {
      if (cell_options->state_dir.empty()) {
        cell.state_dir = running;
      } else if (fs::weakly_canonical(cell.state_folder()) != fs::weakly_canonical(running)) {
        std::cerr << "error: the cell on domain " << cell.domain << " keeps its state in " << running << ", not in "
                  << cell.state_folder().string() << "; submit without --state-dir\n";
        exit_code = 2;
        return;
      }
    }
    if (submit_options->detach) {
      if (running.empty()) throw ConfigError("--detach hands the order to the cell of cellctl up, and none runs on domain " +
                                             std::to_string(cell.domain));
      state::CellStore store(cell.state_folder());
      exit_code = hand_to_desk(store, *submit_options, orders.front()) ? 0 : 1;
      if (exit_code == 0) std::cout << "order " << orders.front().id << " handed to the cell; `cellctl status` follows it\n";
      return;
    }
    CellObserver observer(cell.participant_settings("cellctl"));
    if (!running.empty()) {
      exit_code = submit_to_desk(cell, *submit_options, orders.front(), observer);
      return;
    }
    // No cellctl up on the domain (a cell of processes started by hand): the twin runs here.
    check_identities_for(cell, orders.size());
    TwinIdentities identities(cell.twin_identities_in_use(), observer.participant());
    HeartbeatSocket heartbeats;
    heartbeats.name_to_children();
    run_orders(cell, *submit_options, orders, observer, cell_options->wait_s, identities, heartbeats);
    const Order& order = orders.front();
    std::cout << "twin peak RSS " << order.peak_rss_kb / 1024 << " MB\n";
    if (order.exit_code == 0) std::cout << "order " << order.id << " done: " << order.out << "/report.html, " << order.out << "/plan.json, " << order.out << "/animation.gltf\n";
    exit_code = order.exit_code;
  });

  CLI::App* status = app.add_subcommand("status", "List the cell's resources, inventory and orders");
  add_cell_options(status, *cell_options);
  auto json = std::make_shared<bool>(false);
  status->add_flag("--json", *json, "As one JSON object (docs/cli.md gives its shape)");
  status->callback([cell_options, json] {
    const CellConfig cell = cell_options->load();
    CellObserver observer(cell.participant_settings("cellctl"));
    observer.wait_for_resources(cell.resource_ids(), 2s);
    std::this_thread::sleep_for(300ms);  // orders and resources outside the file
    const nlohmann::json report = cell_status(cell, observer);
    if (*json) {
      std::cout << report.dump(2) << std::endl;
      return;
    }
    TextTable resources({"resource", "kind", "state", "work", "queued", "reserved by", "waiting", "stock", "refused"});
    for (const auto& [id, r] : observer.resources()) {
      std::string stock, waiting;
      for (const auto& s : r.capability.stock()) stock += s.part_type().to_string() + "=" + std::to_string(s.count()) + " ";
      for (const auto& w : r.capability.waiting()) waiting += (waiting.empty() ? "" : " ") + w.to_string();
      const cell::Capability& c = r.capability;
      const std::string refused =
          c.refused_commands() == 0 ? "" : std::to_string(c.refused_commands()) + ", last: " + c.last_refusal().to_string();
      const std::string state = !r.alive ? "gone" : c.out_of_service().to_string().empty() ? "alive" : "out of service";
      resources.add_row({id, c.kind().to_string(), state, c.busy() ? "busy" : "idle",
                         std::to_string(c.queued_commands()), c.reserved_by().to_string(), waiting, stock, refused});
    }
    std::cout << "Cell on domain " << cell.domain << ": " << observer.resources().size() << " resources\n\n";
    resources.print(std::cout);
    TextTable inventory({"part type", "initial", "in buffers", "assembled", "on stations", "in transit", "inspection", ""});
    long inspection = 0;
    for (const auto& [type, c] : report["inventory"].items()) {
      inventory.add_row({type, c["initial"].dump(), c["in_buffers"].dump(), c["assembled"].dump(), c["on_stations"].dump(),
                         c["in_transit"].dump(), c["inspection"].dump(), c["conserved"] ? "" : "NOT CONSERVED"});
      inspection += c["inspection"].get<long>();
    }
    std::cout << "\nInventory (" << report["state_dir"].get<std::string>() << ")\n";
    inventory.print(std::cout);
    if (inspection > 0) {
      std::cout << inspection << " parts are held for inspection: a gripper held them when a process died. The cell does "
                << "not use them again; the journal names each (event 'inspection'). Check them on their station by hand.\n";
    }
    const auto orders = observer.orders();
    std::size_t queued = 0;
    for (const auto& o : report["orders"]) queued += o.contains("place");
    std::cout << "\n" << orders.size() << " orders under way or ended" << (queued ? ", " + std::to_string(queued) + " queued" : "")
              << "\n";
    for (const auto& [id, s] : orders) print_progress(s);
    for (const auto& o : report["orders"]) {
      if (o.contains("place")) std::cout << "[" << o["order"].get<std::string>() << "] QUEUED, place " << o["place"] << " of " << queued << '\n';
    }
  });

  CLI::App* down = app.add_subcommand("down", "Stop the cell that `cellctl up` started");
  add_cell_options(down, *cell_options);
  down->callback([cell_options, &exit_code] {
    const CellConfig cell = cell_options->load();
    const fs::path file = pid_file(cell.domain);
    bool stale = false;
    const pid_t pid = running_up(cell.domain, stale);
    if (pid == 0) {
      std::cerr << "error: no cell of cellctl up on domain " << cell.domain << " (" << file.string()
                << (stale ? ": its cellctl up was killed, and its processes ended with it; the stale file is removed"
                          : "")
                << ")\n";
      exit_code = 1;
      return;
    }
    ::kill(pid, SIGTERM);
    // `up` removes its pid file once its processes have ended.
    for (int i = 0; i < 300 && fs::exists(file); ++i) std::this_thread::sleep_for(50ms);
    if (fs::exists(file)) {
      std::cerr << "error: cellctl up (pid " << pid << ") did not stop within 15 s\n";
      exit_code = 1;
      return;
    }
    std::cout << "cell on domain " << cell.domain << " stopped\n";
  });

  CLI::App* cancel = app.add_subcommand(
      "cancel", "Cancel an order of the cell: a queued one never starts; one under way, its twin fails and cleans up");
  add_cell_options(cancel, *cell_options);
  auto cancelled = std::make_shared<std::string>();
  cancel->add_option("order", *cancelled, "The order's id (cellctl status lists them)")->required();
  cancel->callback([cell_options, cancelled, &exit_code] {
    CellConfig cell = cell_options->load();
    if (const std::string running = running_state_dir(cell.domain); !running.empty() && cell_options->state_dir.empty()) {
      cell.state_dir = running;
    }
    if (!fs::exists(state::CellStore::file_in(cell.state_folder()))) {
      std::cerr << "error: the cell keeps no state in " << cell.state_folder().string() << ": it has no order "
                << *cancelled << '\n';
      exit_code = 1;
      return;
    }
    state::CellStore store(cell.state_folder());
    const ActionAnswer answer = cancel_order(store, *cancelled, "the operator (cellctl)");
    (answer.status == 200 ? std::cout : std::cerr) << (answer.status == 200 ? "" : "error: ") << answer.message << '\n';
    exit_code = answer.status == 200 ? 0 : 1;
  });

  CLI::App* service = app.add_subcommand(
      "service", "Take a resource of the cell out of service (it takes no new work; what it took on, it finishes) or back");
  add_cell_options(service, *cell_options);
  auto service_resource = std::make_shared<std::string>();
  auto service_out = std::make_shared<std::string>();
  service->add_option("resource", *service_resource, "The resource's id (cellctl status lists them)")->required();
  auto* out_opt = service->add_option("--out", *service_out, "Take it out of service, saying why");
  auto* back_opt = service->add_flag("--back", "Put it back into service");
  out_opt->excludes(back_opt);
  service->callback([cell_options, service_resource, service_out, out_opt, back_opt, &exit_code] {
    if (out_opt->count() == 0 && back_opt->count() == 0) throw CLI::ValidationError("service", "say --out REASON or --back");
    if (out_opt->count() > 0 && service_out->empty()) throw CLI::ValidationError("--out", "the reason must not be empty");
    CellConfig cell = cell_options->load();
    state::CellStore store(cell.state_folder());
    const ActionAnswer answer = set_resource_service(cell, store, *service_resource, *service_out, "the operator (cellctl)");
    (answer.status == 200 ? std::cout : std::cerr) << (answer.status == 200 ? "" : "error: ") << answer.message << '\n';
    if (answer.status == 200 && running_state_dir(cell.domain).empty()) {
      std::cout << "no cellctl up runs on domain " << cell.domain << ": the next one starts with it so\n";
    }
    exit_code = answer.status == 200 ? 0 : 1;
  });

  CLI::App* run = app.add_subcommand("run", "Start the cell, assemble one order per product at once, stop the cell");
  add_cell_options(run, *cell_options);
  add_submit_options(run, *submit_options, true);
  run->add_option("--events", *events, "Write every command event and delivery as JSON lines to this file");
  run->callback([cell_options, submit_options, events, &exit_code] {
    CellConfig cell = cell_options->load();
    if (cell.state_dir.empty()) {
      // A run starts from the deployment file's stock: its state is its own, beside its output.
      cell.state_dir = fs::absolute(submit_options->out.empty() ? "out" : submit_options->out) / "cell-state";
      fs::remove_all(cell.state_dir);
    }
    std::signal(SIGINT, request_stop);
    std::signal(SIGTERM, request_stop);
    cell.check_twin_identities();
    auto orders = orders_of(*submit_options);
    check_identities_for(cell, orders.size());
    // The cell's processes, a twin per order and cellctl itself.
    const std::size_t participants = cell_processes(cell, executable_dir()).size() + orders.size() + 1;
    if (!cell.discovery_given && cell.security_dir.empty() && participants > kSimpleDiscoveryParticipants) {
      cell.simple_discovery = false;
      std::cout << participants << " participants, more than simple discovery takes: through a discovery server" << std::endl;
    }
    check_host_limits(cell, orders.size(), "orders at once (cellctl up's queue runs max_twins of them at once)");
    CellObserver observer(cell.participant_settings("cellctl"));
    const RosterWriter roster(observer.participant(), cell);
    if (!events->empty()) observer.log_events_to(*events);
    const auto started = std::chrono::steady_clock::now();
    HeartbeatSocket heartbeats;  // the cell's processes and the twins beat on it
    heartbeats.name_to_children();
    // A twin per order stands by while the cell comes up, as `up`'s desk keeps them: an order
    // starts in a twin that has joined the cell (docs/performance.md "Twin start-up").
    TwinIdentities identities(cell.twin_identities_in_use(), observer.participant());
    TwinPool standby(twin_standby_argv(cell, executable_dir()),
                     static_cast<int>(std::min(orders.size(), static_cast<std::size_t>(cell.max_twins))), identities);
    const auto wait = std::chrono::milliseconds(static_cast<long>(cell_options->wait_s * 1000));
    RunningCell running(cell, observer, wait, heartbeats);
    std::cout << "cell up on domain " << cell.domain << ", real-time factor " << cell.real_time_factor << std::endl;
    run_orders(cell, *submit_options, orders, observer, cell_options->wait_s, identities, heartbeats, &standby,
               [&] { running.end_hung(wait); });
    const bool all = report_orders(orders, observer);
    exit_code = all ? 0 : 1;
    while (Process* p = running.ended()) {  // a cell process that did not last the run is a fault
      std::cerr << "error: " << p->name() << " ended during the run (exit " << p->poll() << ")\n";
      running.forget(p);
      exit_code = 1;
    }
    if (orders.size() == 1 && orders.front().exit_code == 2) exit_code = 2;  // a bad product description
    const auto rss = running.peak_rss();
    running.stop();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::cout << "\ncell down after " << static_cast<long>(wall * 10) / 10.0 << " s";
    if (!events->empty()) std::cout << "; " << observer.events_logged() << " events in " << *events;
    std::cout << "\n\n";
    TextTable memory({"process", "peak RSS MB"});
    for (const auto& [name, kb] : rss) memory.add_row({name, std::to_string(kb / 1024)});
    memory.print(std::cout);
  });
}

}  // namespace cellctl
