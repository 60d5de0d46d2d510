#pragma once
// A cell's deployment file (deploy/cells/*.yaml) and the processes it starts.

#include <array>
#include <chrono>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "services/dds/participant_settings.hpp"
#include "services/node/gripper.hpp"

namespace cellctl {

using Point = std::array<double, 3>;
constexpr double kBoundsMargin = 3.0;  // m around the layout, when the file gives no bounds
constexpr int kDiscoveryBasePort = 11811;  // Fast DDS's (and ROS 2's) discovery server port; + domain
constexpr std::size_t kSimpleDiscoveryParticipants = 28;  // below simple discovery's 32 indexes

struct StationConfig {
  std::string id = "station-1", arm = "arm-1";
  Point position{}, dock{0.6, 0, 0}, table{1.0, 0.025, 1.0};  // table: half extents, its top at position
  double arm_speed = 0.25, arm_angular_speed = 1.0;
  double cost_per_hour = 0;  // the station with its arm, while an order holds it (quotes)
};

struct RobotConfig {
  std::string id = "mobile-robot-1";
  Point home{1.5, 0, 1.2};
  double speed = 0.8;
  double cost_per_hour = 0;  // while it fetches for an order (quotes)
};

struct BufferConfig {
  std::string id;
  Point position{};
  std::map<std::string, int> stock;
};

// `restart: {limit: 5, window: 60}`: cellctl up restarts a cell process that ends, and gives
// up (stops the cell) when one ended more than `limit` times within `window` seconds.
struct RestartPolicy {
  int limit = 5;
  std::chrono::seconds window{60};
  std::chrono::milliseconds first_backoff{500};  // doubled with each end inside the window
  std::chrono::milliseconds max_backoff{8000};
};

// `desk: {max_order_mb: 64, orders_per_minute: 60, max_orders: 1000}`: what the order desk takes
// from remote clients (docs/order-desk.md); past a limit it refuses with the reason.
// Where `cellctl up` serves the cell's dashboard (deploy/cellctl/dashboard.hpp).
struct DashboardAddress {
  std::string host = "127.0.0.1";
  int port = 0;  // 0: any free port (the address up prints says which)
};
// "8080", "127.0.0.1:8080", "0.0.0.0:8080", "0"; throws ConfigError with the reason.
DashboardAddress parse_dashboard_address(const std::string& text);

struct DeskLimits {
  double max_order_mb = 64;   // the product's files, all together
  int orders_per_minute = 6;  // per client
  int max_orders = 1000;      // orders accepted and not ended (queued or under way), from any client
};

struct CellConfig {
  std::filesystem::path file;
  int domain = 42;
  double real_time_factor = 1;
  double liveliness_lease = 5;  // s: a process starved of CPU for 2 s is not taken for gone
  bool localhost_only = true;   // false: every process uses every network interface
  // `network: {interfaces: [IP], peers: [IP]}`: instead, only these addresses of the host, and
  // other hosts' to look for participants at (an OEM's client, the cell's other hosts).
  std::vector<std::string> interfaces, peers;
  // `discovery:` how the cell's participants find each other (docs/topics.md). `simple` (the
  // default): each announces itself to a fixed range of ports (at most 32 participants on a
  // host; the quickest for a small cell). `server`: through discovery servers at port
  // kDiscoveryBasePort + domain, one on 127.0.0.1, or with `network:` one on each host (the
  // first interface and each peer); cellctl starts those on its own addresses.
  // `{servers: [IP:PORT, ...]}`: through these. Without the key, `cellctl run` takes `server`
  // when its orders would bring more than kSimpleDiscoveryParticipants participants.
  bool simple_discovery = true;
  bool discovery_given = false;  // the file (or the command line) said which
  std::vector<std::string> discovery_servers;  // given in the file; empty: the default
  std::vector<StationConfig> stations{StationConfig{}};
  std::vector<RobotConfig> robots{RobotConfig{}};
  std::vector<BufferConfig> buffers;
  // The box every commanded position must lie in (cell-sim and the arms refuse others):
  // `bounds: {min: [x, y, z], max: [x, y, z]}`, or the layout's box with a margin.
  Point bounds_min{}, bounds_max{};
  RestartPolicy restart;
  // `gripper: {max_opening: 0.2, ...}`: the arms' gripper, one for the cell (a twin plans
  // with it before it knows which station it gets); services/node/gripper.hpp.
  fb::GripperGeometry gripper;
  // `fixtures: true`: the station has a jig that holds a part standing on nothing yet (a
  // subassembly built aside that would topple): plans that need one are complete, and say
  // where (twin::PlannerOptions::fixtures). Default: none.
  bool fixtures = false;
  // `state_dir:` the folder of the cell's database (relative to the file's folder); empty:
  // $XDG_STATE_HOME (or ~/.local/state)/agile-cell/domain-N.
  std::filesystem::path state_dir;
  // `security:` the folder `cellctl pki init` wrote (relative to the file's folder); every
  // process of the cell, its twins and cellctl then use DDS-Security. Empty: off.
  std::filesystem::path security_dir;
  // `clients: [oem-a, oem-b]`: who may submit over DDS (the order desk's topics per client).
  std::vector<std::string> clients;
  // `operators: [alice]`: with security, who may use the dashboard by a client certificate of
  // the cell's CA (`cellctl pki` issues one per name), besides the token.
  std::vector<std::string> operators;
  DeskLimits desk;
  // What a quote charges (docs/quotes.md): `setup_cost:` per order, plus each resource's
  // `cost_per_hour:` for the time the order uses it, in `currency:`.
  double setup_cost = 0;
  std::string currency = "EUR";
  // `standby_twins:` twins cellctl up starts before orders come, so that an order's twin has
  // joined the cell already (deploy/cellctl/twin_pool.hpp); 0: each twin starts with its order.
  int standby_twins = 1;
  // `max_twins:` the twins cellctl up's desk runs at once for orders (standby ones apart); the
  // other orders wait in the cell's queue, in the order they came (docs/order-desk.md).
  int max_twins = 16;
  // `twin_watchdog:` s a twin's heartbeat (services/node/heartbeat.hpp) may stay silent before
  // cellctl up's desk ends it as hung and starts another for its order (it counts as died);
  // cellctl run ends it and fails its order.
  // A twin beats from its event loop and between the planner's steps; longer than its waits
  // for the cell (30 s) and its exit watchdog (15 s).
  double twin_watchdog = 60;
  // `twin_identities:` with security, the twins that may run at once, standby ones included:
  // each has a certificate of its own, twin-1 .. twin-N (deploy/cellctl/twin_identities.hpp).
  int twin_identities = 10;
  // `dashboard: [ADDR:]PORT`: cellctl up serves the cell's live page there (loopback unless
  // ADDR says otherwise); empty: no dashboard, unless `up --dashboard` asks for one.
  std::string dashboard;

