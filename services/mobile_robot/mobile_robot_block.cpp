#include "services/mobile_robot/mobile_robot_block.hpp"

#include "services/state/cell_store.hpp"
#include "sim/world/motion_time.hpp"

namespace fb {

MobileRobotBlock::MobileRobotBlock(std::string name, std::string id, Numbers home, double speed,
                                   std::chrono::milliseconds resend_give_after)
    : DeviceBlock(std::move(name), id, {"fetch"}, "INIT"), sim_(id), speed_(speed), work_ends_at_(home),
      resend_give_after_(resend_give_after) {
  declare_input("INIT");
  declare_input("AWARDED", {"sources", "station"});
  declare_input("PLACE", {"resource_id", "dock"});
  declare_input("SIM_REPLY", {"request_id", "ok"});
  declare_input("GIVE_EVENT", {"command_id", "state", "reason"});
  declare_input("TICK");
  declare_output("SIM", {"request_id", "kind", "body_id"});
  declare_output("GIVE", {"command_id", "resource_id", "operation", "part_type"});
  declare_output("PREPARE_GIVE", {"resource_id"});  // a buffer it will fetch from

  const auto answered = [this](const Data& d) { return sim_.answers_last(d); };
  const auto arrived = [this](const Data& d) {
    return sim_.answers_last(d) && get<bool>(d, "ok") && !get_or<bool>(d, "collided", false);
  };
  // Adds a move's distance and time to the fetch's; on failure, the fetch fails with why.
  const auto account = [this](const Data& reply) {
    std::string failure;
    Data outcome = move_outcome(reply, failure);
    distance_ += get<double>(outcome, "distance");
    moving_ += get<double>(outcome, "duration");
    outcome["distance"] = distance_;
    outcome["duration"] = moving_;
    return outcome;
  };
  const auto fail = [this, account](const Data& reply) { emit("FAIL", account(reply)); };
  const auto give_answer = [this](const char* state) {
    return [this, state](const Data& d) {
      return get<std::string>(d, "command_id") == give_id_ && get<std::string>(d, "state") == state;
    };
  };

  for (const char* state : {"INIT", "SPAWNING", "READY", "TO_SOURCE", "WAIT_GIVE", "TO_DESTINATION"}) {
    transition(state, "PLACE", state, [this](const Data& d) {
      docks_[get<std::string>(d, "resource_id")] = get<Numbers>(d, "dock");
    });
    transition(state, "AWARDED", state, [this](const Data& d) {
      const auto it = docks_.find(get<std::string>(d, "station"));
      if (it != docks_.end()) work_ends_at_ = it->second;
      for (const auto& source : split_names(get_or<std::string>(d, "sources", ""))) emit("PREPARE_GIVE", {{"resource_id", source}});
    });
  }
  transition("INIT", "INIT", "SPAWNING", [this, home](const Data&) {
    emit("SIM", sim_.spawn(body(), {home[0], home[1], home[2], 1, 0, 0, 0}, {0, 0, 0}, false));
  });
  transition("SPAWNING", "SIM_REPLY", "READY", {}, answered);

  const auto knows_places = [this](const Data& d) {
    return docks_.count(get<std::string>(d, "source")) && docks_.count(get<std::string>(d, "destination"));
  };
  transition("READY", "START", "TO_SOURCE", [this](const Data& d) {
    fetch_ = d;
    sim_.act_for(get_or<std::string>(d, "order_id", ""));
    distance_ = moving_ = 0;
    drive_to(get<std::string>(d, "source"), {});
  }, knows_places);
  transition("READY", "START", "READY", [this](const Data& d) {
    emit("FAIL", {{"reason", "no dock known for " + get<std::string>(d, "source") + " or " +
                                 get<std::string>(d, "destination")}});
  });
  transition("TO_SOURCE", "SIM_REPLY", "WAIT_GIVE", [this, account](const Data& reply) {
    account(reply);
    give_id_ = get<std::string>(fetch_, "command_id") + "/give";
    give_sent_at_ = std::chrono::steady_clock::now();
    give_ = {{"command_id", give_id_},
             {"resource_id", fetch_.at("source")},
             {"order_id", fetch_.at("order_id")},
             {"award", get_or<std::string>(fetch_, "source_award", "")},
             {"operation", std::string("give")},
             {"part", fetch_.at("part")},
             {"part_type", fetch_.at("part_type")},
             {"destination", resource_id()},  // who takes the part: the buffer's record says so
             {"sim_time", get<double>(reply, "end_time")}};
    emit("GIVE", give_);
  }, arrived);
  transition("TO_SOURCE", "SIM_REPLY", "READY", fail, answered);
  transition("WAIT_GIVE", "GIVE_EVENT", "TO_DESTINATION", [this](const Data&) {
    drive_to(get<std::string>(fetch_, "destination"), {get<std::string>(fetch_, "part")});
  }, give_answer("succeeded"));
  transition("WAIT_GIVE", "GIVE_EVENT", "READY", [this](const Data& d) {
    emit("FAIL", {{"reason", get<std::string>(d, "reason")}, {"distance", distance_}, {"duration", moving_}});
  }, [give_answer](const Data& d) { return give_answer("aborted")(d) || give_answer("rejected")(d); });
  // A give with no final answer yet goes again: one the buffer never heard (written while a
  // buffer that restarted was not matched again: commands are not kept for readers that come
  // later), and one whose answer was lost with a buffer that ended after the give. The buffer
  // carries out a command id once: it ignores a repeat while at it, answers one it finished
  // with its last event, and its next process answers one it did (BufferBlock).
  transition("WAIT_GIVE", "TICK", "WAIT_GIVE", [this](const Data&) {
    give_sent_at_ = std::chrono::steady_clock::now();
    emit("GIVE", give_);
  }, [this](const Data&) { return std::chrono::steady_clock::now() - give_sent_at_ >= resend_give_after_; });
  transition("TO_DESTINATION", "SIM_REPLY", "READY", [this, account](const Data& reply) {
    if (store()) {
      store()->deliver(get_or<std::string>(fetch_, "order_id", ""), get<std::string>(fetch_, "part"),
                       get<std::string>(fetch_, "destination"));
    }
    emit("DONE", account(reply));
  }, arrived);
  // A delivery that failed on the way: the part goes back to its buffer.
  transition("TO_DESTINATION", "SIM_REPLY", "READY", [this, fail](const Data& reply) {
    if (store()) {
      for (const auto& p : store()->return_carried(resource_id())) {
        store()->journal(resource_id(), "returned", p.order, p.part + " (" + p.part_type + ") back to " + p.buffer);
      }
    }
    fail(reply);
  }, answered);
}

std::string MobileRobotBlock::recover() {
  std::string out;
  for (const auto& p : store()->return_carried(resource_id())) {
    out += (out.empty() ? "" : ", ") + p.part + " (" + p.part_type + ") back to " + p.buffer;
  }
  return out.empty() ? "" : "the part it carried went back: " + out;
}

void MobileRobotBlock::check(const Data& command, SampleCheck& c) const {
  if (get<std::string>(command, "operation") != "fetch") return;
  c.text("source", true).text("destination", true).text("part_type", true).text("source_award", true);
}

void MobileRobotBlock::drive_to(const std::string& place, const std::vector<std::string>& carried) {
  const Numbers& dock = docks_.at(place);
  emit("SIM", sim_.move(body(), carried, {dock[0], 0, dock[2], 1, 0, 0, 0}, speed_, 0));
}


Contractor::Estimate MobileRobotBlock::estimate(const std::vector<std::string>& sources,
                                                const std::string& destination) const {
  const auto unknown = [](const std::string& place) {
    return Contractor::Estimate{false, "no dock known for '" + place + "'", 0};
  };
  Contractor::Estimate e;
  Numbers at = work_ends_at_;
  if (!docks_.count(destination)) return unknown(destination);
  const Numbers& to = docks_.at(destination);
  for (const auto& source : sources) {
    const auto it = docks_.find(source);
    if (it == docks_.end()) return unknown(source);
    e.duration += (sim::floor_distance(at, it->second) + sim::floor_distance(it->second, to)) / speed_;
    at = to;
  }
  e.available = true;
  return e;
}

}  // namespace fb
