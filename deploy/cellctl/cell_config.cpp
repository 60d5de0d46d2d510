#include "deploy/cellctl/cell_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>

#include <yaml-cpp/yaml.h>

namespace cellctl {
namespace {

// twin-1, twin-2, ...: the twins' identities (twin_identities.hpp), which nothing else may be.
bool is_twin_identity(const std::string& id) {
  return id.size() > 5 && id.rfind("twin-", 0) == 0 && id.find_first_not_of("0123456789", 5) == std::string::npos;
}


std::string where(const std::filesystem::path& file, const YAML::Node& node) {
  return file.string() + ":" + std::to_string(node.Mark().line + 1);
}

template <class T>
void read(const std::filesystem::path& file, const YAML::Node& parent, const char* key, T& value) {
  const YAML::Node node = parent[key];
  if (!node) return;
  try {
    value = node.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError(where(file, node) + ": '" + key + "' has a value of the wrong kind");
  }
}

void read_point(const std::filesystem::path& file, const YAML::Node& parent, const char* key, Point& point) {
  const YAML::Node node = parent[key];
  if (!node) return;
  if (!node.IsSequence() || node.size() != 3) throw ConfigError(where(file, node) + ": '" + key + "' needs [x, y, z]");
  std::vector<double> v;
  read(file, parent, key, v);
  point = {v[0], v[1], v[2]};
}

void known_keys(const std::filesystem::path& file, const YAML::Node& node, std::set<std::string> keys) {
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (!keys.count(key)) throw ConfigError(where(file, entry.first) + ": unknown key '" + key + "'");
  }
}


void add_point(std::vector<std::string>& argv, const char* option, const Point& p) {
  argv.push_back(option);
  for (double v : p) argv.push_back(std::to_string(v));
}

// --gripper-finger-length M, ...: as add_gripper_options (services/dds/cli_options.hpp) reads them.
void add_gripper(std::vector<std::string>& argv, const fb::GripperGeometry& gripper) {
  for (const auto& [name, size] : fb::gripper_sizes()) {
    argv.insert(argv.end(), {fb::gripper_option(name), std::to_string(gripper.*size)});
  }
}

}  // namespace

std::vector<std::string> CellConfig::resource_ids() const {
  std::vector<std::string> ids;
  for (const auto& s : stations) ids.insert(ids.end(), {s.id, s.arm});
  for (const auto& r : robots) ids.push_back(r.id);
  for (const auto& b : buffers) ids.push_back(b.id);
  return ids;
}

