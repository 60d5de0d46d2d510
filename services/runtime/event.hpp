#pragma once
// An IEC 61499 event and the data that travels WITH it.

#include <cstdint>
#include <map>
#include <string>
#include <variant>
#include <vector>

namespace fb {

// Numbers: a pose is seven (x, y, z, qw, qx, qy, qz), a path is seven per waypoint.
using Numbers = std::vector<double>;
using Value = std::variant<bool, std::int64_t, double, std::string, Numbers>;
using Data = std::map<std::string, Value>;

struct Event {
  std::string name;
  Data data;
};

// data["x"] as T; throws std::invalid_argument naming the key when missing or of another type.
template <class T>
const T& get(const Data& data, const std::string& key);
// A list of names travels as one comma-separated string ("a,b,c").
std::string join_names(const std::vector<std::string>& names);
std::vector<std::string> split_names(const std::string& joined);

// data["x"] as T, or `fallback` when missing.
template <class T>
T get_or(const Data& data, const std::string& key, T fallback);

}  // namespace fb

#include <stdexcept>

namespace fb {

template <class T>
const T& get(const Data& data, const std::string& key) {
  const auto it = data.find(key);
  if (it == data.end()) throw std::invalid_argument("event data has no '" + key + "'");
  if (const T* value = std::get_if<T>(&it->second)) return *value;
  throw std::invalid_argument("event data '" + key + "' has another type");
}

template <class T>
T get_or(const Data& data, const std::string& key, T fallback) {
  return data.count(key) ? get<T>(data, key) : fallback;
}

}  // namespace fb
