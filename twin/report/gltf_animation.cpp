#include "twin/report/gltf_animation.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <map>
#include <stdexcept>

#include <tiny_gltf.h>

namespace twin {
namespace {

// Appends raw values to the one buffer and makes a view and an accessor for them.
class GltfBuilder {
 public:
  tinygltf::Model model;

  GltfBuilder() {
    model.asset.version = "2.0";
    model.asset.generator = "agile-cell cellctl";
    model.buffers.emplace_back();
  }

  int accessor(const void* data, std::size_t bytes, std::size_t count, int component, int type, int target,
               std::vector<double> min = {}, std::vector<double> max = {}) {
    auto& buffer = model.buffers[0].data;
    while (buffer.size() % 4) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    if (target) view.target = target;
    buffer.insert(buffer.end(), static_cast<const unsigned char*>(data), static_cast<const unsigned char*>(data) + bytes);
    model.bufferViews.push_back(view);
    tinygltf::Accessor a;
    a.bufferView = static_cast<int>(model.bufferViews.size() - 1);
    a.componentType = component;
    a.count = count;
    a.type = type;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }

  int floats(const std::vector<float>& values, int type, int target = 0, bool bounds = false) {
    const int width = type == TINYGLTF_TYPE_SCALAR ? 1 : type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
    std::vector<double> min, max;
    if (bounds) {
      min.assign(width, 1e300);
      max.assign(width, -1e300);
      for (std::size_t i = 0; i < values.size(); ++i) {
        min[i % width] = std::min<double>(min[i % width], values[i]);
        max[i % width] = std::max<double>(max[i % width], values[i]);
      }
    }
    return accessor(values.data(), values.size() * sizeof(float), values.size() / width, TINYGLTF_COMPONENT_TYPE_FLOAT,
                    type, target, min, max);
  }