namespace {

void read_cost(const std::filesystem::path& file, const YAML::Node& node, const char* key, double& cost) {
  read(file, node, key, cost);
  if (!std::isfinite(cost) || cost < 0) throw ConfigError(where(file, node[key]) + ": " + key + " must be a number >= 0");
}

StationConfig read_station(const std::filesystem::path& file, const YAML::Node& s) {
  if (!s.IsMap()) throw ConfigError(where(file, s) + ": a station is a map of keys");
  known_keys(file, s, {"id", "arm", "position", "dock", "table", "arm_speed", "arm_angular_speed", "cost_per_hour"});
  StationConfig c;
  read(file, s, "id", c.id);
  read(file, s, "arm", c.arm);
  read_point(file, s, "position", c.position);
  read_point(file, s, "dock", c.dock);
  read_point(file, s, "table", c.table);
  read(file, s, "arm_speed", c.arm_speed);
  read(file, s, "arm_angular_speed", c.arm_angular_speed);
  if (c.arm_speed <= 0 || c.arm_angular_speed <= 0) throw ConfigError(where(file, s) + ": arm speeds must be above 0");
  read_cost(file, s, "cost_per_hour", c.cost_per_hour);
  for (double h : c.table) {
    if (h <= 0) throw ConfigError(where(file, s["table"]) + ": a table's half extents must be above 0");
  }
  return c;
}

RobotConfig read_robot(const std::filesystem::path& file, const YAML::Node& r) {
  if (!r.IsMap()) throw ConfigError(where(file, r) + ": a mobile robot is a map of keys");
  known_keys(file, r, {"id", "home", "speed", "cost_per_hour"});
  RobotConfig c;
  read(file, r, "id", c.id);
  read_point(file, r, "home", c.home);
  read(file, r, "speed", c.speed);
  if (c.speed <= 0) throw ConfigError(where(file, r) + ": speed must be above 0");
  read_cost(file, r, "cost_per_hour", c.cost_per_hour);
  return c;
}

// `single: {...}` is shorthand for `list: [{...}]`; a file has one or the other.
template <class T, class ReadOne>
void read_list(const std::filesystem::path& file, const YAML::Node& root, const char* single, const char* list,
               std::vector<T>& out, std::vector<YAML::Node>& nodes, ReadOne read_one) {
  if (root[single] && root[list]) {
    throw ConfigError(where(file, root[list]) + ": '" + single + "' and '" + list + "' together; use '" + list + "'");
  }
  if (const auto one = root[single]) {
    out = {read_one(file, one)};
    nodes = {one};
  } else if (const auto many = root[list]) {
    if (!many.IsSequence() || many.size() == 0) throw ConfigError(where(file, many) + ": '" + list + "' needs a list of one or more");
    out.clear();
    nodes.clear();
    for (const auto& item : many) {
      out.push_back(read_one(file, item));
      nodes.push_back(item);
    }
  }
}

// Tables are boxes under their station's point; touching is allowed, overlapping is not.
bool overlap(const StationConfig& a, const StationConfig& b) {
  for (int i = 0; i < 3; ++i) {
    const double ca = a.position[i] - (i == 1 ? a.table[1] : 0), cb = b.position[i] - (i == 1 ? b.table[1] : 0);
    if (std::abs(ca - cb) >= a.table[i] + b.table[i] - 1e-9) return false;
  }
  return true;
}

// The layout's box (tables, docks, homes, buffers) with a margin, unless the file says.
void read_bounds(const std::filesystem::path& file, const YAML::Node& root, CellConfig& c) {
  const double inf = std::numeric_limits<double>::infinity();
  c.bounds_min = {inf, inf, inf};
  c.bounds_max = {-inf, -inf, -inf};
  const auto add = [&](const Point& p, const Point& half) {
    for (int i = 0; i < 3; ++i) {
      c.bounds_min[i] = std::min(c.bounds_min[i], p[i] - half[i] - kBoundsMargin);
      c.bounds_max[i] = std::max(c.bounds_max[i], p[i] + half[i] + kBoundsMargin);
    }
  };
  for (const auto& s : c.stations) {
    add(s.position, s.table);
    add(s.dock, {});
  }
  for (const auto& r : c.robots) add(r.home, {});
  for (const auto& b : c.buffers) add(b.position, {});
  const YAML::Node bounds = root["bounds"];
  if (!bounds) return;
  if (!bounds.IsMap()) throw ConfigError(where(file, bounds) + ": bounds take 'min' and 'max'");
  known_keys(file, bounds, {"min", "max"});
  read_point(file, bounds, "min", c.bounds_min);
  read_point(file, bounds, "max", c.bounds_max);
  for (int i = 0; i < 3; ++i) {
    if (!(c.bounds_min[i] < c.bounds_max[i])) throw ConfigError(where(file, bounds) + ": each minimum must be below its maximum");
  }
}

// `discovery: server | simple | {servers: [IP:PORT, ...]}`.
void read_discovery(const std::filesystem::path& file, const YAML::Node& root, CellConfig& c) {
  const YAML::Node node = root["discovery"];
  if (!node) return;
  c.discovery_given = true;
  c.simple_discovery = false;
  if (node.IsScalar()) {
    const std::string mode = node.as<std::string>();
    if (mode != "server" && mode != "simple") {
      throw ConfigError(where(file, node) + ": discovery is 'server', 'simple' or {servers: [IP:PORT, ...]}, not '" + mode + "'");
    }
    c.simple_discovery = mode == "simple";
    return;
  }
  known_keys(file, node, {"servers"});
  read(file, node, "servers", c.discovery_servers);
  if (c.discovery_servers.empty()) throw ConfigError(where(file, node) + ": discovery: servers lists at least one IP:PORT");
  for (const auto& s : c.discovery_servers) {
    try {
      dds::server_address(s);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(where(file, node["servers"]) + ": " + e.what());
    }
  }
}

// yaml-cpp keeps the first of two equal keys in a map and drops the second without a word: a
// second `gripper:` would be ignored. Refused, with both lines.
void no_repeated_keys(const std::filesystem::path& file, const YAML::Node& node) {
  if (node.IsSequence()) {
    for (const auto& item : node) no_repeated_keys(file, item);
    return;
  }
  if (!node.IsMap()) return;
  std::map<std::string, int> seen;
  for (const auto& entry : node) {
    const std::string key = entry.first.Scalar();
    const auto [it, first] = seen.emplace(key, entry.first.Mark().line + 1);
    if (!first) {
      throw ConfigError(where(file, entry.first) + ": the key '" + key + "' is given twice (first on line " +
                        std::to_string(it->second) + ")");
    }
    no_repeated_keys(file, entry.second);
  }
}

}  // namespace

