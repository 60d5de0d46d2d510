#include "sim/cell_sim/request_policy.hpp"

#include <cstdint>
#include <filesystem>
#include <system_error>

namespace sim {
namespace {

constexpr std::uintmax_t kMaxMeshBytes = 64u << 20;
constexpr std::size_t kMaxCarried = 64;
constexpr std::size_t kMaxPathLength = 4095;  // FilePath of the IDL
constexpr double kMinMeshScale = 1e-6, kMaxMeshScale = 1e3;  // micrometres to kilometres

std::string text(const fb::Data& d, const char* key) { return fb::get_or<std::string>(d, key, ""); }

}  // namespace

std::string RequestPolicy::well_formed(const fb::Data& d) const {
  fb::SampleCheck c(d, bounds_);
  c.text("request_id", true).text("requester", true).text("order_id").text("kind", true).text("scene");
  const std::string kind = text(d, "kind");
  if (kind != "ping") c.text("body_id", true);
  if (kind == "spawn") {
    c.poses("placement", 1, 1).non_negative_vector("half_extents").text("mesh_uri", false, kMaxPathLength);
    c.finite("mesh_scale");
    const double scale = fb::get_or<double>(d, "mesh_scale", 1);
    c.require(scale == 0 || (scale >= kMinMeshScale && scale <= kMaxMeshScale),
              "mesh_scale: " + std::to_string(scale) + " metres per unit is not a length unit (1e-6 to 1000)");
    const std::string mesh = text(d, "mesh_uri");
    if (c.ok() && !mesh.empty()) {
      std::error_code error;
      const auto size = std::filesystem::file_size(mesh, error);
      c.require(!error && std::filesystem::is_regular_file(mesh, error), "mesh_uri: " + mesh + " is not a readable file");
      c.require(error || size <= kMaxMeshBytes, "mesh_uri: " + mesh + " is larger than 64 MB");
    }
  } else if (kind == "move") {
    c.poses("path", 1).at_least("speed", 0).at_least("angular_speed", 0).names("carried", kMaxCarried);
    c.require(fb::get_or<double>(d, "speed", 0) > 0, "speed: must be above 0");
    c.text("turning", false).text("into", false);
    c.require(text(d, "turning").empty() == text(d, "into").empty(), "turning, into: one without the other");
  }
  return c.error();
}

std::string RequestPolicy::may_change(const std::string& body, const fb::Data& d, const SimWorld& world) const {
  if (world.is_fixture(body)) return body + " is a fixture of the cell";
  const auto it = owner_.find(body);
  if (it == owner_.end()) return "";  // no such body: the world says so
  const std::string requester = text(d, "requester"), order = text(d, "order_id");
  if (it->second == requester) return "";
  if (!order.empty() && it->second == order) {
    const auto hires = hired_.find(requester);
    if (hires != hired_.end() && hires->second.count(order)) return "";
    return body + " belongs to order " + order + ", which has not hired " + requester;
  }
  return body + " belongs to " + it->second + ", not to " + requester;
}

std::string RequestPolicy::problem_with(const fb::Data& d, const SimWorld& world) const {
  if (std::string problem = well_formed(d); !problem.empty()) return problem;
  const std::string kind = text(d, "kind"), body = text(d, "body_id"), requester = text(d, "requester");
  if (kind == "ping") return "";
  if (kind == "spawn") {
    const std::string scene = text(d, "scene");
    if (!scene.empty() && scene != requester) return "scene " + scene + " is not " + requester + "'s";
    return "";
  }
  if (std::string problem = may_change(body, d, world); !problem.empty()) return problem;
  if (kind == "move") {
    for (const std::string& carried : fb::split_names(text(d, "carried"))) {
      if (std::string problem = may_change(carried, d, world); !problem.empty()) return problem;
    }
    // A part turned into a thread passes into that body: only one of the same order's (never
    // a fixture, nor another order's part).
    if (const std::string into = text(d, "into"); !into.empty()) {
      if (std::string problem = may_change(into, d, world); !problem.empty()) return "into: " + problem;
    }
  }
  return "";
}

std::vector<std::string> RequestPolicy::order_ended(const std::string& order) {
  for (auto& [resource, orders] : hired_) orders.erase(order);
  std::vector<std::string> bodies;
  for (auto it = owner_.begin(); it != owner_.end();) {
    if (it->second == order) {
      bodies.push_back(it->first);
      it = owner_.erase(it);
    } else {
      ++it;
    }
  }
  return bodies;
}

}  // namespace sim
