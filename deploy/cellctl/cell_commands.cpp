#include "deploy/cellctl/cell_commands.hpp"

#include <signal.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>

#include "deploy/cellctl/cell_config.hpp"
#include "deploy/cellctl/cell_observer.hpp"
#include "deploy/cellctl/processes.hpp"
#include "deploy/cellctl/text_table.hpp"

namespace cellctl {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

volatile std::sig_atomic_t stop_requested = 0;
void request_stop(int) { stop_requested = 1; }

struct CellOptions {
  std::string cell = CELL_DEFAULT_FILE;
  int domain = -1;  // -1: the file's
  double real_time_factor = 0;
  double wait_s = 30;

  CellConfig load() const {
    CellConfig c = read_cell_config(cell);
    if (domain >= 0) c.domain = domain;
    if (real_time_factor > 0) c.real_time_factor = real_time_factor;
    return c;
  }
};

void add_cell_options(CLI::App* cmd, CellOptions& o) {
  cmd->add_option("--cell", o.cell, "Deployment file of the cell")->check(CLI::ExistingFile);
  cmd->add_option("--domain", o.domain, "DDS domain id, instead of the file's")->check(CLI::Range(0, 232));
  cmd->add_option("--real-time-factor", o.real_time_factor, "Instead of the file's")->check(CLI::PositiveNumber);
}

fs::path pid_file(int domain) {
  const char* tmp = std::getenv("TMPDIR");
  return fs::path(tmp ? tmp : "/tmp") / ("agile-cell-" + std::to_string(domain) + ".pid");
}

// The cell's processes, started in order; cell-sim first, as the others wait for it.
class RunningCell {
 public:
  RunningCell(const CellConfig& cell, CellObserver& observer, std::chrono::milliseconds wait) {
    for (const auto& spec : cell_processes(cell, executable_dir())) {
      processes_.push_back(std::make_unique<Process>(spec.name, spec.argv));
    }
    const auto missing = observer.wait_for_resources(cell.resource_ids(), wait);
    if (!missing.empty()) {
      std::string list;
      for (const auto& m : missing) list += " " + m;
      throw std::runtime_error("the cell did not come up within " + std::to_string(wait.count() / 1000) +
                               " s; missing:" + list);
    }
  }
  ~RunningCell() { stop(); }

  // A process that ended by itself, or nullptr.
  Process* ended() {
    for (auto& p : processes_) {
      if (p->poll() >= 0) return p.get();
    }
    return nullptr;
  }

  std::vector<std::pair<std::string, long>> peak_rss() const {
    std::vector<std::pair<std::string, long>> out;
    for (const auto& p : processes_) out.emplace_back(p->name(), p->peak_rss_kb());
    return out;
  }

  void stop() {
    for (auto it = processes_.rbegin(); it != processes_.rend(); ++it) (*it)->stop();
    processes_.clear();
  }

 private:
  std::vector<std::unique_ptr<Process>> processes_;
};

void print_progress(const cell::OrderStatus& s) {
  static const char* names[] = {"SUBMITTED", "PLANNING", "VIRTUAL_ASSEMBLY", "PHYSICAL_ASSEMBLY", "DONE", "FAILED"};
  std::cout << "[" << s.order_id() << "] t=" << static_cast<long>(s.sim_time() * 10) / 10.0 << " s  "
            << names[s.state()] << "  " << static_cast<int>(s.progress() * 100) << "%  " << s.message() << std::endl;
}

struct SubmitOptions {
  std::string product, order, out, sequence = "search", path = "linear";
};

void add_submit_options(CLI::App* cmd, SubmitOptions& o) {
  cmd->add_option("PRODUCT", o.product, "AutomationML file (.aml)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--order", o.order, "Order id (default: the product's name and a number)");
  cmd->add_option("--out", o.out, "Folder for the plan and animation (default: out/ORDER)");
  cmd->add_option("--sequence", o.sequence, "Sequence planner")->check(CLI::IsMember({"paper", "search"}));
  cmd->add_option("--path", o.path, "Path planner")->check(CLI::IsMember({"linear", "ompl"}));
}

// Spawns the order's twin and follows it to its end; the twin's exit code.
int submit(const CellConfig& cell, SubmitOptions o, CellObserver& observer, double wait_s) {
  if (o.order.empty()) o.order = fs::path(o.product).stem().string() + "-" + std::to_string(::getpid());
  if (o.out.empty()) o.out = (fs::path("out") / o.order).string();
  observer.on_status([order = o.order](const cell::OrderStatus& s) {
    if (s.order_id() == order) print_progress(s);
  });
  std::vector<std::string> argv{executable_dir() + "/twin", "--domain", std::to_string(cell.domain), "--order", o.order,
                                "--product", o.product, "--out", o.out, "--sequence", o.sequence, "--path", o.path,
                                "--wait", std::to_string(wait_s), "--lease", std::to_string(cell.liveliness_lease),
                                "--quiet"};
  if (!cell.localhost_only) argv.push_back("--all-interfaces");
  Process twin("twin-" + o.order, argv);
  while (twin.poll() < 0) {
    if (stop_requested) twin.stop();
    std::this_thread::sleep_for(20ms);
  }
  observer.on_status({});
  const int code = twin.poll();
  // The twin is the only child reaped so far: the children's peak is its own.
  struct rusage usage {};
  if (::getrusage(RUSAGE_CHILDREN, &usage) == 0) std::cout << "twin peak RSS " << usage.ru_maxrss / 1024 << " MB\n";
  if (code == 0) std::cout << "order " << o.order << " done: " << o.out << "/plan.json, " << o.out << "/animation.gltf\n";
  return code;
}

}  // namespace