  // A triangle mesh's geometry: position and index accessors.
  std::pair<int, int> geometry(const sim::TriangleMesh& mesh) {
    std::vector<float> positions;
    for (const auto& v : mesh.vertices) positions.insert(positions.end(), {float(v.x()), float(v.y()), float(v.z())});
    std::vector<std::uint32_t> indices;
    for (const auto& t : mesh.triangles) indices.insert(indices.end(), {t[0], t[1], t[2]});
    const int p = floats(positions, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
    const int i = accessor(indices.data(), indices.size() * 4, indices.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                           TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    return {p, i};
  }

  int material(const std::string& name, const std::array<double, 4>& rgba) {
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor = {rgba[0], rgba[1], rgba[2], rgba[3]};
    m.pbrMetallicRoughness.metallicFactor = 0.1;
    m.pbrMetallicRoughness.roughnessFactor = 0.7;
    model.materials.push_back(m);
    return static_cast<int>(model.materials.size() - 1);
  }

  int mesh(const std::string& name, std::pair<int, int> geometry, int material) {
    tinygltf::Primitive primitive;
    primitive.attributes["POSITION"] = geometry.first;
    primitive.indices = geometry.second;
    primitive.material = material;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh m;
    m.name = name;
    m.primitives.push_back(primitive);
    model.meshes.push_back(m);
    return static_cast<int>(model.meshes.size() - 1);
  }

  int node(const std::string& name, int mesh, const Pose& pose) {
    tinygltf::Node n;
    n.name = name;
    n.mesh = mesh;
    const Quat q(pose.linear());
    n.rotation = {q.x(), q.y(), q.z(), q.w()};
    n.translation = {pose.translation().x(), pose.translation().y(), pose.translation().z()};
    model.nodes.push_back(n);
    return static_cast<int>(model.nodes.size() - 1);
  }
};

sim::TriangleMesh box_mesh(const Eigen::AlignedBox3d& box) {
  sim::TriangleMesh m;
  for (int i = 0; i < 8; ++i) {
    m.vertices.emplace_back(i & 1 ? box.max().x() : box.min().x(), i & 2 ? box.max().y() : box.min().y(),
                            i & 4 ? box.max().z() : box.min().z());
  }
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

// The gripper with its fingers `opening` apart, as one mesh of its boxes.
sim::TriangleMesh gripper_mesh(const fb::GripperGeometry& gripper, double opening) {
  sim::TriangleMesh out;
  for (const auto& box : fb::gripper_boxes(gripper, opening)) {
    const Vec3 c = box.pose.translation();
    const sim::TriangleMesh m = box_mesh({c - box.half_extents, c + box.half_extents});
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    out.vertices.insert(out.vertices.end(), m.vertices.begin(), m.vertices.end());
    for (const auto& tri : m.triangles) out.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
  }
  return out;
}

// Keyframes of one node: times, translations, rotations, scales.
struct Track {
  std::vector<float> times, translations, rotations, scales;
  void key(double t, const Pose& pose, double scale) {
    float at = static_cast<float>(t);
    if (!times.empty() && at <= times.back()) at = times.back() + 1e-4f;  // strictly increasing, as stored
    times.push_back(at);
    const Quat q(pose.linear());
    translations.insert(translations.end(), {float(pose.translation().x()), float(pose.translation().y()),
                                             float(pose.translation().z())});
    rotations.insert(rotations.end(), {float(q.x()), float(q.y()), float(q.z()), float(q.w())});
    scales.insert(scales.end(), {float(scale), float(scale), float(scale)});
  }
};

}  // namespace

std::array<double, 4> color_rgba(const std::optional<std::string>& color) {
  static const std::map<std::string, std::array<double, 4>> names = {
      {"red", {0.8, 0.1, 0.1, 1}},      {"green", {0.2, 0.6, 0.2, 1}},   {"blue", {0.15, 0.3, 0.8, 1}},
      {"yellow", {0.95, 0.85, 0.1, 1}}, {"orange", {0.95, 0.55, 0.1, 1}}, {"pink", {0.95, 0.55, 0.7, 1}},
      {"white", {0.95, 0.95, 0.95, 1}}, {"black", {0.08, 0.08, 0.08, 1}}, {"grey", {0.5, 0.5, 0.5, 1}},
      {"gray", {0.5, 0.5, 0.5, 1}},     {"lightblue", {0.6, 0.8, 0.95, 1}}, {"purple", {0.5, 0.2, 0.6, 1}}};
  if (!color) return {0.6, 0.6, 0.6, 1};
  std::string c = *color;
  std::transform(c.begin(), c.end(), c.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (const auto it = names.find(c); it != names.end()) return it->second;
  if (c.size() == 7 && c[0] == '#' && c.find_first_not_of("0123456789abcdef", 1) == std::string::npos) {
    return {std::stoi(c.substr(1, 2), nullptr, 16) / 255.0, std::stoi(c.substr(3, 2), nullptr, 16) / 255.0,
            std::stoi(c.substr(5, 2), nullptr, 16) / 255.0, 1};
  }
  return {0.6, 0.6, 0.6, 1};
}

GltfAnimation gltf_animation(const LoadedProduct& loaded, const Plan& plan, const AnimationOptions& options) {
  GltfAnimation out;
  GltfBuilder gltf;
  const auto& parts = loaded.product.parts();
  std::map<const sim::TriangleMesh*, std::pair<int, int>> geometry;
  std::vector<int> part_nodes(parts.size(), -1);
  for (PartIndex i = 0; i < parts.size(); ++i) {
    const auto* mesh = loaded.meshes[i].get();
    if (!mesh) continue;
    if (!geometry.count(mesh)) geometry[mesh] = gltf.geometry(*mesh);
    const int material = gltf.material(parts[i].name, color_rgba(parts[i].color));
    part_nodes[i] = gltf.node(parts[i].name, gltf.mesh(parts[i].name, geometry[mesh], material), parts[i].final_pose);
  }
  // The arm's gripper: one node per step (its fingers stand as far apart as that step's
  // part is wide), shown during its step only.
  const int arm_material = gltf.material("arm", {0.9, 0.45, 0.05, 1});
  std::vector<std::pair<int, Track>> grippers;

  // Time line: steps one after the other; a part is hidden (scale 0) until its step. A
  // subassembly's parts appear where it is built aside, and its insertion moves them all, each
  // at its place relative to the base, from there to the trajectory's start in the gap.
  std::vector<Track> part_tracks(parts.size());
  std::vector<Pose> at(parts.size(), Pose::Identity());  // where each part stands after its last key
  double t = 0;
  for (const auto& step : plan.steps) {
    const auto& w = step.trajectory.waypoints;
    out.steps.emplace_back(t, t);
    if (w.empty()) continue;
    const std::string name = "gripper (" + parts[step.part].name + ")";
    const int node = gltf.node(name, gltf.mesh(name, gltf.geometry(gripper_mesh(options.gripper, step.trajectory.grasp.opening)),
                                               arm_material), w.front().gripper);
    Track& arm_track = grippers.emplace_back(node, Track{}).second;
    arm_track.key(0, w.front().gripper, 0);
    if (t > 0) arm_track.key(t, w.front().gripper, 0);
    std::vector<std::pair<PartIndex, Pose>> moving{{step.part, Pose::Identity()}};
    for (PartIndex p : step.carried) moving.emplace_back(p, parts[step.part].final_pose.inverse() * parts[p].final_pose);
    const auto key = [&](PartIndex p, double time, const Pose& pose, double scale) {
      part_tracks[p].key(time, pose, scale);
      at[p] = pose;
    };
    for (const auto& [p, relative] : moving) {
      if (part_tracks[p].times.empty()) {
        key(p, 0, w.front().part * relative, 0);
        if (t > 0) key(p, t, w.front().part * relative, 0);
      } else {
        key(p, t, at[p], 1);
      }
    }
    t += options.gap;
    for (const auto& [p, relative] : moving) key(p, t, w.front().part * relative, 1);
    arm_track.key(t, w.front().gripper, 1);
    for (std::size_t i = 1; i < w.size(); ++i) {
      const double moved = std::max((w[i].part.translation() - w[i - 1].part.translation()).norm(),
                                    (w[i].gripper.translation() - w[i - 1].gripper.translation()).norm());
      const double turned = Eigen::Quaterniond(w[i - 1].part.linear()).angularDistance(Eigen::Quaterniond(w[i].part.linear()));
      const double took = std::max(moved / options.speed, turned / options.angular_speed);
      t += took > 0 ? took : options.min_segment;
      for (const auto& [p, relative] : moving) key(p, t, w[i].part * relative, 1);
      arm_track.key(t, w[i].gripper, 1);
    }
    arm_track.key(t, w.back().gripper, 0);  // gone with its step
    out.steps.back().second = t;
  }

  tinygltf::Animation animation;
  animation.name = "virtual assembly";
  auto add_track = [&](int node, const Track& track) {
    if (node < 0 || track.times.empty()) return;
    const int input = gltf.floats(track.times, TINYGLTF_TYPE_SCALAR, 0, true);
    const std::pair<const char*, std::pair<const std::vector<float>*, int>> channels[] = {
        {"translation", {&track.translations, TINYGLTF_TYPE_VEC3}},
        {"rotation", {&track.rotations, TINYGLTF_TYPE_VEC4}},
        {"scale", {&track.scales, TINYGLTF_TYPE_VEC3}}};
    for (const auto& [path, values] : channels) {
      tinygltf::AnimationSampler sampler;
      sampler.input = input;
      sampler.output = gltf.floats(*values.first, values.second);
      sampler.interpolation = std::string(path) == "scale" ? "STEP" : "LINEAR";
      animation.samplers.push_back(sampler);
      tinygltf::AnimationChannel channel;
      channel.sampler = static_cast<int>(animation.samplers.size() - 1);
      channel.target_node = node;
      channel.target_path = path;
      animation.channels.push_back(channel);
    }
  };
  for (PartIndex i = 0; i < parts.size(); ++i) add_track(part_nodes[i], part_tracks[i]);
  for (const auto& [node, track] : grippers) add_track(node, track);
  if (!animation.channels.empty()) gltf.model.animations.push_back(animation);

  tinygltf::Scene scene;
  scene.name = loaded.product.name();
  for (int n : part_nodes) {
    if (n >= 0) scene.nodes.push_back(n);
  }
  for (const auto& [node, track] : grippers) scene.nodes.push_back(node);
  gltf.model.scenes.push_back(scene);
  gltf.model.defaultScene = 0;

  std::ostringstream text;
  tinygltf::TinyGLTF().WriteGltfSceneToStream(&gltf.model, text, true, false);
  out.text = text.str();
  return out;
}

void write_gltf_animation(const LoadedProduct& loaded, const Plan& plan, const std::filesystem::path& file,
                          const AnimationOptions& options) {
  std::ofstream out(file);
  out << gltf_animation(loaded, plan, options).text;
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace twin
