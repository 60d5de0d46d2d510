#pragma once
// How long an order's physical assembly takes on the cell, in sim s: its script
// (assembly_script.hpp) run against the resources' own models, as the orchestrator runs it:
// one action after another, the robot's fetches beside the arm's work.
//
//   robot  takes the fetches in the order it hears them (one is sent once the robot heard the
//          last); each drives from where the robot is to the buffer's dock, waits for the
//          buffer's give, drives to the station's dock, straight, at its speed (as the
//          robot's bid counts it and cell-sim moves it)
//   arm    waits for each step's delivery; a grip puts the gripper at its pose; a motion goes
//          from the gripper's pose along the path, each segment as long as cell-sim takes for
//          it at the arm's speeds (sim::segment_duration); a screw by the same rule
//   messages  cost time besides the motions (MessageCosts): a request of the twin's to
//          cell-sim, a command (it, the resource's own request to cell-sim, its final
//          event), a fetch (heard: half a command; while the robot works, its two requests to
//          cell-sim and the buffer's give). They are wall time: in sim time, times the cell's
//          real-time factor (a physical cell's 1 makes them negligible; a simulation at 20x
//          makes a command's 3.5 ms 0.07 s)
//
// What it leaves out: other orders that come later, and messages lost and sent again.

#include <map>
#include <string>
#include <vector>

#include "twin/orchestration/assembly_script.hpp"

namespace twin {

// Measured on one host with the cell at real-time factors 5, 20 and 50 (docs/quotes.md): the
// wall time between a command's start and the next one's, less its motion, 3.1-3.8 ms; a
// fetch's, less its drives, 5.2-6.0 ms.
struct MessageCosts {
  double request = 0.0006, command = 0.0035, fetch = 0.0055;  // wall s
};

struct ResourceModels {
  std::map<std::string, fb::Numbers> docks;  // resource id -> its dock (the station, the buffers)
  fb::Numbers robot_at;                      // where the robot sets out from
  double robot_speed = 1;                    // m/s
  double arm_speed = 0.25;                   // m/s
  double arm_angular_speed = 1;              // rad/s; 0: turning takes no time
  MessageCosts messages;
  double real_time_factor = 0;               // of the cell's sim clock; 0: messages take no time
};

struct ModelledRun {
  double start = 0;     // the station is the order's (s from now)
  double end = 0;       // the script's last action is done
  double robot_s = 0;   // the robot drives for the order
  std::vector<double> delivered;  // when each fetch's part is at the dock, in the script's order
};

// `station_free`, `robot_free`: s from now until the station is the order's and the robot's
// earlier work is done (their queues). Throws std::invalid_argument for a fetch from or to a
// place without a dock.
ModelledRun run_script(const Script& script, const ResourceModels& models, double station_free, double robot_free);

}  // namespace twin
