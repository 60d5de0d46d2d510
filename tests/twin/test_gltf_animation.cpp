// The glTF animation, read back with tinygltf: a node per part with its colour, the arm,
// and animation channels that end with every part at its final pose.

#include <unistd.h>

#include <tiny_gltf.h>

#include "tests/twin/test_support.hpp"
#include "twin/report/gltf_animation.hpp"

TEST_CASE("the virtual assembly is written as a glTF 2.0 animation", "[gltf]") {
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  const twin::LoadedProduct& loaded = cranfield.product;
  const twin::Plan& plan = cranfield.plan;
  REQUIRE(plan.complete);
  const auto file = std::filesystem::temp_directory_path() / ("cranfield-" + std::to_string(::getpid()) + ".gltf");
  twin::write_gltf_animation(loaded, plan, file);

  tinygltf::Model model;
  tinygltf::TinyGLTF reader;
  std::string error, warning;
  const bool ok = reader.LoadASCIIFromFile(&model, &error, &warning, file.string());
  std::filesystem::remove(file);
  INFO(error << warning);
  REQUIRE(ok);

  CHECK(model.asset.version == "2.0");
  REQUIRE(model.scenes.size() == 1);
  CHECK(model.scenes[0].nodes.size() == loaded.product.parts().size() + plan.steps.size());  // parts + a gripper per step
  const auto find_node = [&](const std::string& name) {
    const auto it = std::find_if(model.nodes.begin(), model.nodes.end(), [&](const auto& n) { return n.name == name; });
    REQUIRE(it != model.nodes.end());
    return static_cast<int>(it - model.nodes.begin());
  };
  // The back faceplate is pink.
  const auto& back = model.nodes[find_node("back")];
  const auto& colour = model.materials[model.meshes[back.mesh].primitives[0].material].pbrMetallicRoughness.baseColorFactor;
  CHECK(colour == std::vector<double>{0.95, 0.55, 0.7, 1});

  REQUIRE(model.animations.size() == 1);
  const auto& animation = model.animations[0];
  // translation, rotation and scale for every part and every step's gripper
  CHECK(animation.channels.size() == 3 * (loaded.product.parts().size() + plan.steps.size()));
  // The front faceplate's gripper: its fingers 180 mm apart, on the plate's outer faces.
  const auto& gripper = model.meshes[model.nodes[find_node("gripper (front)")].mesh];
  const auto& corners = model.accessors[gripper.primitives[0].attributes.at("POSITION")];
  const fb::GripperGeometry size;
  CHECK(corners.maxValues[0] - corners.minValues[0] == Approx(0.180 + 2 * size.finger_thickness).margin(1e-6));
  // The front faceplate's translation track ends at its final place (78 mm up).
  const int front = find_node("front");
  for (const auto& channel : animation.channels) {
    if (channel.target_node != front || channel.target_path != "translation") continue;
    const auto& output = model.accessors[animation.samplers[channel.sampler].output];
    const auto& view = model.bufferViews[output.bufferView];
    const auto* values = reinterpret_cast<const float*>(model.buffers[view.buffer].data.data() + view.byteOffset);
    const float* last = values + 3 * (output.count - 1);
    CHECK(last[1] == Approx(0.078).margin(1e-6));
  }
}

TEST_CASE("colour names and #rrggbb", "[gltf]") {
  CHECK(twin::color_rgba(std::string("#ff8000")) == std::array<double, 4>{1.0, 128 / 255.0, 0.0, 1});
  CHECK(twin::color_rgba(std::string("Green")) == std::array<double, 4>{0.2, 0.6, 0.2, 1});
  CHECK(twin::color_rgba(std::nullopt) == std::array<double, 4>{0.6, 0.6, 0.6, 1});
}