CellConfig read_cell_config(const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::BadFile&) {
    throw ConfigError(file.string() + ": cannot read the file");
  } catch (const YAML::ParserException& e) {
    throw ConfigError(file.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) throw ConfigError(file.string() + ": a cell is a map of keys");
  no_repeated_keys(file, root);
  CellConfig c;
  c.file = file;
  known_keys(file, root,
             {"domain", "real_time_factor", "liveliness_lease", "localhost_only", "station", "stations", "mobile_robot",
              "mobile_robots", "buffers", "bounds", "restart", "state_dir", "gripper", "security", "clients", "desk", "network",
              "setup_cost", "currency", "standby_twins", "max_twins", "twin_watchdog", "twin_identities", "fixtures", "discovery",
              "dashboard", "operators"});
  read(file, root, "domain", c.domain);
  read(file, root, "real_time_factor", c.real_time_factor);
  read(file, root, "liveliness_lease", c.liveliness_lease);
  read(file, root, "localhost_only", c.localhost_only);
  read(file, root, "fixtures", c.fixtures);
  if (c.domain < 0 || c.domain > 232) throw ConfigError(where(file, root["domain"]) + ": domain must be 0..232");
  if (c.real_time_factor <= 0) throw ConfigError(where(file, root["real_time_factor"]) + ": must be above 0");
  if (c.liveliness_lease <= 0) throw ConfigError(where(file, root["liveliness_lease"]) + ": must be above 0");
  std::vector<YAML::Node> station_nodes, robot_nodes;
  read_list(file, root, "station", "stations", c.stations, station_nodes, read_station);
  read_list(file, root, "mobile_robot", "mobile_robots", c.robots, robot_nodes, read_robot);
  std::vector<YAML::Node> buffer_nodes;
  for (const auto& b : root["buffers"]) {
    known_keys(file, b, {"id", "position", "stock"});
    BufferConfig buffer;
    read(file, b, "id", buffer.id);
    if (buffer.id.empty()) throw ConfigError(where(file, b) + ": a buffer needs an id");
    read_point(file, b, "position", buffer.position);
    read(file, b, "stock", buffer.stock);
    c.buffers.push_back(buffer);
    buffer_nodes.push_back(b);
  }
  read_bounds(file, root, c);
  if (root["state_dir"]) {
    std::string dir;
    read(file, root, "state_dir", dir);
    if (dir.empty()) throw ConfigError(where(file, root["state_dir"]) + ": state_dir names a folder");
    c.state_dir = file.parent_path() / dir;
  }
  if (const YAML::Node network = root["network"]) {
    known_keys(file, network, {"interfaces", "peers"});
    read(file, network, "interfaces", c.interfaces);
    read(file, network, "peers", c.peers);
    if (c.interfaces.empty()) throw ConfigError(where(file, network) + ": network needs the host's interfaces (IPv4 addresses)");
  }
  read_discovery(file, root, c);
  read(file, root, "standby_twins", c.standby_twins);
  if (c.standby_twins < 0 || c.standby_twins > 16) throw ConfigError(where(file, root["standby_twins"]) + ": standby_twins must be 0..16");
  read(file, root, "max_twins", c.max_twins);
  if (c.max_twins < 1 || c.max_twins > 256) throw ConfigError(where(file, root["max_twins"]) + ": max_twins must be 1..256");
  read(file, root, "twin_watchdog", c.twin_watchdog);
  if (!(c.twin_watchdog >= 5 && c.twin_watchdog <= 3600)) {
    throw ConfigError(where(file, root["twin_watchdog"]) + ": twin_watchdog must be 5..3600 s");
  }
  read(file, root, "twin_identities", c.twin_identities);
  if (c.twin_identities < 1 || c.twin_identities > 256) {
    throw ConfigError(where(file, root["twin_identities"]) + ": twin_identities must be 1..256");
  }
  read(file, root, "dashboard", c.dashboard);
  if (!c.dashboard.empty()) {
    try {
      parse_dashboard_address(c.dashboard);
    } catch (const ConfigError& e) {
      throw ConfigError(where(file, root["dashboard"]) + ": " + e.what());
    }
  }
  read_cost(file, root, "setup_cost", c.setup_cost);
  read(file, root, "currency", c.currency);
  if (c.currency.empty() || c.currency.size() > 8) throw ConfigError(where(file, root["currency"]) + ": currency is 1 to 8 characters");
  read(file, root, "clients", c.clients);
  read(file, root, "operators", c.operators);
  for (const auto& [key, names] : {std::pair{"clients", &c.clients}, std::pair{"operators", &c.operators}}) {
    for (const auto& id : *names) {
      if (id.empty() || id.size() > 64 || id.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos) {
        throw ConfigError(where(file, root[key]) + ": a name in " + key + " is 1 to 64 of a-z, 0-9, - and _ ('" + id +
                          "' is not)");
      }
    }
  }
  if (const YAML::Node desk = root["desk"]) {
    known_keys(file, desk, {"max_order_mb", "orders_per_minute", "max_orders"});
    read(file, desk, "max_order_mb", c.desk.max_order_mb);
    read(file, desk, "orders_per_minute", c.desk.orders_per_minute);
    read(file, desk, "max_orders", c.desk.max_orders);
    if (!(c.desk.max_order_mb > 0 && c.desk.max_order_mb <= 100000) || c.desk.orders_per_minute < 1 || c.desk.max_orders < 1) {
      throw ConfigError(where(file, desk) + ": max_order_mb must be above 0 and at most 100000, orders_per_minute and max_orders 1 or more");
    }
  }
  if (root["security"]) {
    std::string dir;
    read(file, root, "security", dir);
    if (dir.empty()) throw ConfigError(where(file, root["security"]) + ": security names the folder `cellctl pki init` wrote");
    c.security_dir = std::filesystem::absolute(file.parent_path() / dir);
  }
  // Fast DDS 2.9's servers do not take part in DDS-Security (its secure Discovery Server came
  // in 2.10): through one, a secure cell's clients never match (measured: the cell never came up).
  if (!c.security_dir.empty() && !c.simple_discovery) {
    throw ConfigError(where(file, root["discovery"]) + ": discovery through a server does not work with security: on " +
                      "Fast DDS 2.9 a secure cell uses simple discovery (discovery: simple)");
  }
  if (const YAML::Node gripper = root["gripper"]) {
    std::set<std::string> names;
    for (const auto& [name, size] : fb::gripper_sizes()) names.insert(name);
    known_keys(file, gripper, names);
    for (const auto& [name, size] : fb::gripper_sizes()) read(file, gripper, name.c_str(), c.gripper.*size);
    if (const std::string problem = c.gripper.problem(); !problem.empty()) throw ConfigError(where(file, gripper) + ": " + problem);
  }
  if (const YAML::Node restart = root["restart"]) {
    known_keys(file, restart, {"limit", "window"});
    long window = c.restart.window.count();
    read(file, restart, "limit", c.restart.limit);
    read(file, restart, "window", window);
    if (c.restart.limit < 0 || window <= 0) {
      throw ConfigError(where(file, restart) + ": limit must be 0 or more and window above 0");
    }
    c.restart.window = std::chrono::seconds(window);
  }
  std::vector<std::pair<std::string, YAML::Node>> named;  // every resource id, where it stands
  for (std::size_t i = 0; i < c.stations.size(); ++i) {
    const YAML::Node node = i < station_nodes.size() ? station_nodes[i] : root;
    named.insert(named.end(), {{c.stations[i].id, node}, {c.stations[i].arm, node}});
  }
  for (std::size_t i = 0; i < c.robots.size(); ++i) named.push_back({c.robots[i].id, i < robot_nodes.size() ? robot_nodes[i] : root});
  for (std::size_t i = 0; i < c.buffers.size(); ++i) named.push_back({c.buffers[i].id, buffer_nodes[i]});
  std::set<std::string> ids;
  for (const auto& [id, node] : named) {
    // An id is a DDS partition and a topic's name in the permissions, where *, ? and [ are
    // patterns: one such id would let a resource speak for others.
    if (id.empty() || id.size() > 64 ||
        id.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-") != std::string::npos) {
      throw ConfigError(where(file, node) + ": a resource id is 1 to 64 of A-Z, a-z, 0-9, '.', '-' and '_' ('" + id + "' is not)");
    }
    if (!ids.insert(id).second) throw ConfigError(where(file, node) + ": a second resource is called '" + id + "'");
    if (is_twin_identity(id)) throw ConfigError(where(file, node) + ": '" + id + "' is the name of a twin's identity");
  }
  // A client's and an operator's name is their DDS-Security identity too: none may be another's.
  ids.insert({"cell-sim", "twin", "cellctl", "order-desk", "dashboard", "discovery"});
  for (const auto& [key, names] : {std::pair{"clients", &c.clients}, std::pair{"operators", &c.operators}}) {
    for (const auto& id : *names) {
      if (!ids.insert(id).second || is_twin_identity(id)) {
        throw ConfigError(where(file, root[key]) + ": '" + id + "' of " + key + " has the name of a resource, of another " +
                          "client or operator, or of cell-sim, twin, twin-N, cellctl, order-desk, dashboard or discovery");
      }
    }
  }
  for (std::size_t i = 0; i < c.stations.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (overlap(c.stations[i], c.stations[j])) {
        throw ConfigError(where(file, station_nodes[i]) + ": the table of " + c.stations[i].id + " overlaps the table of " +
                          c.stations[j].id);
      }
    }
  }
  return c;
}

