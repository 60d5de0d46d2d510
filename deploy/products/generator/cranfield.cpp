// The Cranfield assembly benchmark (Collins, Palmer, Rathmill 1985) with the dimensions of
// docs/products.md. Y is up; the back faceplate lies on the station, everything else is
// inserted from above into it.

#include <filesystem>

#include "deploy/products/generator/caex_writer.hpp"
#include "deploy/products/generator/mesh_builder.hpp"
#include "deploy/products/generator/products.hpp"

namespace products {
namespace {

using V = Eigen::Vector3d;

constexpr double kPlateX = 240, kPlateZ = 180, kPlateThickness = 12;
constexpr double kPegLength = 90;         // back plate + gap + front plate
constexpr double kPegHalf = 7.5;          // square pegs 15 x 15, round pegs and shaft 15 diameter
constexpr double kHoleHalf = 8;           // holes 16 (0.5 mm clearance on each side)
constexpr double kPendulumThickness = 10;
constexpr double kSeparatorHeight = 20;

struct HoleSpec {
  const char* name;
  double x, z;
  bool square;
};
// The paper's faceplate interfaces (section 4), scaled by 60 mm and rounded.
constexpr HoleSpec kHoles[] = {{"square_left", -40, 69, true},
                               {"square_right", 40, 69, true},
                               {"circle_left", -61, -46, false},
                               {"circle_right", 61, -46, false},
                               {"shaft", 0, 14, false}};

void write_meshes(const std::filesystem::path& dir) {
  std::vector<Hole> holes;
  for (const auto& h : kHoles) holes.push_back({h.x, h.z, kHoleHalf, h.square, 14});
  MeshBuilder plate;
  plate.plate_with_holes(-kPlateX / 2, kPlateX / 2, -kPlateZ / 2, kPlateZ / 2, 0, kPlateThickness, holes);
  plate.write_obj((dir / "faceplate.obj").string(), "Cranfield faceplate 240 x 12 x 180 mm, five through-holes");

  MeshBuilder square_peg;
  square_peg.box(-kPegHalf, kPegHalf, 0, kPegLength, -kPegHalf, kPegHalf);
  square_peg.write_obj((dir / "square_peg.obj").string(), "Cranfield square peg 15 x 90 x 15 mm");

  MeshBuilder round_peg;
  round_peg.cylinder(kPegHalf, 0, kPegLength);
  round_peg.write_obj((dir / "round_peg.obj").string(), "Cranfield round peg and shaft, 15 mm diameter, 90 mm long");

  MeshBuilder pendulum;
  pendulum.plate_with_holes(-10, 10, -100, 10, 0, kPendulumThickness, {{0, 0, kHoleHalf, false, 10}});
  pendulum.write_obj((dir / "pendulum.obj").string(), "Cranfield pendulum 20 x 10 x 110 mm, shaft hole at the origin");

  MeshBuilder separator;
  separator.plate_with_holes(-56, 56, -12, 12, 0, kSeparatorHeight,
                             {{-40, 0, kHoleHalf, true, 12}, {40, 0, kHoleHalf, true, 12}});
  separator.write_obj((dir / "separator.obj").string(), "Cranfield separator 112 x 20 x 24 mm, two square holes");
}

}  // namespace

void write_cranfield(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "meshes");
  write_meshes(dir / "meshes");

  CaexWriter aml("cranfield.aml", "CranfieldBenchmark");
  for (const char* c : {"IBolt", "IBoltAngular", "IShaft", "IPendulum", "ISeparator"}) aml.interface_class(c);