  std::vector<std::string> resource_ids() const;
  // The servers every participant of the cell uses ("IP:PORT"); empty: simple discovery.
  std::vector<std::string> discovery_addresses() const;
  std::vector<std::string> twin_identity_names() const;  // twin-1 .. twin-N
  std::vector<std::string> twin_identities_in_use() const;  // those with security, none without
  // With security: throws ConfigError naming an identity of twin_identities that the
  // security folder lacks (a folder issued before the file asked for more twins).
  void check_twin_identities() const;
  // How a participant of this cell with `identity` (docs/security.md) joins its domain.
  dds::ParticipantSettings participant_settings(const std::string& identity) const;
  std::filesystem::path state_folder() const;
};

// "FILE:LINE: what is wrong".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

CellConfig read_cell_config(const std::filesystem::path& file);

struct ProcessSpec {
  std::string name;               // resource id, or "cell-sim"
  std::vector<std::string> argv;  // argv[0]: the executable
  // The others hold state in it (cell-sim's world: their bodies): when it restarts, they do too.
  bool others_depend = false;
  std::vector<std::string> resources;  // the ids of the resources it publishes
};

// The discovery servers on this host first, then cell-sim (the others wait for it), then the
// stations, the robots, the buffers.
std::vector<ProcessSpec> cell_processes(const CellConfig& cell, const std::filesystem::path& bin_dir);

// The twin of one order on the cell (`quote`: an order for a quote, with the cell's rates;
// quiet: whoever started it shows its status); an empty
// `state_dir`: the twin keeps no durable state (a cell of processes started by hand).
std::vector<std::string> twin_argv(const CellConfig& cell, const std::filesystem::path& bin_dir, const std::string& order,
                                   const std::string& product, const std::string& out, const std::string& sequence,
                                   const std::string& path, const std::filesystem::path& state_dir, double wait_s = 30,
                                   bool quote = false);
// The same twin in two halves: one started before its order (--standby), and the order's
// options it then reads (twin_pool.hpp).
std::vector<std::string> twin_standby_argv(const CellConfig& cell, const std::filesystem::path& bin_dir);
std::vector<std::string> twin_order_args(const CellConfig& cell, const std::string& order, const std::string& product,
                                         const std::string& out, const std::string& sequence, const std::string& path,
                                         const std::filesystem::path& state_dir, double wait_s = 30, bool quote = false);

}  // namespace cellctl