std::filesystem::path CellConfig::state_folder() const {
  if (!state_dir.empty()) return state_dir;
  const char* xdg = std::getenv("XDG_STATE_HOME");
  const char* home = std::getenv("HOME");
  const std::filesystem::path base = xdg && *xdg ? std::filesystem::path(xdg)
                                     : home && *home ? std::filesystem::path(home) / ".local" / "state"
                                                     : std::filesystem::temp_directory_path();
  return base / "agile-cell" / ("domain-" + std::to_string(domain));
}

std::vector<std::string> CellConfig::twin_identity_names() const {
  std::vector<std::string> names;
  for (int i = 1; i <= twin_identities; ++i) names.push_back("twin-" + std::to_string(i));
  return names;
}

std::vector<std::string> CellConfig::twin_identities_in_use() const {
  return security_dir.empty() ? std::vector<std::string>{} : twin_identity_names();
}

void CellConfig::check_twin_identities() const {
  for (const auto& name : twin_identities_in_use()) {
    if (!std::filesystem::exists(security_dir / "identities" / name / "cert.pem")) {
      throw ConfigError(file.string() + ": security: " + security_dir.string() + " has no identity " + name +
                        " (twin_identities: " + std::to_string(twin_identities) + "); `cellctl pki issue " +
                        security_dir.string() + " " + name + " --cell " + file.string() + "` issues it");
    }
  }
}

