#include "services/station/station_block.hpp"

namespace fb {

StationBlock::StationBlock(std::string name, std::string id, Numbers position, Numbers half)
    : DeviceBlock(std::move(name), id, {}, "INIT"), sim_(id) {
  declare_input("INIT");
  declare_input("SIM_REPLY", {"request_id", "ok"});
  declare_output("SIM", {"request_id", "kind", "body_id"});
  transition("INIT", "INIT", "SPAWNING", [this, position, half](const Data&) {
    const Numbers table{position[0], position[1] - half[1], position[2], 1, 0, 0, 0};
    emit("SIM", sim_.spawn_fixture(this->resource_id() + "/table", table, half));
  });
  transition("SPAWNING", "SIM_REPLY", "READY", {},
             [this](const Data& d) { return sim_.answers_last(d) && get<bool>(d, "ok"); });
  transition("SPAWNING", "SIM_REPLY", "FAILED", [this](const Data& d) { error_ = get<std::string>(d, "error"); },
             [this](const Data& d) { return sim_.answers_last(d); });
}

}  // namespace fb