void add_cell_commands(CLI::App& app, int& exit_code) {
  auto cell_options = std::make_shared<CellOptions>();
  auto submit_options = std::make_shared<SubmitOptions>();
  auto events = std::make_shared<std::string>();

  CLI::App* up = app.add_subcommand("up", "Start the cell of a deployment file and supervise it");
  add_cell_options(up, *cell_options);
  up->add_option("CELL", cell_options->cell, "Deployment file (the same as --cell)")->check(CLI::ExistingFile);
  up->callback([cell_options, &exit_code] {
    const CellConfig cell = cell_options->load();
    std::signal(SIGINT, request_stop);
    std::signal(SIGTERM, request_stop);
    CellObserver observer(cell.domain, cell.localhost_only);
    RunningCell running(cell, observer, std::chrono::milliseconds(static_cast<long>(cell_options->wait_s * 1000)));
    std::ofstream(pid_file(cell.domain)) << ::getpid() << '\n';
    std::cout << "cell up on domain " << cell.domain << " (" << cell.resource_ids().size()
              << " resources); `cellctl down --domain " << cell.domain << "` stops it" << std::endl;
    while (!stop_requested) {
      if (Process* p = running.ended()) {
        std::cerr << "error: " << p->name() << " ended (exit " << p->poll() << "); stopping the cell\n";
        exit_code = 1;
        break;
      }
      std::this_thread::sleep_for(100ms);
    }
    running.stop();
    fs::remove(pid_file(cell.domain));
    std::cout << "cell down" << std::endl;
  });

  CLI::App* submit_cmd = app.add_subcommand("submit", "Spawn a twin for an order and follow it to its end");
  add_cell_options(submit_cmd, *cell_options);
  add_submit_options(submit_cmd, *submit_options);
  submit_cmd->callback([cell_options, submit_options, &exit_code] {
    const CellConfig cell = cell_options->load();
    std::signal(SIGINT, request_stop);
    CellObserver observer(cell.domain, cell.localhost_only);
    exit_code = submit(cell, *submit_options, observer, cell_options->wait_s);
  });

  CLI::App* status = app.add_subcommand("status", "List the cell's resources and orders");
  add_cell_options(status, *cell_options);
  status->callback([cell_options] {
    const CellConfig cell = cell_options->load();
    CellObserver observer(cell.domain, cell.localhost_only);
    observer.wait_for_resources(cell.resource_ids(), 2s);
    std::this_thread::sleep_for(300ms);  // orders and resources outside the file
    TextTable resources({"resource", "kind", "state", "work", "reserved by", "stock"});
    for (const auto& [id, r] : observer.resources()) {
      std::string stock;
      for (const auto& s : r.capability.stock()) stock += s.part_type() + "=" + std::to_string(s.count()) + " ";
      resources.add_row({id, r.capability.kind(), r.alive ? "alive" : "gone", r.capability.busy() ? "busy" : "idle",
                         r.capability.reserved_by(), stock});
    }
    std::cout << "Cell on domain " << cell.domain << ": " << observer.resources().size() << " resources\n\n";
    resources.print(std::cout);
    const auto orders = observer.orders();
    std::cout << "\n" << orders.size() << " orders\n";
    for (const auto& [id, s] : orders) print_progress(s);
  });

  CLI::App* down = app.add_subcommand("down", "Stop the cell that `cellctl up` started");
  add_cell_options(down, *cell_options);
  down->callback([cell_options, &exit_code] {
    const CellConfig cell = cell_options->load();
    const fs::path file = pid_file(cell.domain);
    pid_t pid = 0;
    if (!(std::ifstream(file) >> pid) || pid <= 0) {
      std::cerr << "error: no cell of cellctl up on domain " << cell.domain << " (" << file.string() << ")\n";
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

  CLI::App* run = app.add_subcommand("run", "Start the cell, assemble one order, stop the cell");
  add_cell_options(run, *cell_options);
  add_submit_options(run, *submit_options);
  run->add_option("--events", *events, "Write every command event and delivery as JSON lines to this file");
  run->callback([cell_options, submit_options, events, &exit_code] {
    const CellConfig cell = cell_options->load();
    std::signal(SIGINT, request_stop);
    std::signal(SIGTERM, request_stop);
    CellObserver observer(cell.domain, cell.localhost_only);
    if (!events->empty()) observer.log_events_to(*events);
    const auto started = std::chrono::steady_clock::now();
    RunningCell running(cell, observer, std::chrono::milliseconds(static_cast<long>(cell_options->wait_s * 1000)));
    std::cout << "cell up on domain " << cell.domain << ", real-time factor " << cell.real_time_factor << std::endl;
    exit_code = submit(cell, *submit_options, observer, cell_options->wait_s);
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
