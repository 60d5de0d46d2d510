// Gravity (twin/planning/stability.hpp): which assemblies stand, with what margin, what a
// fastening joint changes, the arm's hold and fixtures in plans, joints read from the
// AutomationML.

#include <fstream>
#include <sstream>

#include "tests/support/scratch.hpp"
#include "tests/twin/test_support.hpp"
#include "twin/planning/plan_verifier.hpp"
#include "twin/planning/stability.hpp"

namespace {

// A product of boxes (mm) in one frame: each part's mesh is its box where it stands, its frame
// the product's; every link joins the two parts' origins, with the joint given (or none).
struct Boxes {
  struct Box {
    std::string name;
    twin::Vec3 lo, hi;  // mm
  };
  struct Link {
    std::string a, b, joint;
  };
  std::vector<Box> boxes;
  std::vector<Link> links;

  std::filesystem::path write(const std::filesystem::path& dir) const {
    std::ostringstream aml;
    aml << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<CAEXFile SchemaVersion=\"3.0\" FileName=\"boxes.aml\" "
           "xmlns=\"http://www.dke.de/CAEX\"><InstanceHierarchy Name=\"Order\"><InternalElement Name=\"Boxes\" ID=\"boxes\">\n";
    std::ostringstream classes;
    for (const Box& b : boxes) {
      std::ofstream obj(dir / (b.name + ".obj"));
      for (int i = 0; i < 8; ++i) {
        obj << "v " << (i & 1 ? b.hi.x() : b.lo.x()) << ' ' << (i & 2 ? b.hi.y() : b.lo.y()) << ' '
            << (i & 4 ? b.hi.z() : b.lo.z()) << '\n';
      }
      obj << "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
      aml << "<InternalElement Name=\"" << b.name << "\" ID=\"" << b.name << "\" RefBaseSystemUnitPath=\"Lib/" << b.name << "\"/>\n";
      classes << "<SystemUnitClass Name=\"" << b.name << "\">";
      for (const Link& l : links) {
        if (l.a != b.name && l.b != b.name) continue;
        const std::string other = l.a == b.name ? l.b : l.a;
        classes << "<Attribute Name=\"to_" << other << "\"><DefaultValue>0,0,0</DefaultValue></Attribute>"
                << "<ExternalInterface Name=\"to_" << other << "\" ID=\"" << b.name << "-" << other << "\">";
        if (!l.joint.empty()) classes << "<Attribute Name=\"Joint\"><Value>" << l.joint << "</Value></Attribute>";
        classes << "</ExternalInterface>";
      }
      classes << "<ExternalInterface Name=\"geometry\" ID=\"" << b.name << "-geometry\" RefBaseClassPath=\"ExternalDataReference\">"
              << "<Attribute Name=\"refURI\"><Value>" << b.name << ".obj</Value></Attribute>"
              << "<Attribute Name=\"LengthUnit\"><Value>mm</Value></Attribute></ExternalInterface></SystemUnitClass>\n";
    }
    for (const Link& l : links) {
      aml << "<InternalLink Name=\"" << l.a << "-" << l.b << "\" RefPartnerSideA=\"" << l.a << ":to_" << l.b
          << "\" RefPartnerSideB=\"" << l.b << ":to_" << l.a << "\"/>\n";
    }
    aml << "</InternalElement></InstanceHierarchy><SystemUnitClassLib Name=\"Lib\">" << classes.str()
        << "</SystemUnitClassLib></CAEXFile>\n";
    std::ofstream(dir / "boxes.aml") << aml.str();
    return dir / "boxes.aml";
  }
};

// Whether the product's parts stand, all in place, their fastenings made.
std::optional<twin::Instability> standing(const twin::LoadedProduct& product, const std::vector<std::string>& parts,
                                          twin::StabilityOptions options = {}) {
  const twin::StabilityAnalysis analysis(product, options);
  std::vector<twin::PlacedPart> placed;
  for (const auto& name : parts) {
    const auto p = *product.product.find_part_by_name(name);
    placed.push_back({p, product.product.parts()[p].final_pose});
  }
  std::vector<bool> fastened;
  for (const auto& c : product.product.connections()) fastened.push_back(c.joint.fastens());
  return analysis.check(placed, {}, fastened);
}

std::vector<std::string> names(const twin::Product& product, const std::vector<twin::PartIndex>& parts) {
  std::vector<std::string> out;
  for (auto p : parts) out.push_back(product.parts()[p].name);
  return out;
}

}  // namespace