std::vector<std::string> CellConfig::discovery_addresses() const {
  if (simple_discovery) return {};
  if (!discovery_servers.empty()) return discovery_servers;
  const std::string port = ":" + std::to_string(kDiscoveryBasePort + domain);
  if (interfaces.empty()) return localhost_only ? std::vector<std::string>{"127.0.0.1" + port} : std::vector<std::string>{};
  // One server on each host: this one's first address and each peer. Sorted, so that every
  // host numbers them alike (a server's number is its identity).
  std::set<std::string> hosts(peers.begin(), peers.end());
  hosts.insert(interfaces.front());
  std::vector<std::string> out;
  for (const auto& h : hosts) out.push_back(h + port);
  return out;
}

dds::ParticipantSettings CellConfig::participant_settings(const std::string& identity) const {
  dds::ParticipantSettings s;
  s.discovery.servers = discovery_addresses();
  s.domain_id = domain;
  s.localhost_only = localhost_only && interfaces.empty();
  s.interfaces = interfaces;
  s.peers = peers;
  if (!security_dir.empty()) s.security = {security_dir, identity};
  return s;
}

namespace {

void add_security(std::vector<std::string>& argv, const CellConfig& c) {
  if (!c.security_dir.empty()) argv.insert(argv.end(), {"--security", c.security_dir.string()});
}

void add_network(std::vector<std::string>& argv, const CellConfig& c) {
  for (const auto& a : c.interfaces) argv.insert(argv.end(), {"--interface", a});
  for (const auto& a : c.peers) argv.insert(argv.end(), {"--peer", a});
  if (c.interfaces.empty() && !c.localhost_only) argv.push_back("--all-interfaces");
  for (const auto& a : c.discovery_addresses()) argv.insert(argv.end(), {"--discovery-server", a});
}

// A twin's options that are the cell's, not the order's.
std::vector<std::string> twin_cell_argv(const CellConfig& c, const std::filesystem::path& bin) {
  std::vector<std::string> argv{(bin / "twin").string(), "--domain", std::to_string(c.domain),
                                "--lease", std::to_string(c.liveliness_lease), "--quiet"};
  add_network(argv, c);
  add_security(argv, c);
  return argv;
}

}  // namespace

