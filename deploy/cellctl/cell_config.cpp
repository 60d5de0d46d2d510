#include "deploy/cellctl/cell_config.hpp"

#include <set>

#include <yaml-cpp/yaml.h>

namespace cellctl {
namespace {

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

}  // namespace

std::vector<std::string> CellConfig::resource_ids() const {
  std::vector<std::string> ids{station, arm, robot};
  for (const auto& b : buffers) ids.push_back(b.id);
  return ids;
}

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
  CellConfig c;
  c.file = file;
  known_keys(file, root,
             {"domain", "real_time_factor", "liveliness_lease", "localhost_only", "station", "mobile_robot", "buffers"});
  read(file, root, "domain", c.domain);
  read(file, root, "real_time_factor", c.real_time_factor);
  read(file, root, "liveliness_lease", c.liveliness_lease);
  read(file, root, "localhost_only", c.localhost_only);
  if (c.domain < 0 || c.domain > 232) throw ConfigError(where(file, root["domain"]) + ": domain must be 0..232");
  if (c.real_time_factor <= 0) throw ConfigError(where(file, root["real_time_factor"]) + ": must be above 0");
  if (const auto s = root["station"]) {
    known_keys(file, s, {"id", "arm", "position", "dock", "table", "arm_speed", "arm_angular_speed"});
    read(file, s, "id", c.station);
    read(file, s, "arm", c.arm);
    read_point(file, s, "position", c.station_position);
    read_point(file, s, "dock", c.dock);
    read_point(file, s, "table", c.table);
    read(file, s, "arm_speed", c.arm_speed);
    read(file, s, "arm_angular_speed", c.arm_angular_speed);
  }
  if (const auto r = root["mobile_robot"]) {
    known_keys(file, r, {"id", "home", "speed"});
    read(file, r, "id", c.robot);
    read_point(file, r, "home", c.robot_home);
    read(file, r, "speed", c.robot_speed);
  }
  for (const auto& b : root["buffers"]) {
    known_keys(file, b, {"id", "position", "stock"});
    BufferConfig buffer;
    read(file, b, "id", buffer.id);
    if (buffer.id.empty()) throw ConfigError(where(file, b) + ": a buffer needs an id");
    read_point(file, b, "position", buffer.position);
    read(file, b, "stock", buffer.stock);
    c.buffers.push_back(buffer);
  }
  std::set<std::string> ids;
  for (const auto& id : c.resource_ids()) {
    if (!ids.insert(id).second) throw ConfigError(file.string() + ": two resources are called '" + id + "'");
  }
  return c;
}

std::vector<ProcessSpec> cell_processes(const CellConfig& c, const std::filesystem::path& bin) {
  const std::string domain = std::to_string(c.domain), lease = std::to_string(c.liveliness_lease);
  std::vector<ProcessSpec> out;
  out.push_back({"cell-sim", {(bin / "cell-sim").string(), "--domain", domain, "--real-time-factor",
                              std::to_string(c.real_time_factor)}});
  ProcessSpec station{c.station, {(bin / "station").string(), "--domain", domain, "--id", c.station, "--arm-id", c.arm,
                                  "--arm-speed", std::to_string(c.arm_speed), "--arm-angular-speed",
                                  std::to_string(c.arm_angular_speed), "--lease", lease}};
  add_point(station.argv, "--position", c.station_position);
  add_point(station.argv, "--dock", c.dock);
  add_point(station.argv, "--table", c.table);
  out.push_back(station);
  ProcessSpec robot{c.robot, {(bin / "mobile-robot").string(), "--domain", domain, "--id", c.robot, "--speed",
                              std::to_string(c.robot_speed), "--lease", lease}};
  add_point(robot.argv, "--home", c.robot_home);
  out.push_back(robot);
  for (const auto& b : c.buffers) {
    ProcessSpec buffer{b.id, {(bin / "buffer").string(), "--domain", domain, "--id", b.id, "--lease", lease}};
    add_point(buffer.argv, "--position", b.position);
    for (const auto& [type, count] : b.stock) {
      buffer.argv.push_back("--stock");
      buffer.argv.push_back(type + "=" + std::to_string(count));
    }
    out.push_back(buffer);
  }
  if (!c.localhost_only) {
    for (auto& p : out) p.argv.push_back("--all-interfaces");
  }
  return out;
}

}  // namespace cellctl