TEST_CASE("gravity: a block stands on the station and on a block, and topples beyond its edge", "[stability]") {
  const test::ScratchDir dir("stability-blocks");
  Boxes b;
  b.boxes = {{"base", {0, 0, 0}, {40, 20, 40}}, {"top", {0, 20, 0}, {40, 30, 40}}, {"ledge", {30, 30, 0}, {70, 40, 40}}};
  b.links = {{"base", "top", ""}, {"top", "ledge", ""}};
  const auto product = test::load(b.write(dir.path()));
  CHECK_FALSE(standing(product, {"base"}));
  CHECK_FALSE(standing(product, {"base", "top"}));
  // 10 of its 40 mm on the top, its centre 15 mm beyond: it topples even upright.
  const auto falls = standing(product, {"base", "top", "ledge"});
  REQUIRE(falls);
  CHECK(names(product.product, falls->parts) == std::vector<std::string>{"ledge"});
  CHECK(falls->tilt == 0);
  CHECK(twin::describe(product.product, *falls, {}).find("ledge: nothing holds it up") == 0);
}

TEST_CASE("gravity: a state asked before is remembered by where its parts stand, translation too", "[stability]") {
  // The memory once keyed a pose by the first twelve numbers of its 4x4 matrix, which leave the
  // translation out: a part lifted or moved aside was answered as where it was first asked,
  // and a subassembly built aside then set in place lost its support (the station's contacts
  // of the aside pose).
  const test::ScratchDir dir("stability-moved");
  Boxes b;
  b.boxes = {{"base", {0, 0, 0}, {100, 10, 100}}, {"block", {70, 10, 40}, {90, 30, 60}}};
  b.links = {{"base", "block", ""}};
  const auto product = test::load(b.write(dir.path()));
  const twin::StabilityAnalysis analysis(product);
  const twin::PartIndex base = 0, block = 1;
  const twin::Pose finished = twin::Pose::Identity();
  CHECK_FALSE(analysis.check({{base, finished}}));
  twin::Pose lifted = finished;
  lifted.translation().y() = 0.04;
  const auto in_the_air = analysis.check({{base, lifted}});
  REQUIRE(in_the_air);
  CHECK(in_the_air->tilt == 0);
  // Asked first 150 mm aside, then where it stands finished with the block on its edge: the
  // station bears the plate where it now is.
  twin::Pose aside = finished;
  aside.translation().x() = 0.15;
  CHECK_FALSE(analysis.check({{base, aside}}));
  CHECK_FALSE(analysis.check({{base, finished}, {block, finished}}));
}

TEST_CASE("gravity: a fastening joint holds what contact alone does not", "[stability]") {
  const test::ScratchDir dir("stability-glued");
  Boxes b;
  b.boxes = {{"base", {0, 0, 0}, {40, 20, 40}}, {"ledge", {30, 20, 0}, {70, 30, 40}}};
  b.links = {{"base", "ledge", "glue"}};
  const auto product = test::load(b.write(dir.path()));
  REQUIRE(product.product.connections().front().joint.kind == twin::Joint::Kind::glue);
  // Glued, the pair is one body whose centre lies over the base's foot (base 32 000 mm^3 at
  // x = 20, ledge 16 000 at x = 50: 30 mm, inside 0..40): it stands.
  CHECK_FALSE(standing(product, {"base", "ledge"}));
}

TEST_CASE("gravity: the margin: a post on a narrow foot stands upright and topples tilted 5 degrees", "[stability]") {
  const test::ScratchDir dir("stability-post");
  Boxes b;
  // 4 mm wide, 80 mm tall: its centre 40 mm up, 2 mm from the edge: it tips at 2.9 degrees.
  b.boxes = {{"post", {0, 0, 0}, {4, 80, 20}}};
  const auto product = test::load(b.write(dir.path()));
  const auto falls = standing(product, {"post"});
  REQUIRE(falls);
  CHECK(falls->tilt == 5);
  twin::StabilityOptions gentle;
  gentle.tilt_margin = 2;
  CHECK_FALSE(standing(product, {"post"}, gentle));
}

TEST_CASE("gravity: a bridge on two piers stands, and a part held by side walls with play only falls", "[stability]") {
  const test::ScratchDir dir("stability-bridge");
  Boxes b;
  b.boxes = {{"left", {0, 0, 0}, {20, 40, 20}},
             {"right", {60, 0, 0}, {80, 40, 20}},
             {"bridge", {0, 40, 0}, {80, 50, 20}},
             // Between the piers, 0.2 mm from each, touching nothing below: friction on the walls
             // would have to wedge it, which a part with play does not do.
             {"plug", {20.2, 10, 0}, {59.8, 30, 20}}};
  b.links = {{"left", "bridge", ""}, {"right", "bridge", ""}, {"left", "plug", ""}, {"right", "plug", ""}};
  const auto product = test::load(b.write(dir.path()));
  CHECK_FALSE(standing(product, {"left", "right", "bridge"}));  // two supports: the linear program
  const auto falls = standing(product, {"left", "right", "plug"});
  REQUIRE(falls);
  CHECK(names(product.product, falls->parts) == std::vector<std::string>{"plug"});
}

