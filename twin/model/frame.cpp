#include "twin/model/frame.hpp"

#include <cmath>

namespace twin {

Quat rotation_from_xyz_degrees(const Vec3& degrees) {
  const Vec3 r = degrees * (M_PI / 180.0);
  return Quat(Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
              Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .normalized();
}

}  // namespace twin
