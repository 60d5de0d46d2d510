#pragma once
// The virtual assembly as a glTF 2.0 animation for the designer: one node per part (with its
// colour) and one for the gripper in each step (palm, fingers as far apart as the part is
// wide, carriage); every part appears when its step starts and follows its trajectory, its
// gripper with it. Opens in Blender, three.js
// and any glTF viewer.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "twin/planning/assembly_planner.hpp"

namespace twin {

struct AnimationOptions {
  double speed = 0.1;         // m/s of the part along its trajectory
  double angular_speed = 6;   // rad/s of the part turning (a screw: about a turn a second)
  double min_segment = 0.25;  // s, for segments that neither move nor turn the part (release)
  double gap = 0.5;           // s between steps, while the arm moves to the next part
  fb::GripperGeometry gripper;
};

struct GltfAnimation {
  std::string text;  // the .gltf document, buffers embedded
  std::vector<std::pair<double, double>> steps;  // s: when each plan step starts and ends
};
GltfAnimation gltf_animation(const LoadedProduct& product, const Plan& plan, const AnimationOptions& options = {});

// Writes a self-contained .gltf (buffers embedded). Throws std::runtime_error if it cannot.
void write_gltf_animation(const LoadedProduct& product, const Plan& plan, const std::filesystem::path& file,
                          const AnimationOptions& options = {});

// "pink", "lightblue", "#ff8800", ...: RGBA in 0..1; unknown names are grey.
std::array<double, 4> color_rgba(const std::optional<std::string>& color);

}  // namespace twin