TEST_CASE("gravity in plans: the arm holds a part until it is fastened", "[stability][planning]") {
  // Cranfield's front plate is pressed onto the pegs and the shaft: released before, it would
  // fall (nothing is under it); the plan holds it until the press fit is made.
  const test::Planned cranfield(test::product("cranfield/cranfield.aml"));
  REQUIRE(cranfield.plan.complete);
  CHECK(cranfield.plan.stability);
  const auto& last = cranfield.plan.steps.back();
  CHECK(cranfield.product.product.parts()[last.part].name == "front");
  CHECK(last.hold);
  CHECK(twin::step_result(last) == "ok, held until fastened");
  // The same plan, the front let go at once: the replay sees it fall.
  twin::Plan careless = cranfield.plan;
  careless.steps.back().hold = false;
  const twin::Verification v = twin::verify_plan(cranfield.product, careless);
  REQUIRE_FALSE(v.violations.empty());
  CHECK(v.violations.front().step == careless.steps.size());
  CHECK(twin::describe(cranfield.product.product, v.violations.front()).find("when the arm lets go, front") != std::string::npos);
}

TEST_CASE("gravity in plans: where no order stands, a fixture must hold it, and the plan says where", "[stability][planning]") {
  // A thin tall panel with a bushing beside it: the panel cannot stand alone.
  const auto product = test::load(test::data("planning/grasp/grasp.aml"));
  auto sequence = twin::make_sequence_planner("search");
  const twin::Plan without = twin::plan_assembly(product, *sequence, *twin::make_path_planner("linear"));
  CHECK_FALSE(without.complete);
  const auto fixture = std::find_if(without.findings.begin(), without.findings.end(), [](const auto& f) { return f.kind == "fixture"; });
  REQUIRE(fixture != without.findings.end());
  CHECK(fixture->message.find("a fixture must hold panel") != std::string::npos);
  // A cell with fixtures builds it, and the replay, with the fixture holding the panel, passes.
  const twin::Plan with = twin::plan_assembly(product, *sequence, *twin::make_path_planner("linear"), test::with_fixtures());
  CHECK(with.complete);
  CHECK(with.verification.passed);
  REQUIRE_FALSE(with.steps.front().fixture.empty());
  CHECK(product.product.parts()[with.steps.front().fixture.front()].name == "panel");
}

TEST_CASE("joints: read from the interfaces, a screw with its pitch, contradictions and bad values refused", "[stability][aml]") {
  const test::ScratchDir dir("joints");
  Boxes b;
  b.boxes = {{"plate", {0, 0, 0}, {40, 5, 40}}, {"leg", {15, 5, 15}, {25, 50, 25}}};
  b.links = {{"plate", "leg", ""}};
  const auto file = b.write(dir.path());
  // The product with attributes added to the leg's interface (and the plate's).
  const std::string leg = "<ExternalInterface Name=\"to_plate\" ID=\"leg-plate\">";
  const std::string plate = "<ExternalInterface Name=\"to_leg\" ID=\"plate-leg\">";
  const auto read = [&](const std::string& on_leg, const std::string& on_plate = "") {
    std::ifstream in(file);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.find(leg), leg.size(), leg + on_leg);
    text.replace(text.find(plate), plate.size(), plate + on_plate);
    std::ofstream(dir.path() / "variant.aml") << text;
    return test::load(dir.path() / "variant.aml");
  };
  const std::string screw = "<Attribute Name=\"Joint\"><Value>screw</Value></Attribute>";
  const auto screwed = read(screw + "<Attribute Name=\"Pitch\" Unit=\"mm\"><Value>1.5</Value></Attribute>");
  const twin::Joint& joint = screwed.product.connections().front().joint;
  CHECK(joint.kind == twin::Joint::Kind::screw);
  CHECK(joint.pitch == Approx(0.0015));
  CHECK(joint.fastens());
  CHECK_FALSE(read("").product.connections().front().joint.fastens());  // no joint: contact

  const auto refused = [&](const std::string& on_leg, const std::string& on_plate, const std::string& said) {
    try {
      read(on_leg, on_plate);
      FAIL("accepted: " << on_leg << " / " << on_plate);
    } catch (const twin::DescriptionError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find("variant.aml:") != std::string::npos);
      CHECK(std::string(e.what()).find(said) != std::string::npos);
    }
  };
  refused("<Attribute Name=\"Joint\"><Value>nail</Value></Attribute>", "", "declares joint 'nail', which is none of contact, screw");
  refused(screw, "", "has no Pitch");
  refused(screw + "<Attribute Name=\"Pitch\"><Value>-1</Value></Attribute>", "", "is not a length above 0");
  refused("<Attribute Name=\"Joint\"><Value>glue</Value></Attribute>", "<Attribute Name=\"Joint\"><Value>snap</Value></Attribute>",
          "declare different joints");
}
