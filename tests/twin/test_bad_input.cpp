// Every kind of bad input: a DescriptionError naming file, line, element and the fault.

#include "tests/twin/test_support.hpp"

namespace {

struct BadInput {
  const char* file;
  int line;
  const char* element;  // what SourceRef::element starts with; "" when there is none
  const char* message;  // a fragment of the message
};

const BadInput kBadInputs[] = {
    {"not_xml.aml", 3, "", "not well-formed XML"},
    {"truncated.aml", 35, "", "truncated?"},
    {"not_caex.aml", 3, "Assembly", "not a CAEX file"},
    {"unknown_link_id.aml", 15, "InternalLink \"base-block\"", "unknown part ID '0a000000-0000-4000-8000-00000000dead'"},
    {"unknown_interface.aml", 15, "InternalLink \"base-block\"", "part 'base' has no interface 'slott'"},
    {"interface_without_coordinates.aml", 15, "InternalLink \"base-block\"", "interface 'slot' of part 'base' has no coordinates"},
    {"coordinate_two_numbers.aml", 28, "Attribute \"slot\"", "'20,10' is not three numbers"},
    {"coordinate_not_a_number.aml", 28, "Attribute \"slot\"", "'ten' is not a finite number"},
    {"coordinate_infinite.aml", 28, "Attribute \"slot\"", "'inf' is not a finite number"},
    {"duplicate_ids.aml", 12, "InternalElement \"turned\"", "duplicate ID"},
    {"missing_mesh.aml", 42, "Attribute \"refURI\"", "mesh file 'meshes/no_such_block.stl' does not exist"},
    {"unreadable_mesh.aml", 42, "Attribute \"refURI\"", "cannot read mesh"},
    {"mesh_outside_folder.aml", 42, "Attribute \"refURI\"", "leaves the product's folder"},
    {"mesh_absolute_path.aml", 42, "Attribute \"refURI\"", "must be a path relative to the product's folder"},
    {"inconsistent_loop.aml", 16, "InternalLink \"block-turned\"", "loop that does not fit"},
    {"unreached_part.aml", 12, "InternalElement \"turned\"", "not reached by any link from 'base': turned"},
    {"entity_expansion.aml", 3, "<!DOCTYPE>", "not accepted"},
    {"external_entity.aml", 3, "<!DOCTYPE>", "not accepted"},
};

}  // namespace

TEST_CASE("bad input is refused with file, line, element and reason", "[bad-input]") {
  for (const auto& bad : kBadInputs) {
    SECTION(bad.file) {
      const auto path = test::data(std::string("bad/") + bad.file);
      try {
        test::load(path);
        FAIL("no error for " << bad.file);
      } catch (const twin::DescriptionError& e) {
        INFO(e.what());
        CHECK(e.where().file == path.string());
        CHECK(e.where().line == bad.line);
        CHECK(e.where().element.rfind(bad.element, 0) == 0);
        CHECK_THAT(e.message(), Catch::Contains(bad.message));
      }
    }
  }
}

TEST_CASE("a missing file is an error naming it", "[bad-input]") {
  CHECK_THROWS_WITH(test::load(test::data("bad/there_is_no_such_file.aml")),
                    Catch::Contains("there_is_no_such_file.aml") && Catch::Contains("cannot open"));
  CHECK_THROWS_WITH(test::load(test::data("good/meshes/plate.obj")), Catch::Contains("unknown product description format"));
}
