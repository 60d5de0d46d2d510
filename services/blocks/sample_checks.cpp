#include "services/blocks/sample_checks.hpp"

#include <cmath>
#include <sstream>

namespace fb {
namespace {

std::string triple(const double* v) {
  std::ostringstream out;
  out << '(' << v[0] << ", " << v[1] << ", " << v[2] << ')';
  return out.str();
}

bool all_finite(const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

bool CellBounds::contains(const double* xyz) const {
  for (int i = 0; i < 3; ++i) {
    if (!(xyz[i] >= min[i] && xyz[i] <= max[i])) return false;
  }
  return true;
}

void SampleCheck::fail(std::string what) {
  if (error_.empty()) error_ = std::move(what);
}

SampleCheck& SampleCheck::require(bool condition, const std::string& what) {
  if (!condition) fail(what);
  return *this;
}

SampleCheck& SampleCheck::text(const char* key, bool required, std::size_t max_length) {
  const auto it = data_.find(key);
  const std::string* value = it == data_.end() ? nullptr : std::get_if<std::string>(&it->second);
  if (it != data_.end() && !value) {
    fail(std::string(key) + ": not a text");
  } else if (value && value->size() > max_length) {
    fail(std::string(key) + ": " + std::to_string(value->size()) + " characters, more than " +
         std::to_string(max_length));
  } else if (required && (!value || value->empty())) {
    fail(std::string(key) + ": empty");
  }
  return *this;
}

SampleCheck& SampleCheck::finite(const char* key) { return at_least(key, -HUGE_VAL); }

SampleCheck& SampleCheck::at_least(const char* key, double low) {
  const auto it = data_.find(key);
  if (it == data_.end()) return *this;
  const double* v = std::get_if<double>(&it->second);
  if (!v) {
    fail(std::string(key) + ": not a number");
  } else if (!std::isfinite(*v)) {
    fail(std::string(key) + ": " + std::to_string(*v) + " is not finite");
  } else if (*v < low) {
    std::ostringstream out;
    out << key << ": " << *v << " is below " << low;
    fail(out.str());
  }
  return *this;
}

const Numbers* SampleCheck::numbers(const char* key) {
  const auto it = data_.find(key);
  if (it == data_.end()) return nullptr;
  const Numbers* n = std::get_if<Numbers>(&it->second);
  if (!n) fail(std::string(key) + ": not a list of numbers");
  return n;
}

SampleCheck& SampleCheck::vector(const char* key, bool positive) {
  const Numbers* n = numbers(key);
  if (!n) return *this;
  if (n->size() != 3) return fail(std::string(key) + ": needs 3 numbers, has " + std::to_string(n->size())), *this;
  if (!all_finite(n->data(), 3)) return fail(std::string(key) + ": " + triple(n->data()) + " is not finite"), *this;
  if (positive && !((*n)[0] > 0 && (*n)[1] > 0 && (*n)[2] > 0)) {
    fail(std::string(key) + ": " + triple(n->data()) + " is not a size (each above 0)");
  }
  return *this;
}

SampleCheck& SampleCheck::non_negative_vector(const char* key) {
  vector(key);
  const Numbers* n = ok() ? numbers(key) : nullptr;
  if (n && n->size() == 3 && ((*n)[0] < 0 || (*n)[1] < 0 || (*n)[2] < 0)) {
    fail(std::string(key) + ": " + triple(n->data()) + " has a negative size");
  }
  return *this;
}

SampleCheck& SampleCheck::poses(const char* key, std::size_t min_count, std::size_t max_count) {
  const Numbers* n = numbers(key);
  const std::size_t size = n ? n->size() : 0;
  if (size % 7 != 0) return fail(std::string(key) + ": " + std::to_string(size) + " numbers, not 7 per pose"), *this;
  const std::size_t count = size / 7;
  if (count < min_count || count > max_count) {
    return fail(std::string(key) + ": " + std::to_string(count) + " poses, not " + std::to_string(min_count) + " to " +
                std::to_string(max_count)),
           *this;
  }
  for (std::size_t i = 0; i < count && ok(); ++i) {
    const double* p = n->data() + 7 * i;
    const std::string where = std::string(key) + "[" + std::to_string(i) + "]: ";
    if (!all_finite(p, 3)) {
      fail(where + "position " + triple(p) + " is not finite");
    } else if (!bounds_.contains(p)) {
      fail(where + "position " + triple(p) + " is outside the cell " + triple(bounds_.min.data()) + " to " +
           triple(bounds_.max.data()));
    } else if (!all_finite(p + 3, 4)) {
      fail(where + "orientation is not finite");
    } else if (const double norm = std::sqrt(p[3] * p[3] + p[4] * p[4] + p[5] * p[5] + p[6] * p[6]);
               std::abs(norm - 1) > kQuaternionTolerance) {
      fail(where + "orientation is not a unit quaternion (length " + std::to_string(norm) + ")");
    }
  }
  return *this;
}

SampleCheck& SampleCheck::names(const char* key, std::size_t max_count) {
  text(key, false, max_count * (kMaxTextLength + 1));
  const auto it = data_.find(key);
  const std::string* value = it == data_.end() ? nullptr : std::get_if<std::string>(&it->second);
  if (!ok() || !value) return *this;
  const std::vector<std::string> list = split_names(*value);
  if (list.size() > max_count)
    fail(std::string(key) + ": " + std::to_string(list.size()) + " names, more than " + std::to_string(max_count));
  for (const std::string& name : list) {
    if (name.size() > kMaxTextLength) fail(std::string(key) + ": a name longer than " + std::to_string(kMaxTextLength));
  }
  return *this;
}

}  // namespace fb
