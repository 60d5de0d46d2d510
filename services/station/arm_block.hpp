#pragma once
// The station's robot arm: a two-finger parallel gripper on a carriage, moved in cell-sim. It
// knows no products: a part is a body id, a grasp is the gripper's pose and opening given by
// the command.
//
//   START grip (part, path = [gripper pose], opening = m between the fingers, carried =
//         bodies joined to the part): the gripper (palm, fingers, carriage;
//         services/node/gripper.hpp) goes to the grasp; the part, and the carried bodies with
//         it (a subassembly's other members), are held from now on
//   START translate | rotate (path): the palm moves along the path with the fingers, the
//         carriage and the held part; a collision ends it (FAIL with the contact)
//   START screw (path, turns, pitch, destination = a body): as a motion, along a helix the
//         path samples, turning the held part into the thread of `destination`, which it may
//         go into by the thread's overlap; the path must turn `turns` times
//   START release: lets go;  connect | disconnect (part): the part becomes an obstacle
//         (joined to the assembly) or movable again
//   SIM_REPLY: cell-sim's answers; SIM: requests to cell-sim

#include "services/node/device_block.hpp"
#include "services/node/gripper.hpp"
#include "services/node/sim_requests.hpp"

namespace fb {

struct ArmSettings {
  double speed = 0.25;          // m/s
  double angular_speed = 1.0;   // rad/s
  GripperGeometry gripper;
};

class ArmBlock : public DeviceBlock {
 public:
  ArmBlock(std::string name, std::string resource_id, ArmSettings settings);

  const std::string& held() const { return held_; }
  const std::vector<std::string>& carried() const { return carried_; }

 private:
  std::string recover() override;
  void check(const Data& command, SampleCheck& check) const override;
  void grip(const Data& command);
  std::vector<std::string> held_bodies() const;  // the gripped part first
  // Its bodies in cell-sim, the palm first.
  std::vector<std::string> gripper_bodies() const;
  void request(Data data);

  ArmSettings settings_;
  SimRequests sim_;
  std::string held_, held_order_;
  std::vector<std::string> carried_;
  bool has_gripper_ = false;
  int awaited_ = 0;  // replies still to come for the current command
  std::string error_;
};

}  // namespace fb