std::vector<std::string> twin_standby_argv(const CellConfig& c, const std::filesystem::path& bin) {
  auto argv = twin_cell_argv(c, bin);
  argv.push_back("--standby");
  return argv;
}

std::vector<std::string> twin_order_args(const CellConfig& c, const std::string& order, const std::string& product,
                                         const std::string& out, const std::string& sequence, const std::string& path,
                                         const std::filesystem::path& state_dir, double wait_s, bool quote) {
  std::vector<std::string> args{"--order", order, "--product", product, "--out", out, "--sequence", sequence,
                                "--path", path, "--wait", std::to_string(wait_s)};
  if (!state_dir.empty()) args.insert(args.end(), {"--state-dir", state_dir.string()});
  add_gripper(args, c.gripper);
  if (c.fixtures) args.push_back("--fixtures");
  if (quote) {
    args.insert(args.end(), {"--quote", "--setup-cost", std::to_string(c.setup_cost), "--currency", c.currency});
    for (const auto& s : c.stations) args.insert(args.end(), {"--cost-per-hour", s.id + "=" + std::to_string(s.cost_per_hour)});
    for (const auto& r : c.robots) args.insert(args.end(), {"--cost-per-hour", r.id + "=" + std::to_string(r.cost_per_hour)});
  }
  return args;
}

std::vector<std::string> twin_argv(const CellConfig& c, const std::filesystem::path& bin, const std::string& order,
                                   const std::string& product, const std::string& out, const std::string& sequence,
                                   const std::string& path, const std::filesystem::path& state_dir, double wait_s,
                                   bool quote) {
  std::vector<std::string> argv = twin_cell_argv(c, bin);
  const auto order_args = twin_order_args(c, order, product, out, sequence, path, state_dir, wait_s, quote);
  argv.insert(argv.end(), order_args.begin(), order_args.end());
  return argv;
}

