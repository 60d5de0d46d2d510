#pragma once
// Checks of a sample from the network, as event data, before anything acts on it: every
// number finite, poses with unit quaternions inside the cell's bounds, sizes positive,
// texts and paths within their limits. Each check names the field; the first failure is
// kept, so a refusal says what was wrong and where:
//
//   SampleCheck check(command, bounds);
//   check.text("part").poses("path", 1, kMaxWaypoints).positive("size");
//   if (!check.ok()) refuse(check.error());   // "path[3]: position (0, inf, 1) is not finite"

#include <array>
#include <cstddef>
#include <string>

#include "services/runtime/event.hpp"

namespace fb {

// The box every position in the cell lies in, m.
struct CellBounds {
  std::array<double, 3> min{-50, -50, -50};
  std::array<double, 3> max{50, 50, 50};
  bool contains(const double* xyz) const;
};

constexpr std::size_t kMaxTextLength = 255;    // an Id of the IDL (string<256>, one less: longer ones come cut)
constexpr std::size_t kMaxWaypoints = 2048;    // MAX_WAYPOINTS of the IDL
constexpr double kQuaternionTolerance = 1e-3;  // | |q| - 1 | at most this

class SampleCheck {
 public:
  SampleCheck(const Data& data, CellBounds bounds = {}) : data_(data), bounds_(bounds) {}

  // A text field (missing counts as empty) of at most `max_length` characters; `required`:
  // not empty either.
  SampleCheck& text(const char* key, bool required = false, std::size_t max_length = kMaxTextLength);
  // A number field: finite (missing is fine: it means 0).
  SampleCheck& finite(const char* key);
  SampleCheck& at_least(const char* key, double low);  // finite and >= low
  // Three numbers, finite; `positive`: each above 0.
  SampleCheck& vector(const char* key, bool positive = false);
  SampleCheck& non_negative_vector(const char* key);
  // Poses of seven numbers (x, y, z, qw, qx, qy, qz): positions finite and inside the bounds,
  // quaternions of unit length; between `min_count` and `max_count` of them.
  SampleCheck& poses(const char* key, std::size_t min_count, std::size_t max_count = kMaxWaypoints);
  // A comma-separated list of at most `max_count` names, each a valid text.
  SampleCheck& names(const char* key, std::size_t max_count);

  // A check of the caller's: fails with `what` unless `condition` holds.
  SampleCheck& require(bool condition, const std::string& what);

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

 private:
  const Numbers* numbers(const char* key);
  void fail(std::string what);

  const Data& data_;
  CellBounds bounds_;
  std::string error_;
};

}  // namespace fb