  pugi::xml_node faceplate = aml.unit_class("Faceplate");
  aml.geometry(faceplate, "meshes/faceplate.obj");
  pugi::xml_node back = aml.unit_class("FaceplateBack", "Faceplate");
  pugi::xml_node front = aml.unit_class("FaceplateFront", "Faceplate");
  for (const auto& h : kHoles) {
    const char* iclass = h.square ? "IBoltAngular" : (std::string(h.name) == "shaft" ? "IShaft" : "IBolt");
    aml.interface_point(back, h.name, iclass, V(h.x, 0, h.z));                 // bottom face, as in the paper
    // The front plate is pressed onto the pegs and the shaft: nothing else holds it up.
    aml.interface_point(front, h.name, iclass, V(h.x, kPlateThickness, h.z), "press-fit");  // top face
  }

  pugi::xml_node peg = aml.unit_class("Peg");
  aml.interface_point(peg, "bottom", "IBolt", V(0, 0, 0));
  aml.interface_point(peg, "top", "IBolt", V(0, kPegLength, 0));
  pugi::xml_node square_peg = aml.unit_class("SquarePeg", "Peg");
  aml.geometry(square_peg, "meshes/square_peg.obj");
  aml.interface_point(square_peg, "separator", "ISeparator", V(0, kPlateThickness, 0));
  pugi::xml_node round_peg = aml.unit_class("RoundPeg", "Peg");
  aml.geometry(round_peg, "meshes/round_peg.obj");
  pugi::xml_node shaft = aml.unit_class("Shaft", "Peg");
  aml.geometry(shaft, "meshes/round_peg.obj");
  aml.interface_point(shaft, "pendulum", "IPendulum", V(0, kPlateThickness, 0));

  pugi::xml_node pendulum = aml.unit_class("Pendulum");
  aml.geometry(pendulum, "meshes/pendulum.obj");
  aml.interface_point(pendulum, "shaft", "IShaft", V(0, 0, 0));
  pugi::xml_node separator = aml.unit_class("Separator");
  aml.geometry(separator, "meshes/separator.obj");
  aml.interface_point(separator, "peg_left", "IBoltAngular", V(-40, 0, 0));
  aml.interface_point(separator, "peg_right", "IBoltAngular", V(40, 0, 0));

  const auto back_plate = aml.part("back", "FaceplateBack", "pink");
  const auto shaft_part = aml.part("shaft", "Shaft", "green");
  const auto pendulum_part = aml.part("pendulum", "Pendulum", "yellow");
  const auto square_left = aml.part("boltA1", "SquarePeg", "green");
  const auto square_right = aml.part("boltA2", "SquarePeg", "green");
  const auto round_left = aml.part("boltR1", "RoundPeg", "green");
  const auto round_right = aml.part("boltR2", "RoundPeg", "green");
  const auto separator_part = aml.part("separator", "Separator", "orange");
  const auto front_plate = aml.part("front", "FaceplateFront", "lightblue");

  // The paper's links: the shaft to the back faceplate, the pendulum to the shaft.
  aml.link("back-shaft", back_plate, "shaft", shaft_part, "bottom");
  aml.link("shaft-pendulum", shaft_part, "pendulum", pendulum_part, "shaft");
  aml.link("back-boltA1", back_plate, "square_left", square_left, "bottom");
  aml.link("back-boltA2", back_plate, "square_right", square_right, "bottom");
  aml.link("back-boltR1", back_plate, "circle_left", round_left, "bottom");
  aml.link("back-boltR2", back_plate, "circle_right", round_right, "bottom");
  aml.link("boltA1-separator", square_left, "separator", separator_part, "peg_left");
  aml.link("boltA2-separator", square_right, "separator", separator_part, "peg_right");
  aml.link("front-boltA1", front_plate, "square_left", square_left, "top");
  aml.link("front-boltA2", front_plate, "square_right", square_right, "top");
  aml.link("front-boltR1", front_plate, "circle_left", round_left, "top");
  aml.link("front-boltR2", front_plate, "circle_right", round_right, "top");
  aml.link("front-shaft", front_plate, "shaft", shaft_part, "top");
  aml.save((dir / "cranfield.aml").string());
}

}  // namespace products