std::vector<ProcessSpec> cell_processes(const CellConfig& c, const std::filesystem::path& bin) {
  const std::string domain = std::to_string(c.domain), lease = std::to_string(c.liveliness_lease);
  std::vector<ProcessSpec> out;
  const auto add_bounds = [&c](std::vector<std::string>& argv) {
    argv.push_back("--cell-bounds");
    for (const Point& p : {c.bounds_min, c.bounds_max}) {
      for (double v : p) argv.push_back(std::to_string(v));
    }
  };
  out.push_back({"cell-sim", {(bin / "cell-sim").string(), "--domain", domain, "--real-time-factor",
                              std::to_string(c.real_time_factor)},
                 true, {}});
  add_bounds(out.back().argv);
  for (const auto& st : c.stations) {
    ProcessSpec station{st.id, {(bin / "station").string(), "--domain", domain, "--id", st.id, "--arm-id", st.arm,
                                "--arm-speed", std::to_string(st.arm_speed), "--arm-angular-speed",
                                std::to_string(st.arm_angular_speed), "--lease", lease},
                        false, {st.id, st.arm}};
    add_point(station.argv, "--position", st.position);
    add_point(station.argv, "--dock", st.dock);
    add_point(station.argv, "--table", st.table);
    add_bounds(station.argv);
    add_gripper(station.argv, c.gripper);
    out.push_back(station);
  }
  for (const auto& r : c.robots) {
    ProcessSpec robot{r.id, {(bin / "mobile-robot").string(), "--domain", domain, "--id", r.id, "--speed",
                             std::to_string(r.speed), "--lease", lease},
                      false, {r.id}};
    add_point(robot.argv, "--home", r.home);
    out.push_back(robot);
  }
  for (const auto& b : c.buffers) {
    ProcessSpec buffer{b.id, {(bin / "buffer").string(), "--domain", domain, "--id", b.id, "--lease", lease}, false, {b.id}};
    add_point(buffer.argv, "--position", b.position);
    for (const auto& [type, count] : b.stock) {
      buffer.argv.push_back("--stock");
      buffer.argv.push_back(type + "=" + std::to_string(count));
    }
    out.push_back(buffer);
  }
  for (auto& p : out) {
    p.argv.insert(p.argv.end(), {"--state-dir", c.state_folder().string()});
    add_network(p.argv, c);
    add_security(p.argv, c);
  }
  // The discovery servers on this host's addresses, before the others.
  const auto servers = c.discovery_addresses();
  for (std::size_t i = servers.size(); i-- > 0;) {
    const std::string ip = dds::server_address(servers[i]).first;
    const bool here = c.interfaces.empty() ? c.localhost_only && ip == "127.0.0.1"
                                           : std::find(c.interfaces.begin(), c.interfaces.end(), ip) != c.interfaces.end();
    if (!here) continue;
    ProcessSpec server{"discovery-" + std::to_string(i), {(bin / "discovery-server").string(), "--domain", domain, "--serve",
                                                          std::to_string(i)},
                       false, {}};
    add_network(server.argv, c);
    add_security(server.argv, c);
    if (!c.security_dir.empty()) server.argv.insert(server.argv.end(), {"--identity", "discovery"});
    out.insert(out.begin(), server);
  }
  return out;
}

DashboardAddress parse_dashboard_address(const std::string& text) {
  DashboardAddress a;
  std::string port = text;
  if (const std::size_t colon = text.rfind(':'); colon != std::string::npos) {
    a.host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  const bool digits = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos;
  a.port = digits ? std::stoi(port) : -1;
  if (a.port < 0 || a.port > 65535 || a.host.empty()) {
    throw ConfigError("dashboard: '" + text + "' is not [ADDR:]PORT (a port 0-65535, 0 any free one; e.g. 8080 or "
                      "127.0.0.1:8080)");
  }
  return a;
}

}  // namespace cellctl
